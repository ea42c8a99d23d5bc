#pragma once
// The simulated robot behind Robot: the stack sets its wheel speeds, it answers with
// encoder readings at the odometry rate and camera frames when they arrive (after their delay),
// and everything, truth included, goes to a mission log. Kidnaps happen as the scenario says.

#include <deque>
#include <memory>
#include <string>

#include "lampnav/core/robot.hpp"
#include "lampnav/sim/scenario.hpp"

namespace lampnav::sim {

class World;

class SimulatedRobot : public Robot {
 public:
  // Writes the mission log to `log_path`. Throws InputError for a bad scenario.
  SimulatedRobot(const Scenario& scenario, const std::string& log_path);
  ~SimulatedRobot() override;

  void set_wheel_speeds(double left, double right) override;
  // Ends (nullopt) at the scenario's max_duration_s or after finish().
  std::optional<RobotInput> next() override;

  // The true pose now (for scoring and demos, never for the stack).
  Pose2 truth() const;
  double now_s() const;
  // Delivers the frames still in flight and closes the log.
  RecordStats finish();

 private:
  Scenario scenario_;
  std::unique_ptr<World> world_;
  std::deque<RobotInput> queue_;
  double left_ = 0, right_ = 0;
  std::size_t next_kidnap_ = 0;
  bool finished_ = false;
};

}  // namespace lampnav::sim
