#pragma once
// Where a route enters and leaves a corridor, shared by route commands, route waypoints and the
// navigation's command interpreter.

#include <algorithm>

#include "lampnav/graph/map.hpp"

namespace lampnav::graph {

// The distance along a corridor's axis at which the neighbouring node `other` meets it: a door
// listed in the corridor at its `at`, a door node elsewhere at the foot of its point, anything
// else at the nearer axis end.
inline double meeting_point(const Node& corridor, const Node& other) {
  const Axis& ax = *corridor.axis;
  if (other.place == Place::door) {
    if (const Door* d = corridor.find_door(other.name)) return d->at;
    const double s = ax.along(other.point);
    if (s > 0 && s < ax.length()) return s;
  }
  return (other.point - ax.first).norm() <= (other.point - ax.second).norm() ? 0.0 : ax.length();
}

// Where a route that comes from (or goes to) `neighbour` meets the corridor's axis; with no
// neighbour (the route starts or ends here), at the foot of the corridor's own point.
inline double entry_point(const Node& corridor, const Node* neighbour) {
  if (neighbour) return meeting_point(corridor, *neighbour);
  return std::clamp(corridor.axis->along(corridor.point), 0.0, corridor.axis->length());
}

// Where the robot comes from / goes to when it uses node n next to point p: the end of n's axis
// away from p, or n's own point.
inline Eigen::Vector2d far_anchor(const Node& n, const Eigen::Vector2d& p) {
  if (!n.axis) return n.point;
  return (n.axis->first - p).norm() > (n.axis->second - p).norm() ? n.axis->first : n.axis->second;
}

}  // namespace lampnav::graph
