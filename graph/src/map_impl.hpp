#pragma once
// The map's storage: a Boost.Graph adjacency_list whose bundled properties are the public Node
// and Edge structs, plus id, name and spatial indexes. Private to the graph module.

#include <algorithm>
#include <boost/graph/adjacency_list.hpp>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "lampnav/graph/grid_index.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::graph {

using Graph = boost::adjacency_list<boost::vecS, boost::vecS, boost::bidirectionalS, Node, Edge>;
using Vertex = Graph::vertex_descriptor;
using EdgeDesc = Graph::edge_descriptor;

struct LampRef {
  Vertex vertex;
  std::size_t index;  // in the node's lamp sequence
};

struct TopologicalMap::Impl {
  std::string name;
  bool plain_nav2 = false;
  std::string nav2_keys;
  Graph g;
  std::vector<EdgeDesc> edge_order;  // insertion order
  std::unordered_map<std::int64_t, Vertex> vertex_by_id;
  std::unordered_map<std::int64_t, std::size_t> edge_by_id;  // index into edge_order
  std::unordered_map<std::string, Vertex> vertex_by_name;
  std::unordered_map<std::string, LampRef> lamp_by_id;
  std::vector<LampRef> lamps;  // all lamps, in insertion order
  GridIndex region_index;      // vertex indexes by region bounds
  GridIndex lamp_index{2.0};   // indexes into `lamps` by position

  Vertex vertex(NodeId id) const;
  const Lamp& lamp(const LampRef& r) const { return g[r.vertex].lamps[r.index]; }
};

}  // namespace lampnav::graph
