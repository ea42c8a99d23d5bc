#pragma once
// The bundled office floor and robot, shared by the ceiling-camera tests.

#include "lampnav/core/robot_description.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav_test.hpp"

namespace lampnav::test {

struct OfficeWorld {
  RobotDescription robot = read_robot_description(source_path("maps/robots/pioneer.json"));
  graph::TopologicalMap map = graph::read_map(source_path("maps/office_floor.geojson")).map;
  const CameraDescription& camera() const { return *robot.find_camera("ceiling_camera"); }
};

}  // namespace lampnav::test
