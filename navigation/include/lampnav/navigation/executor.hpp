#pragma once
// Route commands carried out on the localizer's estimate: the commands are walked on the graph
// into a route (interpreter.hpp), the route is driven by pure pursuit on the estimate, and
// progress is counted by the places the localizer reports entering. When the robot is lost it
// stops and waits; once relocalized it plans again from where it now is to the same goal. A
// command that cannot be carried out, or a robot lost too long, ends the mission with the reason.
// While the localizer is ambiguous (one of several look-alike places) standing still decides
// nothing: the executor drives along the corridor the robot stands in, as far as it runs in
// every one of the places (reachable in all of them), to where their views will differ; between
// symmetry twins (no motion can decide) it stops and says so.

#include <string>
#include <vector>

#include "lampnav/fusion/localizer.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav/navigation/interpreter.hpp"
#include "lampnav/navigation/path_follower.hpp"

namespace lampnav::navigation {

struct ExecutorOptions {
  double max_speed = 0.5;        // m/s
  double max_turn_rate = 0.8;    // rad/s
  double lookahead = 0.6;        // m, pure pursuit
  double goal_tolerance = 0.15;  // m
  double max_lost_s = 60.0;      // lost longer than this ends the mission
  double off_route_m = 2.0;      // further from the path than this: plan again
  double explore_m = 40.0;       // while ambiguous, drive at most this far to decide
  double explore_speed = 0.3;    // m/s
  void validate() const;         // throws InputError naming the field
};

enum class ExecutorStatus { idle, driving, waiting, arrived, failed };
const char* to_string(ExecutorStatus status);

struct WheelSpeeds {
  double left = 0, right = 0;  // m/s
};

struct ExecutorEvent {
  Stamp stamp;
  std::string text;
};

class Executor {
 public:
  Executor(const graph::TopologicalMap& map, double semi_axis, const ExecutorOptions& options = {});

  // Plans the commands from `pose`. False (status failed, reason() says why) when they cannot be
  // carried out from there.
  bool start(Stamp stamp, const Pose2& pose, const std::vector<graph::RouteCommand>& commands);
  // The wheel speeds for the latest estimate.
  WheelSpeeds step(const fusion::LocalizerEstimate& estimate);

  ExecutorStatus status() const { return status_; }
  const std::string& reason() const { return reason_; }
  // The command in progress (index into plan().commands).
  std::size_t command() const;
  const CommandPlan& plan() const { return plan_; }
  const std::string& goal() const { return goal_; }
  const std::vector<ExecutorEvent>& events() const { return events_; }
  int replans() const { return replans_; }

 private:
  bool adopt(Stamp stamp, const Pose2& pose, const std::vector<graph::RouteCommand>& commands);
  bool replan(Stamp stamp, const Pose2& pose, const std::string& why);
  void fail(Stamp stamp, const std::string& why);
  void note(Stamp stamp, const std::string& text) { events_.push_back({stamp, text}); }
  // Wheel speeds that take the robot along its corridor to where the look-alike places differ,
  // or nothing when no such motion is known.
  std::optional<WheelSpeeds> explore(const fusion::LocalizerEstimate& e);

  const graph::TopologicalMap* map_;
  double semi_axis_;
  ExecutorOptions o_;
  ExecutorStatus status_ = ExecutorStatus::idle;
  std::string reason_, goal_;
  CommandPlan plan_;
  std::optional<PathFollower> follower_;
  std::size_t reached_ = 0;  // index in plan_.route.nodes of the last place entered
  const graph::Node* last_node_ = nullptr;
  std::optional<Stamp> lost_since_;
  double explored_m_ = 0;               // driven while ambiguous since the loss
  std::optional<Stamp> explore_stamp_;  // the last exploring step
  double explore_v_ = 0;
  bool explore_noted_ = false;
  std::vector<ExecutorEvent> events_;
  int replans_ = 0;
};

}  // namespace lampnav::navigation
