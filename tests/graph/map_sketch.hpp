#pragma once
// Small hand-made maps for tests: corridors along axes, square places, two-way connections.

#include <string>
#include <vector>

#include "lampnav/graph/map.hpp"

namespace lampnav::test {

class MapSketch {
 public:
  // A corridor 2 m wide along a->b, with doors (name, side, at) and lamps every `lamp_every` m.
  MapSketch& corridor(const std::string& name, Eigen::Vector2d a, Eigen::Vector2d b,
                      std::vector<graph::Door> doors = {}, double lamp_every = 2.4) {
    graph::Node n = base(name, graph::Place::corridor, 0.5 * (a + b));
    n.axis = graph::Axis{a, b};
    n.width = 2.0;
    const Eigen::Vector2d d = (b - a).normalized(), l(-d.y(), d.x());
    const Eigen::Vector2d lo = (a - l).cwiseMin(a + l).cwiseMin(b - l).cwiseMin(b + l);
    const Eigen::Vector2d hi = (a - l).cwiseMax(a + l).cwiseMax(b - l).cwiseMax(b + l);
    n.region = graph::Polygon({lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}});
    n.doors = std::move(doors);
    const double len = (b - a).norm();
    int k = 0;
    for (double s = lamp_every / 2; lamp_every > 0 && s < len; s += lamp_every) {
      graph::Lamp lamp;
      lamp.id = LampId(name + "-L" + std::to_string(++k));
      const Eigen::Vector2d p = a + s * d;
      lamp.xyz = {p.x(), p.y(), 2.7};
      lamp.yaw = std::atan2(d.y(), d.x());
      lamp.yaw_given = true;
      lamp.length = 1.2;
      lamp.width = 0.3;
      n.lamps.push_back(lamp);
    }
    map_.add_node(std::move(n));
    return *this;
  }
  // A place: a square of side `size` centred at c.
  MapSketch& place(const std::string& name, graph::Place kind, Eigen::Vector2d c,
                   double size = 2.0) {
    graph::Node n = base(name, kind, c);
    const double h = size / 2;
    n.region = graph::Polygon({{c.x() - h, c.y() - h},
                               {c.x() + h, c.y() - h},
                               {c.x() + h, c.y() + h},
                               {c.x() - h, c.y() + h}});
    map_.add_node(std::move(n));
    return *this;
  }
  // Two one-way edges between a and b (or one, a->b, when one_way).
  MapSketch& connect(const std::string& a, const std::string& b, bool one_way = false,
                     double cost = -1) {
    add_edge(a, b, cost);
    if (!one_way) add_edge(b, a, cost);
    return *this;
  }
  const graph::TopologicalMap& map() const { return map_; }
  NodeId id(const std::string& name) const { return map_.find_node(name)->id; }

 private:
  graph::Node base(const std::string& name, graph::Place kind, Eigen::Vector2d p) {
    graph::Node n;
    n.id = NodeId(next_id_++);
    n.name = name;
    n.place = kind;
    n.point = p;
    return n;
  }
  void add_edge(const std::string& a, const std::string& b, double cost) {
    graph::Edge e;
    e.id = EdgeId(next_id_++);
    e.start = id(a);
    e.end = id(b);
    e.geometry = {{map_.find_node(a)->point, map_.find_node(b)->point}};
    if (cost >= 0) e.cost_given = cost;
    e.cost = cost >= 0 ? cost : e.geometric_length();
    map_.add_edge(std::move(e));
  }
  graph::TopologicalMap map_{"sketch"};
  std::int64_t next_id_ = 1;
};

}  // namespace lampnav::test
