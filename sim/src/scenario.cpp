#include "lampnav/sim/scenario.hpp"

#include <cmath>
#include <queue>
#include <random>

#include "joystick.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/graph/planner.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav/io/mission_log.hpp"
#include "world.hpp"

namespace lampnav::sim {

using Eigen::Vector2d;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

void check(bool ok, const char* field, const std::string& message) {
  if (!ok) throw InputError({"", "scenario", field}, message);
}

double path_length(const std::vector<Vector2d>& pts) {
  double len = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) len += (pts[i] - pts[i - 1]).norm();
  return len;
}

// Start pose: at the first waypoint, facing the second.
Pose2 start_of(const std::vector<Vector2d>& pts) {
  if (pts.size() < 2) return pts.empty() ? Pose2() : Pose2(pts[0], 0.0);
  const Vector2d d = pts[1] - pts[0];
  return {pts[0], std::atan2(d.y(), d.x())};
}

const graph::Node& need(const graph::TopologicalMap& map, const std::string& name,
                        const std::string& scenario) {
  const graph::Node* n = map.find_node(name);
  if (!n)
    throw InputError({"", "scenario " + scenario, "map"},
                     "the map has no node named '" + name + "'");
  return *n;
}

}  // namespace

void Scenario::validate() const {
  check(max_speed > 0 && max_speed <= 3, "max_speed", "must be in (0, 3] m/s");
  check(odometry_rate >= 10 && odometry_rate <= 1000, "odometry_rate", "must be 10 to 1000 Hz");
  check(ceiling_rate >= 0 && ceiling_rate <= 100, "ceiling_rate", "must be 0 to 100 Hz");
  check(omni_rate >= 0 && omni_rate <= 100, "omni_rate", "must be 0 to 100 Hz");
  check(ceiling_delay_s >= 0 && ceiling_delay_s <= 10, "ceiling_delay_s", "must be 0 to 10 s");
  check(omni_delay_s >= 0 && omni_delay_s <= 10, "omni_delay_s", "must be 0 to 10 s");
  check(frame_drop_probability >= 0 && frame_drop_probability <= 1, "frame_drop_probability",
        "must be 0 to 1");
  check(bump_sigma_rad >= 0 && bump_sigma_rad <= 10 * kDeg, "bump_sigma",
        "must be 0 to 10 degrees");
  check(waypoints.size() >= 2, "waypoints", "a scenario needs a path of at least two points");
  check(jump_m > 0, "jump_m", "must be positive");
  for (const auto& id : failed_lamps) {
    check(map.find_lamp(LampId(id)) != nullptr, "failed_lamps", "the map has no lamp '" + id + "'");
  }
  if (ceiling_rate > 0) {
    check(robot.find_camera("ceiling_camera") != nullptr, "robot",
          "the robot has no camera named ceiling_camera");
  }
  if (omni_rate > 0) {
    check(robot.find_camera("omni_camera") != nullptr, "robot",
          "the robot has no camera named omni_camera");
  }
  if (!goal.empty())
    check(map.find_node(goal) != nullptr, "goal", "the map has no node named '" + goal + "'");
  odometry.validate();
  ceiling.validate();
  omni.validate();
}

std::vector<std::string> scenario_names() {
  return {"corridor", "domus-global", "domus-kidnap", "office-mission"};
}

Scenario make_route_scenario(const graph::TopologicalMap& map, const std::string& map_geojson,
                             const RobotDescription& robot, const std::string& from,
                             const std::string& to, std::uint64_t seed) {
  const graph::Node& a = need(map, from, "route");
  const graph::Node& b = need(map, to, "route");
  const auto route = graph::plan_route(map, a.id, b.id);
  if (!route) throw JobFailed("no route from '" + from + "' to '" + to + "'");
  Scenario s;
  s.name = "route " + from + " -> " + to;
  s.map = map;
  s.map_geojson = map_geojson;
  s.robot = robot;
  s.waypoints = graph::route_waypoints(map, *route);
  if (s.waypoints.size() < 2)
    throw InputError({"", "--route", ""}, "start and goal are the same place");
  s.start = start_of(s.waypoints);
  s.goal = to;
  for (const auto& c : graph::route_to_commands(map, *route)) s.commands.push_back(c.text());
  s.seed = seed;
  return s;
}

