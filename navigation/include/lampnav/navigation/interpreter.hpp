#pragma once
// Route commands walked on the graph from where the robot stands: the route they describe. "Follow
// corridor C1, turn right at the first corner, stop at the second door on the left" becomes the
// nodes C1, K1, C3, D6, each command ending at one of them. A command that cannot be carried out
// (no such corner ahead, a door that is not there) is reported with its number and why.

#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/graph/planner.hpp"
#include "lampnav/graph/route_commands.hpp"

namespace lampnav::navigation {

struct CommandPlan {
  graph::Route route;                     // from the node the robot stands in to the last place
  std::vector<std::size_t> completes_at;  // per command: the index in route.nodes where it ends
  std::vector<graph::RouteCommand> commands;
  // The floor points to drive, from the robot's position (corridor starts taken from its foot).
  std::vector<Eigen::Vector2d> waypoints;
};

struct Interpretation {
  std::optional<CommandPlan> plan;
  std::string why;  // when there is no plan
  int failed = -1;  // the command (0-based) that could not be carried out
};

// Walks `commands` from `start`: the node whose region holds it, heading its way. "Straight on"
// at a junction or corner is the exit within graph::kStraightTolerance of the way in; a turn is
// the exit on that side nearest a right angle.
Interpretation interpret_commands(const graph::TopologicalMap& map, const Pose2& start,
                                  const std::vector<graph::RouteCommand>& commands);

}  // namespace lampnav::navigation
