#pragma once
// The augmented topological map (seed paper 2, section 2): places as nodes of a graph, each tagged
// with metric facts and its ORDERED sequence of ceiling lamps. Stored as a Boost.Graph
// adjacency_list with the Node and Edge structs below as bundled properties; ids and names are
// kept apart from vertex descriptors, which never leave the implementation.

#include <Eigen/Core>
#include <functional>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/ids.hpp"
#include "lampnav/core/pose2.hpp"
#include "lampnav/graph/geometry.hpp"

namespace lampnav::graph {

// `waypoint` is a node of a plain Nav2 route graph (map-format.md, last section): a point of the
// graph with no place, region or lamps; it is never written as a lampnav place.
enum class Place { corridor, junction, corner, end, door, hall, room, waypoint };
const char* to_string(Place p);
// The places a lampnav map may name (all but `waypoint`).
std::optional<Place> place_from_string(const std::string& s);

enum class LampShape { rectangle, disc };
const char* to_string(LampShape s);

// A lamp: the emitting face of a ceiling light, a horizontal shape facing down (conventions.md).
struct Lamp {
  LampId id;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // m, centre in `map`, z above the floor
  double yaw = 0.0;                               // rad, direction of the long axis
  bool yaw_given = false;                         // a disc may leave yaw out
  LampShape shape = LampShape::rectangle;
  double length = 0.0;  // m, along yaw (a disc: its diameter)
  double width = 0.0;   // m (a disc: its diameter)
  NodeId node;          // the node whose sequence holds it

  // Extent of the lamp along a direction (rad, map frame): what a camera moving that way must fit.
  double extent_along(double direction) const;
};

enum class Side { left, right };
const char* to_string(Side s);

// A door along a corridor: `side` when walking the axis from its first end, `at` metres along it.
struct Door {
  std::string name;
  Side side = Side::left;
  double at = 0.0;  // m
};

// A corridor's centreline, from its first end to its second.
struct Axis {
  Eigen::Vector2d first = Eigen::Vector2d::Zero();
  Eigen::Vector2d second = Eigen::Vector2d::Zero();
  double length() const { return (second - first).norm(); }
  Eigen::Vector2d direction() const { return (second - first).normalized(); }
  // Distance along the axis of the foot of p (may be outside [0, length]).
  double along(const Eigen::Vector2d& p) const { return (p - first).dot(direction()); }
  Eigen::Vector2d point_at(double s) const { return first + s * direction(); }
};

// Which way a node is walked: along its axis from the first end (forward) or from the second.
enum class Travel { forward, backward };

struct Node {
  NodeId id;
  std::string name;
  Place place = Place::corridor;
  Eigen::Vector2d point = Eigen::Vector2d::Zero();  // m, the node's Point geometry
  Polygon region;
  std::optional<Axis> axis;
  std::optional<double> width;            // m
  std::optional<double> length_override;  // m, metadata.length
  std::vector<Door> doors;
  std::vector<Lamp> lamps;  // in walking order from the axis' first end (halls: stable order)
  // Nav2's keys that lampnav keeps but does not read (`operations`; for a plain Nav2 graph also
  // `frame` and the whole `metadata`), as the text of a JSON object written back unchanged.
  std::string nav2_keys;

  // metadata.length if given, else the axis length, else 0.
  double length() const;
  const Door* find_door(const std::string& door_name) const;
};

struct Edge {
  EdgeId id;
  NodeId start, end;
  // The cost planning uses, as Nav2's route server scores it: `cost_given` when `overridable` is
  // false, else the straight line between the two node points (map-format.md). A map made in
  // code sets it; the writer writes it (with "overridable": false) where it is not the line.
  double cost = 0.0;
  std::optional<double> cost_given;                    // `cost` as written in the file
  std::optional<bool> overridable;                     // Nav2's flag as written in the file
  std::vector<std::vector<Eigen::Vector2d>> geometry;  // MultiLineString (or one LineString)
  bool line_string = false;                            // written as a LineString
  // A plain Nav2 graph's edge geometry that is no valid line (Nav2 ignores edge geometry), as
  // JSON text written back as it came; `geometry` is then the straight line between the nodes.
  std::string nav2_geometry;
  // Nav2's keys kept but not read (`metadata`, `operations`, ...), as JSON object text.
  std::string nav2_keys;
  double geometric_length() const;
};

class TopologicalMap {
 public:
  explicit TopologicalMap(std::string name = {});
  TopologicalMap(const TopologicalMap& other);
  TopologicalMap& operator=(const TopologicalMap& other);
  TopologicalMap(TopologicalMap&&) noexcept;
  TopologicalMap& operator=(TopologicalMap&&) noexcept;
  ~TopologicalMap();

