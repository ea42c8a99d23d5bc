#pragma once
// A mapped drive scaled: what a map build does with measured distances, and what a survey does
// to fit a drive to the map. Private to mapping/.

#include <Eigen/Core>

#include "lampnav/mapping/lamp_mapper.hpp"

namespace lampnav::mapping {

// The drive and its lamps scaled by `s` about `about`, heights about the ceiling camera's
// (`camera_z` above the floor): every lamp then projects into every keyframe's camera as before
// (up to the camera's offset from the robot's centre, which does not scale: 0.1 mm for 0.05 % at
// 20 cm), and only the wheels' travel reads `s` times longer.
void scale_drive(MappingResult& drive, double s, const Eigen::Vector2d& about, double camera_z);

}  // namespace lampnav::mapping
