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
#include <optional>
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
  // The floor's swing, learnt from the frames. A lamp seen in two frames a few centimetres of
  // travel apart, carried between them by the wheels, lies off itself by the difference of the
  // two frames' tilts (through the lens: ceiling_geometry.hpp), whatever the map. The median of
  // those offsets over the last `tilt_window` lamps, each normalized by its spread for a tilt of
  // one radian (a chi-square of 2 degrees of freedom times the tilt's variance), gives the tilt's
  // spread as the camera's models take it (a base tilted about the floor also moves the camera:
  // a lamp moves by its height above the floor times the tilt, 1.125 times what the turn of a
  // camera 2.4 m under it alone would do, and the models need that). Once `tilt_min_samples`
  // lamps hold it and it exceeds `tilt_sigma` by `tilt_margin` (a factor) and by twice its own
  // standard error, it takes tilt_sigma's place in the gates here, up to max_tilt_sigma; the
  // localizer gives it to its ceiling models and scales its omni models alike. The detection's
  // own noise is in the offsets too, so the spread learnt is a little larger than the tilt's,
  // never smaller. Only ever raised above tilt_sigma: a swing slow enough to move two frames
  // alike is not seen this way, and the configured value stays the floor.
  bool learn_tilt = true;
  int tilt_window = 300;
  int tilt_min_samples = 50;
  double tilt_margin = 1.3;
  double tilt_pair_travel_m = 0.1;  // frames further apart are not used (lamp heights differ)
  double tilt_match_m = 0.5;        // a lamp's nearest in the other frame, within this, alone
  double max_tilt_sigma = 0.07;     // rad (4 degrees)
  void validate() const;            // throws InputError naming the field
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
  // `steady`: the gates take the configured tilt_sigma, whatever swing was learnt (the
  // localizer while it looks for the robot: a move must not hide in the floor's swing there).
  ContinuityVerdict frame(Stamp stamp, const std::vector<vision::LampDetection>& lamps,
                          const OdometryTrack& odometry, bool steady = false);
  // Forgets the last frame (the dead reckoning started again). The swing learnt is kept: the
  // floor and the mount are the same.
  void reset();

  // The tilt spread (rad) the gates use: options.tilt_sigma, or the swing learnt once it holds.
  double tilt_sigma() const;
  // The swing learnt so far (rad) and how many lamps it rests on; nullopt before
  // tilt_min_samples.
  std::optional<double> learnt_tilt_sigma() const;
  int tilt_samples() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::fusion