  const std::string& name() const;
  void set_name(std::string name);
  // A plain Nav2 route graph (a file with no `lampnav` block) is written back as one: its nodes
  // are waypoints, and edge ids may repeat, as Nav2 allows.
  bool plain_nav2() const;
  void set_plain_nav2(bool plain);
  // The file's top-level keys lampnav keeps but does not read (`crs`, `date_generated`, ...), as
  // JSON object text written back unchanged.
  const std::string& nav2_keys() const;
  void set_nav2_keys(std::string json_object);

  // Adds a node; throws lampnav::Error on a duplicate id, name or lamp id. Each lamp's `node` is
  // set to this node.
  void add_node(Node node);
  // Adds a one-way edge; throws lampnav::Error when an end names no node or the id is taken (in
  // a plain Nav2 graph, by a node: edges may share ids there; find_edge gives the first).
  void add_edge(Edge edge);

  std::size_t node_count() const;
  std::size_t edge_count() const;
  std::size_t lamp_count() const;

  // Nodes and edges in the order they were added.
  const Node& node_at_index(std::size_t i) const;
  const Edge& edge_at_index(std::size_t i) const;
  template <class T, const T& (TopologicalMap::*Get)(std::size_t) const>
  class Range;
  Range<Node, &TopologicalMap::node_at_index> nodes() const;
  Range<Edge, &TopologicalMap::edge_at_index> edges() const;

  const Node& node(NodeId id) const;  // throws lampnav::Error if absent
  const Node* find_node(NodeId id) const;
  const Node* find_node(const std::string& name) const;
  const Edge* find_edge(EdgeId id) const;
  const Lamp* find_lamp(const LampId& id) const;
  // The one-way edges leaving / entering a node.
  std::vector<const Edge*> out_edges(NodeId id) const;
  std::vector<const Edge*> in_edges(NodeId id) const;
  // The edge from a to b with the lowest cost, if any.
  const Edge* edge_between(NodeId a, NodeId b) const;

  // The node whose region contains p (regions may touch: the first added wins on a shared edge).
  const Node* node_containing(const Eigen::Vector2d& p) const;
  // The node whose region contains p, else the one whose region is nearest within `margin` (m);
  // null when none is. A robot is often a few centimetres outside every region (a built map's
  // regions meet with slivers between them; a pose estimate is centimetres off).
  const Node* node_near(const Eigen::Vector2d& p, double margin) const;
  // Lamps of a node in the order met when walking it that way (paper 2's lamp tags).
  std::vector<const Lamp*> lamps_in_walking_order(NodeId id, Travel travel) const;
  // The walking direction along a node's axis for a heading (rad); forward for nodes without one.
  Travel travel_for_heading(NodeId id, double heading) const;
  // Lamps ahead of a pose, nearest first: in front of it, at most `max_distance` ahead and at most
  // `lateral` to either side of its heading line, whatever node holds them.
  std::vector<const Lamp*> lamps_ahead(const Pose2& pose, double max_distance,
                                       double lateral) const;
  // All lamps whose centre (x, y) lies within `radius` of p, nearest first.
  std::vector<const Lamp*> lamps_within(const Eigen::Vector2d& p, double radius) const;
  // The same lamps, unsorted, each given to `visit` (for hot paths that order them their own way).
  void visit_lamps_within(const Eigen::Vector2d& p, double radius,
                          const std::function<void(const Lamp&)>& visit) const;

  // Implementation access for the graph module's algorithms (planner, checks).
  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

template <class T, const T& (TopologicalMap::*Get)(std::size_t) const>
class TopologicalMap::Range {
 public:
  class iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = T;
    using difference_type = std::ptrdiff_t;
    using pointer = const T*;
    using reference = const T&;
    iterator(const TopologicalMap* m, std::size_t i) : m_(m), i_(i) {}
    reference operator*() const { return (m_->*Get)(i_); }
    pointer operator->() const { return &(m_->*Get)(i_); }
    iterator& operator++() {
      ++i_;
      return *this;
    }
    bool operator==(const iterator& o) const { return i_ == o.i_; }
    bool operator!=(const iterator& o) const { return i_ != o.i_; }

   private:
    const TopologicalMap* m_;
    std::size_t i_;
  };
  Range(const TopologicalMap* m, std::size_t n) : m_(m), n_(n) {}
  iterator begin() const { return {m_, 0}; }
  iterator end() const { return {m_, n_}; }
  std::size_t size() const { return n_; }

 private:
  const TopologicalMap* m_;
  std::size_t n_;
};

inline TopologicalMap::Range<Node, &TopologicalMap::node_at_index> TopologicalMap::nodes() const {
  return {this, node_count()};
}
inline TopologicalMap::Range<Edge, &TopologicalMap::edge_at_index> TopologicalMap::edges() const {
  return {this, edge_count()};
}

}  // namespace lampnav::graph
