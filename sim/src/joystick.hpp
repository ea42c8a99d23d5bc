#pragma once
// The person at the joystick of a scripted scenario: drives the TRUE robot from waypoint to
// waypoint the way a person steering by eye does: head for the next waypoint, turn on the spot
// when it is well off to the side, ease off near the goal. It is the simulator's own, deliberately
// unlike navigation's PathFollower (pure pursuit on the estimate): a fault in the follower under
// test must not move the ground truth it is measured against.

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "lampnav/core/pose2.hpp"

namespace lampnav::sim {

struct JoystickOptions {
  double max_speed = 0.5;       // m/s
  double max_turn_rate = 0.8;   // rad/s
  double reach = 0.3;           // m: a waypoint this close is passed, the next one is aimed at
  double turn_on_spot = 0.6;    // rad: a heading error past this stops the robot to turn
  double goal_tolerance = 0.1;  // m
};

class Joystick {
 public:
  Joystick(std::vector<Eigen::Vector2d> waypoints, const JoystickOptions& options);
  // Forward speed (m/s) and turn rate (rad/s) for the robot at `truth`.
  std::pair<double, double> steer(const Pose2& truth);
  bool arrived() const { return arrived_; }

 private:
  std::vector<Eigen::Vector2d> waypoints_;
  JoystickOptions o_;
  std::size_t next_ = 1;  // the waypoint aimed at
  bool arrived_ = false;
};

}  // namespace lampnav::sim
