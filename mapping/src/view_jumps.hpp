#pragma once
// Where a drive's ceiling view jumps as no driving could make it: the robot lifted and put down
// elsewhere (a kidnap), which the wheels do not see. Private to mapping/: a map build maps the
// parts between jumps apart, since the lamps after a jump would be placed where the wheels say
// the robot still is, and joins a part to the map only where its lamps fit one place
// (part_placement.hpp).

#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::mapping {

struct ViewJumpOptions {
  double margin = 0.15;  // of the image size: a whole lamp this far in cannot leave in a frame
  double gate = 0.05;    // normalized: a lamp's centre is measured this far off its predicted place
  double enter = 0.1;  // normalized: a lamp entering the view is first seen by this far in, at most
  double min_height_m = 1.0;  // the lamps are at least this far above the camera
};

// One ceiling frame: when, the wheels' cumulative travel then, and what the detector found.
struct ViewFrame {
  Stamp stamp;
  double left = 0, right = 0;                                 // m
  const std::vector<vision::LampDetection>* lamps = nullptr;  // nullptr: unreadable
};

// The index of the first frame after each jump, in order. A jump: between two frames with lamps
// (frames without any are passed over), every lamp of the earlier one, whole or cut by the
// border, is gone from where the wheels' motion could have taken it; a lamp of the later one
// reaches further into the view than it could have entered since, and came from no lamp of the
// earlier one (a lamp does not appear in the middle of the view by driving); and the next frame
// with lamps still shows the new view.
std::vector<std::size_t> view_jumps(const std::vector<ViewFrame>& frames,
                                    const CameraDescription& camera, double semi_axis,
                                    const ViewJumpOptions& options = {});

}  // namespace lampnav::mapping
