#pragma once
// Pure pursuit along a polyline of floor points.

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "lampnav/core/pose2.hpp"

namespace lampnav::navigation {

// Drives along waypoints: pure pursuit with a look-ahead, slowing into bends and at the goal. The
// executor drives it on the estimate; the simulator's person at the joystick on the true pose.
class PathFollower {
 public:
  struct Options {
    double max_speed = 0.5;       // m/s
    double max_turn_rate = 0.8;   // rad/s
    double lookahead = 0.6;       // m
    double goal_tolerance = 0.1;  // m
  };
  PathFollower(std::vector<Eigen::Vector2d> waypoints, Options options);
  PathFollower(std::vector<Eigen::Vector2d> waypoints)
      : PathFollower(std::move(waypoints), Options{}) {}
  // Body speed (forward m/s, turn rad/s) for the current true pose.
  std::pair<double, double> command(const Pose2& pose);
  bool arrived() const { return arrived_; }
  const std::vector<Eigen::Vector2d>& waypoints() const { return pts_; }

 private:
  std::vector<Eigen::Vector2d> pts_;
  Options o_;
  std::size_t seg_ = 0;  // current segment pts_[seg_] -> pts_[seg_ + 1]
  bool arrived_ = false;
};

}  // namespace lampnav::navigation
