#pragma once
// Test maps edited from the bundled ones: lamps made round, moved, added or taken out.

#include <cmath>
#include <functional>

#include "lampnav/graph/map.hpp"

namespace lampnav::test {

// A copy of `map` with each node passed through `edit`, the edges as they were.
inline graph::TopologicalMap edited(const graph::TopologicalMap& map,
                                    const std::function<void(graph::Node&)>& edit) {
  graph::TopologicalMap out(map.name());
  for (const graph::Node& n : map.nodes()) {
    graph::Node c = n;
    edit(c);
    out.add_node(c);
  }
  for (const auto& e : map.edges()) out.add_edge(e);
  return out;
}

// The node's rectangular lamps made 0.5 m discs, as round downlights hang.
inline void make_round(graph::Node& n) {
  for (auto& l : n.lamps) {
    if (l.shape != graph::LampShape::rectangle) continue;
    l.shape = graph::LampShape::disc;
    l.length = l.width = 0.5;
    l.yaw = 0;
    l.yaw_given = false;
  }
}

// Every other corridor lamp taken down (the first kept), the rest made round: the office's
// corridors then have 0.5 m discs 4.5 m apart.
inline void sparse_round(graph::Node& n) {
  if (n.place == graph::Place::corridor) {
    std::vector<graph::Lamp> kept;
    for (std::size_t i = 0; i < n.lamps.size(); i += 2) kept.push_back(n.lamps[i]);
    n.lamps = kept;
  }
  make_round(n);
}

// The node's lamps hung in two rows, each lamp replaced by two `offset` m either side of it across
// its corridor (across the lamp's axis at a junction, corner or end): a wide corridor's two rows
// of troffers. Rooms, doors and halls as they were.
inline void two_rows(graph::Node& n, double offset) {
  if (n.place == graph::Place::room || n.place == graph::Place::door ||
      n.place == graph::Place::hall)
    return;
  std::vector<graph::Lamp> rows;
  for (const graph::Lamp& l : n.lamps) {
    const Eigen::Vector2d along =
        n.axis ? n.axis->direction() : Eigen::Vector2d(std::cos(l.yaw), std::sin(l.yaw));
    const Eigen::Vector2d across(-along.y(), along.x());
    for (const auto& [side, tag] : {std::pair{1.0, "a"}, std::pair{-1.0, "b"}}) {
      graph::Lamp c = l;
      c.id = LampId{l.id.value + tag};
      c.xyz.head<2>() += side * offset * across;
      rows.push_back(c);
    }
  }
  n.lamps = rows;
}

// A corridor's lamps hung `offset` m to the left of its axis (walking it from its first end), as
// where a row of lamps runs along one side of a corridor and the robot drives down its middle.
inline void to_one_side(graph::Node& n, double offset) {
  if (n.place != graph::Place::corridor || !n.axis) return;
  const Eigen::Vector2d along = n.axis->direction();
  for (graph::Lamp& l : n.lamps) l.xyz.head<2>() += offset * Eigen::Vector2d(-along.y(), along.x());
}

// A second row beside each corridor's lamps, `apart` m to the left of its axis (walking it from its
// first end), the first row under the axis (ids -L1b, ...): a wide corridor driven under one of
// its two rows. Places' lamps as they were.
inline void row_beside(graph::Node& n, double apart) {
  if (n.place != graph::Place::corridor || !n.axis) return;
  const Eigen::Vector2d along = n.axis->direction();
  const std::size_t count = n.lamps.size();
  for (std::size_t i = 0; i < count; ++i) {
    graph::Lamp c = n.lamps[i];
    c.id = LampId{c.id.value + "b"};
    c.xyz.head<2>() += apart * Eigen::Vector2d(-along.y(), along.x());
    n.lamps.push_back(c);
  }
}

}  // namespace lampnav::test
