#pragma once
// Stand-in for nav2_route's graph types, reduced to what the GeoJSON loader fills and what the
// test's route search reads. Field names and meanings follow Nav2's: a node holds its directed
// edges; an edge's cost is used as it is only when it is not `overridable`; metadata values are
// std::any (numbers, booleans, strings, vectors of those, nested Metadata).

#include <any>
#include <filesystem>
#include <string>
#include <unordered_map>
#include <vector>

namespace nav2_route {

struct Metadata {
  template <class T>
  void setValue(const std::string& key, const T& value) {
    data[key] = value;
  }
  std::unordered_map<std::string, std::any> data;
};

enum class OperationTrigger { NODE = 0, ON_ENTER = 1, ON_EXIT = 2 };

struct Operation {
  std::string type;
  OperationTrigger trigger = OperationTrigger::NODE;
  Metadata metadata;
};
using Operations = std::vector<Operation>;

struct EdgeCost {
  float cost = 0.0f;
  bool overridable = true;  // when true, Nav2's edge scorers (by default the distance) decide
};

struct Coordinates {
  std::string frame_id = "map";
  float x = 0.0f, y = 0.0f;
};

struct Node;

struct DirectionalEdge {
  unsigned int edgeid = 0;
  Node* start = nullptr;
  Node* end = nullptr;
  EdgeCost edge_cost;
  Metadata metadata;
  Operations operations;
};

struct Node {
  unsigned int nodeid = 0;
  Coordinates coords;
  std::vector<DirectionalEdge> neighbors;
  Metadata metadata;
  Operations operations;

  void addEdge(EdgeCost& cost, Node* node, unsigned int edgeid, Metadata meta_data = {},
               Operations operations_data = {}) {
    neighbors.push_back(
        {edgeid, this, node, cost, std::move(meta_data), std::move(operations_data)});
  }
};

using Graph = std::vector<Node>;
using GraphToIDMap = std::unordered_map<unsigned int, unsigned int>;

}  // namespace nav2_route
