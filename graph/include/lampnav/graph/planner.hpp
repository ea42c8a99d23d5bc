#pragma once
// Route planning: the cheapest path over the one-way edges' costs (Dijkstra).

#include <optional>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::graph {

struct Route {
  std::vector<NodeId> nodes;  // from start to goal, both included
  std::vector<EdgeId> edges;  // nodes.size() - 1 edges
  double cost = 0.0;
};

// The cheapest route, or nullopt when the goal cannot be reached. Throws lampnav::Error when an
// id names no node.
std::optional<Route> plan_route(const TopologicalMap& map, NodeId from, NodeId to);
// From a pose: starts in the node whose region contains it. Throws lampnav::Error when the pose
// lies in no region.
std::optional<Route> plan_route(const TopologicalMap& map, const Pose2& from, NodeId to);

// The floor points a robot passes through to drive a route: along each corridor's axis from where
// it comes in to where it leaves (an axis end, or a door's place along it), through the points of
// the other places. Consecutive duplicates are dropped.
std::vector<Eigen::Vector2d> route_waypoints(const TopologicalMap& map, const Route& route);

}  // namespace lampnav::graph
