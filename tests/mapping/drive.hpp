#pragma once
// A drive for mapping tests: through waypoints (turn on the spot, then straight), with wheels that
// have a scale error and noise, and the ideal lamp detections of the ceiling camera at 10 Hz (and
// of the omni camera, when asked).

#include <functional>
#include <random>
#include <vector>

#include "edited_map.hpp"
#include "lampnav/core/pose2.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"
#include "lampnav/sim/lamp_sensors.hpp"
#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::test {

struct DriveOptions {
  double speed = 0.5, turn_rate = 0.6;  // m/s, rad/s
  double scale_error_left = 0.004, scale_error_right = -0.003;
  double wheel_noise = 0.002;  // m per sqrt(m)
  double ceiling_rate = 10;    // Hz
  double omni_rate = 0;        // Hz (0: no omni views)
  std::uint64_t seed = 1;
};

struct DriveRecord {
  struct Wheels {
    Stamp stamp;
    double left, right;  // cumulative, m, as measured
  };
  struct Frame {
    Stamp stamp;
    Pose2 truth;
    std::vector<vision::LampDetection> lamps;
  };
  struct OmniFrame {
    Stamp stamp;
    vision::OmniDetection detection;
  };
  std::vector<Wheels> wheels;
  std::vector<Frame> frames;
  std::vector<OmniFrame> omni;
  Pose2 start;
  double length_m = 0;
};

// The centres of the lamps a drive mapped.
std::vector<Eigen::Vector3d> lamp_centres(const mapping::MappingResult& mapped);

// The lamp SLAM over a recorded drive, wheels and frames in time order.
mapping::MappingResult map_drive(const DriveRecord& drive, const RobotDescription& robot,
                                 const mapping::LampMapperOptions& options = {});

// Through a grid building's junctions and corners, row by row (serpentine), then column by
// column: every corridor driven, every junction passed twice (which closes the loops). The path
// follows the map's routes between them.
std::vector<Eigen::Vector2d> every_corridor_twice(const graph::TopologicalMap& map);

// The office floor's corridors, every one driven once and C6 twice: E1, J1, K1, K2, J2, E2 and
// back through J2 and C5 to J1.
std::vector<Eigen::Vector2d> office_every_corridor();

DriveRecord drive_through(const std::vector<Eigen::Vector2d>& waypoints, double start_yaw,
                          const sim::LampSensors& sensors, double semi_axis,
                          const DriveOptions& options = {});

// The bundled office floor and robot, driven with the ideal detections of its working lamps.
struct Office {
  graph::TopologicalMap map;
  RobotDescription robot;
  Office();
  // Through the waypoints from the first, facing the second.
  DriveRecord drive(const std::vector<Eigen::Vector2d>& waypoints,
                    const DriveOptions& options = {}) const;
};

}  // namespace lampnav::test
