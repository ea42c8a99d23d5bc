#pragma once
// Frame-to-frame tracking of ceiling lamps: a lamp keeps its track id while it stays in view, a
// lamp entering the view starts a new track, and a track whose lamp leaves the view (or is lost)
// ends and is reported once. Measurements come from the LampDetector (sub-pixel, undistorted,
// completed at the border).
//
// Windowed tracking: each track predicts where its lamp will be in the next frame (its last image
// motion, constant velocity), and between full detections the tracker reads only windows around
// those predictions, around the small blobs cut by the border (a lamp entering or leaving), and
// the one-pixel ring of the image border, which every lamp entering the view must cross (its left
// and right columns read every LampDetector::border_chord_px() / 3 pixels, so that a lamp
// entering there covers three of the pixels read). A frame is read whole on a schedule, after a
// reset, and whenever the windows cannot vouch for the frame: something bright on the border ring
// outside every window, a blob reaching a window's edge, a track whose lamp is not in its window.
// A blob wholly inside a window is measured exactly as a full detection measures it, so windowed
// frames report the same lamps.

#include <memory>
#include <vector>

#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::vision {

struct LampTrackerOptions {
  int max_tracks = 32;        // live tracks at most; new lamps beyond it are not tracked
  double max_step_px = 60.0;  // px: a lamp further than this from its track's predicted centre
                              // is another blob: the track ends
  // Frames: the whole frame is read at least this often, for lamps that appear away from the
  // border (switched on, no longer hidden). 1 reads every frame whole (no windows).
  int full_detection_every = 10;
  int window_margin_px = 6;  // px added around each predicted box, beyond the last frame's change
                             // of motion
  void validate() const;     // throws InputError naming the field
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
  DetectionStats stats;    // of the pixels read
  bool whole = true;       // the frame was read whole (else only the windows and the ring)
  long pixels_read = 0;    // pixels the detection thresholded (windows, ring)
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
  // Ends every track (after a kidnap or a long gap); they are reported ended by the next frame,
  // which is read whole.
  void reset();
  int live_tracks() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::vision
