#pragma once
// Frame-to-frame tracking of ceiling lamps with ViSP's vpDot2: a lamp keeps its track id while it
// stays in view, a lamp entering the view starts a new track, and a track whose lamp leaves the
// view (or is lost) ends and is reported once. Each frame's measurements come from the
// LampDetector (sub-pixel, undistorted, completed at the border); vpDot2 carries the identity of
// each blob from one frame to the next.

#include <memory>
#include <vector>

#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::vision {

struct LampTrackerOptions {
  int max_tracks = 32;        // live tracks at most; new lamps beyond it are not tracked
  double max_step_px = 60.0;  // px: a tracked centre moving more than this in one frame
                              // means the blob was confused with another: the track ends
  void validate() const;      // throws InputError naming the field
};

struct TrackedLamp {
  int track_id = 0;  // unique over the tracker's life, never reused
  int age = 0;       // frames this track has been seen in, this one included
  bool is_new = false;
  LampDetection detection;
};

struct TrackedFrame {
  std::vector<TrackedLamp> lamps;
  std::vector<int> ended;  // tracks that ended in this frame (their lamp is gone)
  DetectionStats stats;
};

class LampTracker {
 public:
  LampTracker(const CameraDescription& camera, const LampShapePrior& prior,
              const LampDetectorOptions& detector = {}, const LampTrackerOptions& options = {});
  ~LampTracker();
  LampTracker(LampTracker&&) noexcept;
  LampTracker& operator=(LampTracker&&) noexcept;

  // Detects and tracks the lamps of the next frame. Throws InputError for a frame that is not an
  // image of the camera's size (see check_image); the tracks are then left as they were.
  TrackedFrame process(const ImageView& image);
  TrackedFrame process(const Image8& image) { return process(ImageView::of(image)); }
  // Ends every track (after a kidnap or a long gap); they are reported ended by the next frame.
  void reset();
  int live_tracks() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::vision
