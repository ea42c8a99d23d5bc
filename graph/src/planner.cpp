#include "lampnav/graph/planner.hpp"

#include <algorithm>
#include <boost/graph/dijkstra_shortest_paths.hpp>
#include <cstdio>

#include "lampnav/core/error.hpp"
#include "lampnav/graph/corridor_geometry.hpp"
#include "map_impl.hpp"

namespace lampnav::graph {

std::optional<Route> plan_route(const TopologicalMap& map, NodeId from, NodeId to) {
  const auto& impl = map.impl();
  const Graph& g = impl.g;
  const Vertex s = impl.vertex(from);
  const Vertex t = impl.vertex(to);
  const std::size_t n = boost::num_vertices(g);
  std::vector<Vertex> pred(n);
  std::vector<double> dist(n);
  std::vector<EdgeDesc> pred_edge(n);
  struct EdgeRecorder : boost::default_dijkstra_visitor {
    std::vector<EdgeDesc>* pe;
    void edge_relaxed(EdgeDesc e, const Graph& gr) { (*pe)[boost::target(e, gr)] = e; }
  } recorder;
  recorder.pe = &pred_edge;
  boost::dijkstra_shortest_paths(
      g, s,
      boost::predecessor_map(
          boost::make_iterator_property_map(pred.begin(), boost::get(boost::vertex_index, g)))
          .distance_map(
              boost::make_iterator_property_map(dist.begin(), boost::get(boost::vertex_index, g)))
          .weight_map(boost::get(&Edge::cost, g))
          .visitor(recorder));
  if (t != s && pred[t] == t) return std::nullopt;
  Route r;
  r.cost = dist[t];
  for (Vertex v = t; v != s; v = pred[v]) {
    r.nodes.push_back(g[v].id);
    r.edges.push_back(g[pred_edge[v]].id);
  }
  r.nodes.push_back(g[s].id);
  std::reverse(r.nodes.begin(), r.nodes.end());
  std::reverse(r.edges.begin(), r.edges.end());
  return r;
}

std::optional<Route> plan_route(const TopologicalMap& map, const Pose2& from, NodeId to) {
  const Node* start = map.node_containing(from.translation());
  if (!start) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "the pose (%.3f, %.3f) lies in no node's region", from.x(),
                  from.y());
    throw Error(buf);
  }
  return plan_route(map, start->id, to);
}

using Eigen::Vector2d;

std::vector<Vector2d> route_waypoints(const TopologicalMap& map, const Route& route) {
  std::vector<Vector2d> pts;
  auto add = [&](const Vector2d& p) {
    if (pts.empty() || (pts.back() - p).norm() > 1e-6) pts.push_back(p);
  };
  const std::size_t k = route.nodes.size();
  for (std::size_t i = 0; i < k; ++i) {
    const Node& n = map.node(route.nodes[i]);
    const Node* prev = i > 0 ? &map.node(route.nodes[i - 1]) : nullptr;
    const Node* next = i + 1 < k ? &map.node(route.nodes[i + 1]) : nullptr;
    if (n.place == Place::corridor && n.axis) {
      add(n.axis->point_at(entry_point(n, prev)));
      add(n.axis->point_at(entry_point(n, next)));
    } else {
      add(n.point);
    }
  }
  return pts;
}

}  // namespace lampnav::graph
