#include "drive.hpp"

#include <cmath>

#include <algorithm>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/planner.hpp"
#include "lampnav_test.hpp"

namespace lampnav::test {

DriveRecord drive_through(const std::vector<Eigen::Vector2d>& waypoints, double start_yaw,
                          const sim::LampSensors& sensors, double semi_axis,
                          const DriveOptions& o) {
  DriveRecord rec;
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  Pose2 truth(waypoints.front(), start_yaw);
  rec.start = truth;
  const double dt = 0.02;
  double t = 0, left = 0, right = 0, next_frame = 0.01, next_omni = 0.015;
  auto stamp = [](double s) { return Stamp(std::chrono::nanoseconds(std::llround(s * 1e9))); };
  auto step = [&](double v, double w) {
    truth = truth * Pose2(v * dt, 0.0, w * dt);
    const double dl = (v - w * semi_axis) * dt, dr = (v + w * semi_axis) * dt;
    left += dl * (1 + o.scale_error_left) + o.wheel_noise * std::sqrt(std::abs(dl)) * n01(rng);
    right += dr * (1 + o.scale_error_right) + o.wheel_noise * std::sqrt(std::abs(dr)) * n01(rng);
    rec.length_m += 0.5 * (std::abs(dl) + std::abs(dr));
    t += dt;
    rec.wheels.push_back({stamp(t), left, right});
    if (t >= next_frame) {
      next_frame += 1.0 / o.ceiling_rate;
      rec.frames.push_back({stamp(t), truth, sensors.ceiling(truth, rng)});
    }
    if (o.omni_rate > 0 && t >= next_omni) {
      next_omni += 1.0 / o.omni_rate;
      rec.omni.push_back({stamp(t), sensors.omni(truth, rng)});
    }
  };
  rec.wheels.push_back({stamp(0), 0, 0});
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    const Eigen::Vector2d d = waypoints[i] - truth.translation();
    const double heading = std::atan2(d.y(), d.x());
    double turn = wrap_angle(heading - truth.yaw());
    while (std::abs(turn) > o.turn_rate * dt) {
      step(0, turn > 0 ? o.turn_rate : -o.turn_rate);
      turn = wrap_angle(heading - truth.yaw());
    }
    double remaining = (waypoints[i] - truth.translation()).norm();
    while (remaining > o.speed * dt) {
      // Steer gently towards the waypoint, as a driver would.
      const Eigen::Vector2d to = waypoints[i] - truth.translation();
      const double err = wrap_angle(std::atan2(to.y(), to.x()) - truth.yaw());
      step(o.speed, std::clamp(2.0 * err, -o.turn_rate, o.turn_rate));
      remaining = (waypoints[i] - truth.translation()).norm();
    }
  }
  return rec;
}

mapping::MappingResult map_drive(const DriveRecord& drive, const RobotDescription& robot,
                                 const mapping::LampMapperOptions& options) {
  mapping::LampMapper mapper(robot, options);
  std::size_t w = 0;
  for (const auto& f : drive.frames) {
    for (; w < drive.wheels.size() && drive.wheels[w].stamp <= f.stamp; ++w)
      mapper.wheels(drive.wheels[w].stamp, drive.wheels[w].left, drive.wheels[w].right);
    mapper.ceiling(f.stamp, f.lamps);
  }
  return mapper.finish();
}

std::vector<Eigen::Vector3d> lamp_centres(const mapping::MappingResult& mapped) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& l : mapped.lamps) out.push_back(l.xyz);
  return out;
}

Office::Office()
    : map(graph::read_map(source_path("maps/office_floor.geojson")).map),
      robot(read_robot_description(source_path("maps/robots/pioneer.json"))) {}

DriveRecord Office::drive(const std::vector<Eigen::Vector2d>& waypoints,
                          const DriveOptions& options) const {
  const sim::LampSensors sensors(map, robot);
  const Eigen::Vector2d d = waypoints[1] - waypoints[0];
  return drive_through(waypoints, std::atan2(d.y(), d.x()), sensors, robot.semi_axis, options);
}

std::vector<Eigen::Vector2d> every_corridor_twice(const graph::TopologicalMap& map) {
  std::vector<const graph::Node*> places;
  for (const auto& n : map.nodes())
    if (n.place == graph::Place::junction || n.place == graph::Place::corner) places.push_back(&n);
  std::vector<NodeId> targets;
  auto serpentine = [&](bool by_rows) {
    std::vector<const graph::Node*> sorted = places;
    auto key = [by_rows](const graph::Node* n) {
      return by_rows ? std::make_pair(std::round(n->point.y()), n->point.x())
                     : std::make_pair(std::round(n->point.x()), n->point.y());
    };
    std::sort(sorted.begin(), sorted.end(),
              [&](const auto* a, const auto* b) { return key(a) < key(b); });
    std::vector<std::vector<const graph::Node*>> lines;
    for (const auto* p : sorted) {
      if (lines.empty() || key(lines.back().front()).first != key(p).first) lines.emplace_back();
      lines.back().push_back(p);
    }
    for (std::size_t r = 0; r < lines.size(); ++r) {
      if (r % 2) std::reverse(lines[r].begin(), lines[r].end());
      for (const auto* p : lines[r]) targets.push_back(p->id);
    }
  };
  serpentine(true);
  serpentine(false);
  std::vector<Eigen::Vector2d> waypoints = {map.node(targets.front()).point};
  for (std::size_t i = 1; i < targets.size(); ++i) {
    if (targets[i] == targets[i - 1]) continue;
    const auto route = graph::plan_route(map, targets[i - 1], targets[i]);
    if (!route) continue;  // a place the missing corridors cut off
    for (std::size_t k = 1; k < route->nodes.size(); ++k) {
      const graph::Node& n = map.node(route->nodes[k]);
      if (n.place == graph::Place::junction || n.place == graph::Place::corner)
        waypoints.push_back(n.point);
    }
  }
  return waypoints;
}

std::vector<Eigen::Vector2d> office_every_corridor() {
  return {{1, 10}, {21, 10}, {41, 10}, {41, -8}, {21, -8}, {1, -8}, {21, -8}, {21, 10}};
}

}  // namespace lampnav::test
