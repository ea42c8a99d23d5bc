#include "lampnav/navigation/path_follower.hpp"

#include <algorithm>
#include <cmath>

namespace lampnav::navigation {

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

}  // namespace lampnav::navigation
