#pragma once
// Where a drive's ceiling view jumps as no driving could make it: the robot lifted and put down
// elsewhere (a kidnap), which the wheels do not see. Private to mapping/: a map build maps the
// parts between jumps apart, since the lamps after a jump would be placed where the wheels say
// the robot still is, and joins a part to the map only where its lamps fit one place
// (part_placement.hpp).

#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::mapping {

struct ViewJumpOptions {
  double margin = 0.15;  // of the image size: a whole lamp this far in cannot leave in a frame
  double gate = 0.05;    // normalized: a lamp's centre is measured this far off its predicted place
  // ... or this many times the 99th percentile of how far the drive's whole lamps of known height
  // lie off their predicted places, if more (floor bumps of 0.5 deg: 0.040 to 0.044; 0.7 deg:
  // 0.062 to 0.064; 1 deg: 0.082 to 0.093).
  double gate_over_p99 = 1.1;
  double enter = 0.1;  // normalized: a lamp entering the view is first seen by this far in, at most
  double min_height_m = 1.0;  // the lamps are at least this far above the camera
  // A lamp's place by the wheels from one whole view, 1 sigma, over its height above the camera
  // (0.03 m under the office's 2.7 m ceiling: floor bumps tilt the camera).
  double place_noise = 0.0125;
  double parallax = 0.2;   // normalized: a lamp's height is fitted once its views spread this far
  double told_spread = 2;  // a lamp not yet fitted is within this factor of the heights fitted
  int window = 5;          // whole views of a lamp averaged on each side of a boundary
  // A lamp's place by the wheels moves this far, over its height: not the same lamp (0.085 m
  // under the office's ceiling; eleven drives without a carry moved places by up to 0.023).
  double moved = 0.035;
  // ... or this many times the 90th percentile of the drive's own moves, if more (floor bumps of
  // 0.5 deg: 0.011 to 0.013, and at most 0.023; of 0.7 deg: 0.016 to 0.018, and at most 0.038).
  double moved_over_p90 = 3;
};

// One ceiling frame: when, the robot's pose then by its wheels alone (dead reckoning in any fixed
// frame, fusion::OdometryTrack's), and what the detector found.
struct ViewFrame {
  Stamp stamp;
  Pose2 wheels;
  const std::vector<vision::LampDetection>* lamps = nullptr;  // nullptr: unreadable
};

// The index of the first frame after each jump, in order. Lamps are followed from frame to
// frame, and a lamp's height above the camera is fitted from its track's whole views once they
// spread across the image; until then it is only known to be at least min_height_m. A jump is
// either of:
// - Between two frames with lamps (frames without any are passed over), the earlier view is gone
//   from where the wheels' motion could have taken it: no lamp whole in either stayed, and some
//   lamp of the earlier one has no counterpart at all. And a lamp of the later one reaches
//   further into the view than it could have entered since, and came from no lamp of the
//   earlier one (a lamp does not appear in the middle of the view by driving). It holds from
//   the frame with lamps before the earlier one, and to the one after the later one: not one
//   bad frame on either side.
// - Every lamp followed across a boundary, with at least three whole views on each side, lies
//   elsewhere on the ceiling after it than before by the wheels (the robot put down where the
//   ceiling looks nearly alike, closer than one frame's gate can tell); not within 2 x window
//   frames with lamps of a jump of the first kind.
std::vector<std::size_t> view_jumps(const std::vector<ViewFrame>& frames,
                                    const CameraDescription& camera,
                                    const ViewJumpOptions& options = {});

}  // namespace lampnav::mapping
