#include "lampnav/sim/odometry.hpp"

#include <algorithm>
#include <cmath>

#include "lampnav/core/error.hpp"

namespace lampnav::sim {

void OdometryErrors::validate() const {
  auto check = [](double v, double lo, double hi, const char* field) {
    if (!(v >= lo && v <= hi)) {
      throw InputError({"", "odometry errors", field},
                       "must be between " + std::to_string(lo) + " and " + std::to_string(hi));
    }
  };
  check(left_scale, -0.2, 0.2, "left_scale");
  check(right_scale, -0.2, 0.2, "right_scale");
  check(semi_axis_error, -0.2, 0.2, "semi_axis_error");
  check(noise_per_sqrt_m, 0.0, 0.1, "noise_per_sqrt_m");
  check(slip_per_m, 0.0, 10.0, "slip_per_m");
  check(slip_fraction, 0.0, 1.0, "slip_fraction");
}

OdometryErrors OdometryErrors::none() {
  OdometryErrors e;
  e.left_scale = e.right_scale = e.semi_axis_error = e.noise_per_sqrt_m = e.slip_per_m = 0.0;
  return e;
}

WheelTravel wheel_travel(double forward, double turn, double semi_axis) {
  return {forward - turn * semi_axis, forward + turn * semi_axis};
}

Pose2 drive(const Pose2& pose, const WheelTravel& t, double semi_axis) {
  const double ds = 0.5 * (t.left + t.right);
  const double dr = (t.right - t.left) / (2.0 * semi_axis);
  const double mid = pose.yaw() + 0.5 * dr;
  return {pose.x() + ds * std::cos(mid), pose.y() + ds * std::sin(mid), pose.yaw() + dr};
}

WheelEncoders::WheelEncoders(const OdometryErrors& errors, std::uint64_t seed)
    : e_(errors), rng_(seed) {
  e_.validate();
}

double WheelEncoders::measure(double truth, double scale) {
  double m = truth * (1.0 + scale);
  const double d = std::fabs(truth);
  if (d > 0 && e_.noise_per_sqrt_m > 0) {
    std::normal_distribution<double> n(0.0, e_.noise_per_sqrt_m * std::sqrt(d));
    m += n(rng_);
  }
  if (d > 0 && e_.slip_per_m > 0) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (u(rng_) < e_.slip_per_m * d) {
      m += truth * e_.slip_fraction;  // the wheel spun further than the robot moved
      ++slips_;
    }
  }
  return m;
}

WheelTravel WheelEncoders::step(const WheelTravel& truth) {
  cumulative_.left += measure(truth.left, e_.left_scale);
  cumulative_.right += measure(truth.right, e_.right_scale);
  return cumulative_;
}

PathFollower::PathFollower(std::vector<Eigen::Vector2d> waypoints, Options options)
    : pts_(std::move(waypoints)), o_(options) {
  if (pts_.size() < 2) arrived_ = true;
}

std::pair<double, double> PathFollower::command(const Pose2& pose) {
  if (arrived_) return {0.0, 0.0};
  const Eigen::Vector2d p = pose.translation();
  // Advance past segments whose end is behind us.
  while (seg_ + 2 < pts_.size()) {
    const Eigen::Vector2d a = pts_[seg_], b = pts_[seg_ + 1];
    const double t = (p - a).dot(b - a) / std::max(1e-12, (b - a).squaredNorm());
    if (t < 1.0) break;
    ++seg_;
  }
  const Eigen::Vector2d goal = pts_.back();
  const double to_goal = (goal - p).norm();
  if (seg_ + 2 >= pts_.size() && to_goal < o_.goal_tolerance) {
    arrived_ = true;
    return {0.0, 0.0};
  }
  // Look-ahead point: walk `lookahead` metres along the path from the foot of p on this segment.
  const Eigen::Vector2d a = pts_[seg_], b = pts_[seg_ + 1];
  const double len = (b - a).norm();
  double s = len > 0 ? std::clamp((p - a).dot(b - a) / len, 0.0, len) : 0.0;
  double remaining = o_.lookahead;
  std::size_t k = seg_;
  Eigen::Vector2d target = b;
  while (true) {
    const Eigen::Vector2d u = pts_[k], v = pts_[k + 1];
    const double l = (v - u).norm();
    if (s + remaining <= l || k + 2 >= pts_.size()) {
      target = l > 0 ? Eigen::Vector2d(u + (v - u) * std::min(1.0, (s + remaining) / l)) : v;
      break;
    }
    remaining -= (l - s);
    s = 0;
    ++k;
  }
  const Eigen::Vector2d local = pose.transform_to(target);
  const double heading_error = std::atan2(local.y(), local.x());
  double turn = std::clamp(2.0 * heading_error, -o_.max_turn_rate, o_.max_turn_rate);
  // Slow down when the target is off to the side (turn on the spot past 60 degrees) and near
  // the goal.
  double speed =
      o_.max_speed * std::max(0.0, std::cos(std::min(std::fabs(heading_error) * 1.5, M_PI / 2)));
  speed = std::min(speed, std::max(0.05, 0.8 * to_goal));
  return {speed, turn};
}

}  // namespace lampnav::sim
