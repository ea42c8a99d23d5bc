#pragma once
// A simulated mission: the world (map, robot, lamps that work), how a person drives it, what
// happens on the way (kidnaps, frame drops, camera delays, floor bumps), and its recording as a
// mission log (shared/spec/mission-log.md) with truth. Every scenario is reproducible from its
// seed: the same seed writes the same bytes.

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/io/image_encoding.hpp"
#include "lampnav/sim/odometry.hpp"
#include "lampnav/sim/renderers.hpp"

namespace lampnav::sim {

// The robot is lifted at `at_s` seconds and put down at `to` (or, without it, at a random place
// along a corridor, or in a hall, drawn from the scenario's seed). Odometry knows nothing of it.
struct Kidnap {
  double at_s = 0;
  std::optional<Pose2> to;
};

struct Scenario {
  std::string name;
  graph::TopologicalMap map;
  std::string map_geojson;  // attached to the log as map.geojson
  RobotDescription robot;
  Pose2 start;
  std::vector<Eigen::Vector2d> waypoints;  // the path driven from `start`
  std::string goal;                        // goal node: after a kidnap the path is re-planned to it
  std::vector<std::string> commands;       // route commands given at the start (/commands)

  double max_speed = 0.5;        // m/s
  double odometry_rate = 50.0;   // Hz
  double ceiling_rate = 10.0;    // Hz; 0 records no ceiling camera
  double omni_rate = 1.0;        // Hz; 0 records no omnidirectional camera
  double ceiling_delay_s = 1.0;  // capture to availability (paper 2: about 1 s)
  double omni_delay_s = 0.5;
  double frame_drop_probability = 0.02;
  double bump_sigma_rad = 0.5 * 3.14159265358979323846 / 180.0;  // floor bumps; 0 turns them off
  std::vector<Kidnap> kidnaps;
  // domus-kidnap: the robot is carried between captures (jumps of `jump_m`), never driven.
  bool carried = false;
  double jump_m = 4.0;
  std::set<std::string> failed_lamps;
  OdometryErrors odometry;
  CeilingRenderOptions ceiling;
  OmniRenderOptions omni;
  // How the log stores the frames. The simulated robot sees each frame as the log holds it (a
  // JPEG frame decoded again), so that a replay of the log is the live run exactly.
  io::ImageEncoding images;
  std::uint64_t seed = 1;
  double max_duration_s = 900.0;

  // Throws InputError naming the field when a setting is out of range or a name is not in the map.
  void validate() const;
};

// The named scenarios: "corridor", "domus-global", "domus-kidnap", "office-mission".
std::vector<std::string> scenario_names();
// Builds a named scenario on `map` (the office floor for corridor and office-mission, the Domus
// museum for the others); throws InputError when the map lacks the places the scenario needs.
Scenario make_named_scenario(const std::string& name, const graph::TopologicalMap& map,
                             const std::string& map_geojson, const RobotDescription& robot,
                             std::uint64_t seed);
// A scenario that drives the planned route between two named places.
Scenario make_route_scenario(const graph::TopologicalMap& map, const std::string& map_geojson,
                             const RobotDescription& robot, const std::string& from,
                             const std::string& to, std::uint64_t seed);

struct RecordStats {
  double duration_s = 0;
  std::size_t wheel_messages = 0, ceiling_frames = 0, omni_frames = 0, dropped_frames = 0;
  std::size_t kidnaps = 0;
  int slips = 0;
  bool arrived = false;
  double path_length_m = 0;
};

// Records the scenario to an MCAP mission log. `progress` (if set) is called with the fraction
// of the way done.
RecordStats record_mission(const Scenario& scenario, const std::string& path,
                           const std::function<void(double)>& progress = {});

}  // namespace lampnav::sim
