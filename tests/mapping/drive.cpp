#include "drive.hpp"

#include <cmath>

#include "lampnav/graph/geojson.hpp"
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
  double t = 0, left = 0, right = 0, next_frame = 0.01;
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

Office::Office()
    : map(graph::read_map(source_path("maps/office_floor.geojson")).map),
      robot(read_robot_description(source_path("maps/robots/pioneer.json"))) {}

DriveRecord Office::drive(const std::vector<Eigen::Vector2d>& waypoints,
                          const DriveOptions& options) const {
  const sim::LampSensors sensors(map, robot);
  const Eigen::Vector2d d = waypoints[1] - waypoints[0];
  return drive_through(waypoints, std::atan2(d.y(), d.x()), sensors, robot.semi_axis, options);
}

std::vector<Eigen::Vector2d> office_every_corridor() {
  return {{1, 10}, {21, 10}, {41, 10}, {41, -8}, {21, -8}, {1, -8}, {21, -8}, {21, 10}};
}

}  // namespace lampnav::test
