#include "joystick.hpp"

#include <algorithm>
#include <cmath>

namespace lampnav::sim {

Joystick::Joystick(std::vector<Eigen::Vector2d> waypoints, const JoystickOptions& options)
    : waypoints_(std::move(waypoints)), o_(options) {
  arrived_ = waypoints_.size() < 2;
}

std::pair<double, double> Joystick::steer(const Pose2& truth) {
  if (arrived_) return {0.0, 0.0};
  const Eigen::Vector2d at = truth.translation();
  const std::size_t last = waypoints_.size() - 1;
  // A waypoint is passed when close, or when the robot is already nearer the one after it.
  while (next_ < last) {
    const Eigen::Vector2d w = waypoints_[next_];
    const bool close = (w - at).norm() < o_.reach;
    const bool beyond = (waypoints_[next_ + 1] - at).norm() < (waypoints_[next_ + 1] - w).norm();
    if (!close && !beyond) break;
    ++next_;
  }
  const double to_goal = (waypoints_[last] - at).norm();
  if (next_ == last && to_goal < o_.goal_tolerance) {
    arrived_ = true;
    return {0.0, 0.0};
  }
  const Eigen::Vector2d seen = truth.transform_to(waypoints_[next_]);
  const double off = std::atan2(seen.y(), seen.x());
  const double turn = std::clamp(1.5 * off, -o_.max_turn_rate, o_.max_turn_rate);
  if (std::fabs(off) > o_.turn_on_spot) return {0.0, turn};
  // Full speed when the waypoint is dead ahead, less as it drifts aside; gentle at the goal.
  const double ahead = 1.0 - std::fabs(off) / o_.turn_on_spot;
  double speed = o_.max_speed * (0.3 + 0.7 * ahead);
  if (next_ == last) speed = std::min(speed, std::max(0.05, to_goal));
  return {speed, turn};
}

}  // namespace lampnav::sim
