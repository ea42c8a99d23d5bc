#include "lampnav/graph/planner.hpp"

#include <algorithm>
#include <boost/graph/dijkstra_shortest_paths.hpp>
#include <cstdio>

#include "lampnav/core/error.hpp"
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

}  // namespace lampnav::graph