Scenario make_named_scenario(const std::string& name, const graph::TopologicalMap& map,
                             const std::string& map_geojson, const RobotDescription& robot,
                             std::uint64_t seed) {
  if (name == "corridor") {
    // A long corridor run on the office floor: along C1, straight through J1, along C2.
    Scenario s = make_route_scenario(map, map_geojson, robot, "E1", "K1", seed);
    s.name = name;
    return s;
  }
  if (name == "office-mission") {
    // Across the office floor, kidnapped halfway into corridor C2 (lifted and put down facing
    // west), then on to the goal.
    Scenario s = make_route_scenario(map, map_geojson, robot, "E1", "Workshop", seed);
    s.name = name;
    const graph::Node& c2 = need(map, "C2", name);
    const double half = path_length(s.waypoints) / s.max_speed / 2;
    s.kidnaps.push_back(
        {half, Pose2(c2.axis ? c2.axis->point_at(0.55 * c2.axis->length()) : c2.point, M_PI)});
    return s;
  }
  if (name == "domus-global" || name == "domus-kidnap") {
    for (const char* hall : {"E", "A", "B"}) need(map, hall, name);
    Scenario s;
    s.name = name;
    s.map = map;
    s.map_geojson = map_geojson;
    s.robot = robot;
    s.seed = seed;
    s.ceiling_rate = 0;  // paper 1 used the omnidirectional camera alone
    s.omni_rate = 1.0;   // one image a second, as in paper 1
    s.omni_delay_s = 0.3;
    s.max_speed = 0.4;
    if (name == "domus-global") {
      // 60 images along a 24 m path at up to 0.4 m/s, through area E into area B.
      s.waypoints = {{-3.0, -3.0}, {10.0, -3.0}, {14.0, 0.0}, {20.0, 1.5}};
    } else {
      // Jumps of about 4 m between images over a path of more than 40 m through A, E and B.
      s.waypoints = {{-5.0, -8.0}, {20.0, -8.0}, {20.0, -3.0},
                     {2.0, -3.0},  {16.0, 1.0},  {26.0, 2.5}};
      s.carried = true;
      s.jump_m = 4.0;
    }
    s.start = start_of(s.waypoints);
    return s;
  }
  std::string names;
  for (const auto& n : scenario_names()) names += (names.empty() ? "" : ", ") + n;
  throw InputError({"", "--scenario", ""},
                   "unknown scenario '" + name + "' (known: " + names + ")");
}

// ---------------------------------------------------------------------------------------------
// Recording.

namespace {

// Points every `step` metres along a polyline, with the heading of the segment they lie on.
std::vector<Pose2> resample(const std::vector<Vector2d>& pts, double step) {
  std::vector<Pose2> out;
  double carry = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const Vector2d a = pts[i - 1], b = pts[i];
    const double len = (b - a).norm();
    const double yaw = std::atan2(b.y() - a.y(), b.x() - a.x());
    double s = carry;
    for (; s <= len; s += step) out.emplace_back(a + (b - a) * (s / len), yaw);
    carry = s - len;
  }
  return out;
}

}  // namespace

RecordStats record_mission(const Scenario& s, const std::string& path,
                           const std::function<void(double)>& progress) {
  s.validate();
  World world(s, path);
  if (s.carried) {
    // Carried between captures: each capture point is a kidnap from the last; the wheels never
    // turn (their readings stay put, so odometry knows nothing of the jumps).
    const auto stops = resample(s.waypoints, s.jump_m);
    const std::int64_t omni_ns = s.omni_rate > 0 ? std::llround(1e9 / s.omni_rate) : 0;
    const std::int64_t period = omni_ns > 0 ? 2 * omni_ns : 2'000'000'000;
    std::normal_distribution<double> jitter(0.0, 1.0);
    std::mt19937_64& rng_jitter = world.event_rng();
    for (std::size_t i = 0; i < stops.size(); ++i) {
      const Pose2 stop(stops[i].x() + 0.3 * jitter(rng_jitter),
                       stops[i].y() + 0.3 * jitter(rng_jitter),
                       stops[i].yaw() + 20 * kDeg * jitter(rng_jitter));
      if (i > 0) {
        world.put_down(stop, "carried to the next stop");
        world.stats().path_length_m += (stops[i].translation() - stops[i - 1].translation()).norm();
      } else {
        world.place(stop);
      }
      for (std::int64_t k = 0; k < period; k += world.period_ns()) {
        world.hold();
        if (k == world.period_ns()) world.capture_all();
        world.deliver(world.now_ns());
        world.advance();
      }
      if (progress) progress(static_cast<double>(i + 1) / stops.size());
    }
    world.stats().arrived = true;
  } else {
    JoystickOptions joystick;
    joystick.max_speed = s.max_speed;
    Joystick follower(s.waypoints, joystick);
    const double expected = path_length(s.waypoints) / s.max_speed;
    std::size_t kidnap_index = 0;
    while (!follower.arrived() &&
           world.now_ns() < static_cast<std::int64_t>(s.max_duration_s * 1e9)) {
      const double t_s = world.now_ns() * 1e-9;
      if (kidnap_index < s.kidnaps.size() && t_s >= s.kidnaps[kidnap_index].at_s) {
        const Kidnap& k = s.kidnaps[kidnap_index++];
        const Pose2 to = k.to ? *k.to : world.random_place();
        world.put_down(to);
        // The person at the joystick drives on to the goal from where the robot now stands.
        std::vector<Vector2d> pts{to.translation()};
        if (!s.goal.empty()) {
          if (const auto route = graph::plan_route(s.map, to, s.map.find_node(s.goal)->id)) {
            for (const auto& p : graph::route_waypoints(s.map, *route)) pts.push_back(p);
          }
        }
        if (pts.size() < 2) pts.push_back(s.waypoints.back());
        follower = Joystick(pts, joystick);
      }
      const auto [v, w] = follower.steer(world.pose());
      world.drive(v, w);
      world.deliver(world.now_ns());
      if (progress && (world.now_ns() / world.period_ns()) % 50 == 0)
        progress(std::min(0.99, t_s / std::max(1.0, expected)));
    }
    world.stats().arrived = follower.arrived();
  }
  world.finish();
  if (progress) progress(1.0);
  return world.stats();
}

}  // namespace lampnav::sim
