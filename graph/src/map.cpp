#include <algorithm>
#include <cmath>

#include "lampnav/core/error.hpp"
#include "map_impl.hpp"

namespace lampnav::graph {

const char* to_string(Place p) {
  switch (p) {
    case Place::corridor:
      return "corridor";
    case Place::junction:
      return "junction";
    case Place::corner:
      return "corner";
    case Place::end:
      return "end";
    case Place::door:
      return "door";
    case Place::hall:
      return "hall";
    case Place::room:
      return "room";
    case Place::waypoint:
      return "waypoint";
  }
  return "?";
}

std::optional<Place> place_from_string(const std::string& s) {
  for (Place p : {Place::corridor, Place::junction, Place::corner, Place::end, Place::door,
                  Place::hall, Place::room}) {
    if (s == to_string(p)) return p;
  }
  return std::nullopt;
}

const char* to_string(LampShape s) { return s == LampShape::rectangle ? "rectangle" : "disc"; }
const char* to_string(Side s) { return s == Side::left ? "left" : "right"; }

double Lamp::extent_along(double direction) const {
  if (shape == LampShape::disc) return length;
  const double rel = direction - yaw;
  return std::fabs(length * std::cos(rel)) + std::fabs(width * std::sin(rel));
}

double Node::length() const {
  if (length_override) return *length_override;
  return axis ? axis->length() : 0.0;
}

const Door* Node::find_door(const std::string& door_name) const {
  for (const auto& d : doors) {
    if (d.name == door_name) return &d;
  }
  return nullptr;
}

double Edge::geometric_length() const {
  double len = 0;
  for (const auto& line : geometry) {
    for (std::size_t i = 1; i < line.size(); ++i) len += (line[i] - line[i - 1]).norm();
  }
  return len;
}

Vertex TopologicalMap::Impl::vertex(NodeId id) const {
  auto it = vertex_by_id.find(id.value);
  if (it == vertex_by_id.end()) throw Error("no node with id " + std::to_string(id.value));
  return it->second;
}

TopologicalMap::TopologicalMap(std::string name) : impl_(std::make_unique<Impl>()) {
  impl_->name = std::move(name);
}
TopologicalMap::TopologicalMap(const TopologicalMap& other)
    : impl_(std::make_unique<Impl>(*other.impl_)) {}
TopologicalMap& TopologicalMap::operator=(const TopologicalMap& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
TopologicalMap::TopologicalMap(TopologicalMap&&) noexcept = default;
TopologicalMap& TopologicalMap::operator=(TopologicalMap&&) noexcept = default;
TopologicalMap::~TopologicalMap() = default;

const std::string& TopologicalMap::name() const { return impl_->name; }
void TopologicalMap::set_name(std::string name) { impl_->name = std::move(name); }
bool TopologicalMap::plain_nav2() const { return impl_->plain_nav2; }
void TopologicalMap::set_plain_nav2(bool plain) { impl_->plain_nav2 = plain; }
const std::string& TopologicalMap::nav2_keys() const { return impl_->nav2_keys; }
void TopologicalMap::set_nav2_keys(std::string json_object) {
  impl_->nav2_keys = std::move(json_object);
}

void TopologicalMap::add_node(Node node) {
  Impl& m = *impl_;
  if (m.vertex_by_id.count(node.id.value) || m.edge_by_id.count(node.id.value)) {
    throw Error("duplicate feature id " + std::to_string(node.id.value));
  }
  if (m.vertex_by_name.count(node.name)) throw Error("duplicate node name '" + node.name + "'");
  for (std::size_t i = 0; i < node.lamps.size(); ++i) {
    const auto& id = node.lamps[i].id.value;
    if (m.lamp_by_id.count(id)) throw Error("duplicate lamp id '" + id + "'");
    for (std::size_t j = 0; j < i; ++j) {
      if (node.lamps[j].id.value == id) throw Error("duplicate lamp id '" + id + "'");
    }
  }
  for (auto& l : node.lamps) l.node = node.id;
  const Vertex v = boost::add_vertex(std::move(node), m.g);
  const Node& n = m.g[v];
  m.vertex_by_id.emplace(n.id.value, v);
  m.vertex_by_name.emplace(n.name, v);
  if (n.region.size() >= 3) m.region_index.insert(n.region.bounds(), v);
  for (std::size_t i = 0; i < n.lamps.size(); ++i) {
    m.lamp_by_id.emplace(n.lamps[i].id.value, LampRef{v, i});
    const Eigen::Vector2d p = n.lamps[i].xyz.head<2>();
    m.lamp_index.insert(Box2{p, p}, m.lamps.size());
    m.lamps.push_back(LampRef{v, i});
  }
}

void TopologicalMap::add_edge(Edge edge) {
  Impl& m = *impl_;
  if (m.vertex_by_id.count(edge.id.value) || (m.edge_by_id.count(edge.id.value) && !m.plain_nav2)) {
    throw Error("duplicate feature id " + std::to_string(edge.id.value));
  }
  const Vertex a = m.vertex(edge.start);
  const Vertex b = m.vertex(edge.end);
  const std::int64_t id = edge.id.value;
  const auto [e, added] = boost::add_edge(a, b, std::move(edge), m.g);
  (void)added;  // parallel edges are allowed (vecS out-edge lists)
  m.edge_by_id.emplace(id, m.edge_order.size());  // a repeated id keeps the first
  m.edge_order.push_back(e);
}

std::size_t TopologicalMap::node_count() const { return boost::num_vertices(impl_->g); }
std::size_t TopologicalMap::edge_count() const { return impl_->edge_order.size(); }
std::size_t TopologicalMap::lamp_count() const { return impl_->lamps.size(); }

const Node& TopologicalMap::node_at_index(std::size_t i) const { return impl_->g[i]; }
const Edge& TopologicalMap::edge_at_index(std::size_t i) const {
  return impl_->g[impl_->edge_order[i]];
}

const Node& TopologicalMap::node(NodeId id) const { return impl_->g[impl_->vertex(id)]; }

const Node* TopologicalMap::find_node(NodeId id) const {
  auto it = impl_->vertex_by_id.find(id.value);
  return it == impl_->vertex_by_id.end() ? nullptr : &impl_->g[it->second];
}

const Node* TopologicalMap::find_node(const std::string& name) const {
  auto it = impl_->vertex_by_name.find(name);
  return it == impl_->vertex_by_name.end() ? nullptr : &impl_->g[it->second];
}

const Edge* TopologicalMap::find_edge(EdgeId id) const {
  auto it = impl_->edge_by_id.find(id.value);
  return it == impl_->edge_by_id.end() ? nullptr : &impl_->g[impl_->edge_order[it->second]];
}

const Lamp* TopologicalMap::find_lamp(const LampId& id) const {
  auto it = impl_->lamp_by_id.find(id.value);
  return it == impl_->lamp_by_id.end() ? nullptr : &impl_->lamp(it->second);
}

std::vector<const Edge*> TopologicalMap::out_edges(NodeId id) const {
  std::vector<const Edge*> out;
  for (auto [it, end] = boost::out_edges(impl_->vertex(id), impl_->g); it != end; ++it) {
    out.push_back(&impl_->g[*it]);
  }
  return out;
}

std::vector<const Edge*> TopologicalMap::in_edges(NodeId id) const {
  std::vector<const Edge*> in;
  for (auto [it, end] = boost::in_edges(impl_->vertex(id), impl_->g); it != end; ++it) {
    in.push_back(&impl_->g[*it]);
  }
  return in;
}

const Edge* TopologicalMap::edge_between(NodeId a, NodeId b) const {
  const Edge* best = nullptr;
  for (const Edge* e : out_edges(a)) {
    if (e->end == b && (!best || e->cost < best->cost)) best = e;
  }
  return best;
}

const Node* TopologicalMap::node_containing(const Eigen::Vector2d& p) const {
  const Node* found = nullptr;
  std::size_t best = SIZE_MAX;
  impl_->region_index.query(Box2{p, p}, [&](std::size_t v) {
    if (v < best && impl_->g[v].region.contains(p)) {
      best = v;
      found = &impl_->g[v];
    }
  });
  return found;
}

const Node* TopologicalMap::node_near(const Eigen::Vector2d& p, double margin) const {
  if (const Node* n = node_containing(p)) return n;
  if (!(margin > 0)) return nullptr;
  const Node* found = nullptr;
  double best = margin;
  const Eigen::Vector2d m(margin, margin);
  impl_->region_index.query(Box2{p - m, p + m}, [&](std::size_t v) {
    const Node& n = impl_->g[v];
    if (n.region.size() < 3) return;
    const double d = n.region.distance_to_boundary(p);
    if (d <= best) {
      best = d;
      found = &n;
    }
  });
  return found;
}

std::vector<const Lamp*> TopologicalMap::lamps_in_walking_order(NodeId id, Travel travel) const {
  const Node& n = node(id);
  std::vector<const Lamp*> out;
  out.reserve(n.lamps.size());
  for (const auto& l : n.lamps) out.push_back(&l);
  if (travel == Travel::backward) std::reverse(out.begin(), out.end());
  return out;
}

Travel TopologicalMap::travel_for_heading(NodeId id, double heading) const {
  const Node& n = node(id);
  if (!n.axis) return Travel::forward;
  const Eigen::Vector2d h(std::cos(heading), std::sin(heading));
  return h.dot(n.axis->direction()) >= 0 ? Travel::forward : Travel::backward;
}

std::vector<const Lamp*> TopologicalMap::lamps_within(const Eigen::Vector2d& p,
                                                      double radius) const {
  std::vector<std::pair<double, const Lamp*>> hits;
  visit_lamps_within(p, radius,
                     [&](const Lamp& l) { hits.emplace_back((l.xyz.head<2>() - p).norm(), &l); });
  std::sort(hits.begin(), hits.end(), [](const auto& a, const auto& b) {
    return a.first < b.first || (a.first == b.first && a.second->id < b.second->id);
  });
  std::vector<const Lamp*> out;
  out.reserve(hits.size());
  for (const auto& h : hits) out.push_back(h.second);
  return out;
}

void TopologicalMap::visit_lamps_within(const Eigen::Vector2d& p, double radius,
                                        const std::function<void(const Lamp&)>& visit) const {
  const Eigen::Vector2d r(radius, radius);
  impl_->lamp_index.query(Box2{p - r, p + r}, [&](std::size_t i) {
    const Lamp& l = impl_->lamp(impl_->lamps[i]);
    if ((l.xyz.head<2>() - p).squaredNorm() <= radius * radius) visit(l);
  });
}

std::vector<const Lamp*> TopologicalMap::lamps_ahead(const Pose2& pose, double max_distance,
                                                     double lateral) const {
  std::vector<std::pair<double, const Lamp*>> ahead;
  const double reach = std::hypot(max_distance, lateral);
  for (const Lamp* l : lamps_within(pose.translation(), reach)) {
    const Eigen::Vector2d q = pose.transform_to(l->xyz.head<2>());
    if (q.x() > 0 && q.x() <= max_distance && std::fabs(q.y()) <= lateral) {
      ahead.emplace_back(q.x(), l);
    }
  }
  std::stable_sort(ahead.begin(), ahead.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<const Lamp*> out;
  for (const auto& a : ahead) out.push_back(a.second);
  return out;
}

}  // namespace lampnav::graph
