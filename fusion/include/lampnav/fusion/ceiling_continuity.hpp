#pragma once
// Did the robot move as its wheels say? Each ceiling frame's lamps against those of the last frame
// that had lamps, carried between the two by the dead reckoning. No map is needed: the lamps are
// put at one height (the map's lamps' usual one), and between frames a few centimetres of travel
// apart a lamp at another height errs by the travel times the height's relative error.
//
// The wheels do not see a lift. A robot carried while it is looking for its place, or carried
// before the kidnap monitor noticed, would otherwise be looked for among the places its drive so
// far allows, the truth not among them; in a regular building the image after the carry can fit
// one of them as well as it fits the truth. The ceiling camera sees the move: the lamps well
// inside the view before it are gone, and other lamps are where the wheels say none could be.
// Lamps fail, people hide them, a detection drops out, a floor bump swings the view: a lamp
// missing, or one appearing, alone is not a move. A frame is odd when it has a lamp where the
// last frame showed none, misses one the last frame showed, and agrees with it on no lamp; the
// move is seen when the next frame with lamps agrees with the odd one and not with the last frame
// before it (the lamps moved, and stayed where they moved to).

#include <memory>
#include <string>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/fusion/odometry_track.hpp"
#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::fusion {

struct CeilingContinuityOptions {
  bool enabled = true;  // the localizer holds its ceiling frames against one another
  // A lamp of this frame is one of another frame's when it lies within `gate_sigmas` of where the
  // wheels carried it. The spread is the floor bumps' (each frame its own tilt of `tilt_sigma`,
  // rad, moving a lamp by its height above the camera times 1 + |n|^2 of it), plus `sigma_m`.
  double tilt_sigma = 0.0087;  // the ceiling pipeline's (half a degree)
  double sigma_m = 0.01;
  double gate_sigmas = 3.5;
  // Plus this per metre travelled between the two frames: a lamp hung at another height than the
  // map's usual one (it errs by the travel times the height's relative error), the heading's
  // drift.
  double gate_per_m = 0.25;
  // Frames further apart than this (m of the wheels' travel, turning included) are not compared:
  // the gate would cover the spacing of lamps.
  double max_travel_m = 1.5;
  // A lamp counts as in view (to be seen again, or to have been seen) when its centre lies at
  // least this fraction of the image's width and height inside the image: there a lamp is in
  // full view or completed (docs/ceiling-pipeline.md), not cut down to a sliver.
  double margin = 0.15;
  void validate() const;  // throws InputError naming the field
};

struct ContinuityVerdict {
  bool compared = false;  // the frame had lamps and a recent frame to hold them against
  bool odd = false;       // it does not agree with that frame (below)
  bool broken = false;    // the ceiling camera saw a move the wheels did not
  // Against the last frame that agreed with the ones before it:
  int matched = 0;   // lamps of this frame where the wheels put one of that frame's
  int appeared = 0;  // lamps of this frame, in view then, that it did not have
  int vanished = 0;  // lamps of it, in view now, that this frame does not have
  Stamp since;       // its capture time: a move is after it
  Stamp moved_by;    // broken: the odd frame's capture time; the move is before it
  std::string why;   // broken: the evidence in words
};

class CeilingContinuity {
 public:
  // `lamp_height`: the height (m above the floor) the lamps are taken at. Throws lampnav::Error
  // when the camera is not a ceiling camera model, InputError for bad options.
  CeilingContinuity(const CameraDescription& camera, double lamp_height,
                    const CeilingContinuityOptions& options = {});
  ~CeilingContinuity();
  CeilingContinuity(CeilingContinuity&&) noexcept;

  // The lamps (full and completed views; partial ones are left out) of a frame captured at
  // `stamp`, with the dead reckoning that covers it. A frame with no lamp, or captured before
  // the last one, changes nothing.
  ContinuityVerdict frame(Stamp stamp, const std::vector<vision::LampDetection>& lamps,
                          const OdometryTrack& odometry);
  // Forgets the last frame (the dead reckoning started again).
  void reset();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::fusion
