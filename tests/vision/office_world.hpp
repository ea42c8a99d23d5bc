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
  // The same ceiling camera at 640x480: focal lengths scaled with the width, centre in the middle.
  CameraDescription camera_640() const {
    CameraDescription c = camera();
    const double scale = 640.0 / c.width;
    c.pinhole.fx *= scale;
    c.pinhole.fy *= scale;
    c.width = 640;
    c.height = 480;
    c.pinhole.cx = 0.5 * (c.width - 1);
    c.pinhole.cy = 0.5 * (c.height - 1);
    return c;
  }
};

}  // namespace lampnav::test
