#pragma once
// The bundled office floor and robot, and poses on its corridor C1, shared by the navigation unit
// tests (executor, runtime).

#include <cmath>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav_test.hpp"

namespace lampnav::test {

struct NavOffice {
  RobotDescription robot = read_robot_description(source_path("maps/robots/pioneer.json"));
  graph::TopologicalMap map =
      graph::parse_map(slurp(source_path("maps/office_floor.geojson")), "office").map;
  // A pose on corridor C1's axis, facing its second end, `along` metres from the first.
  Pose2 on_c1(double along) const {
    const graph::Axis& a = *map.find_node("C1")->axis;
    const Eigen::Vector2d d = a.direction();
    return {a.point_at(along), std::atan2(d.y(), d.x())};
  }
};

// `s` seconds of robot time.
inline Stamp at_s(double s) {
  return Stamp(std::chrono::milliseconds(static_cast<long>(s * 1000)));
}

}  // namespace lampnav::test
