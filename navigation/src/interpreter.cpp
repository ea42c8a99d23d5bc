#include "lampnav/navigation/interpreter.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "lampnav/graph/corridor_geometry.hpp"
#include "lampnav/graph/geometry.hpp"

namespace lampnav::navigation {

using Eigen::Vector2d;
using graph::CommandKind;
using graph::Node;
using graph::Place;

namespace {

constexpr double kRightAngle = M_PI / 2;

// A command that cannot be carried out from where the walk stands.
struct Refusal {
  std::string why;
};

// The walk along the graph: the nodes so far, the way the robot faces, and (in a corridor) where
// along its axis it came in.
class Walker {
 public:
  Walker(const graph::TopologicalMap& map, const Node& start, const Pose2& pose)
      : map_(&map), heading_(std::cos(pose.yaw()), std::sin(pose.yaw())) {
    nodes_.push_back(start.id);
    if (start.axis) {
      s_in_ = std::clamp(start.axis->along(pose.translation()), 0.0, start.axis->length());
      heading_ = start.axis->direction() * (heading_.dot(start.axis->direction()) >= 0 ? 1 : -1);
    }
  }

  const Node& cur() const { return map_->node(nodes_.back()); }
  bool undecided() const { return undecided_; }
  void decide(bool reverse) {
    undecided_ = false;
    if (reverse) heading_ = -heading_;
  }
  const Node* prev() const {
    return nodes_.size() > 1 ? &map_->node(nodes_[nodes_.size() - 2]) : nullptr;
  }
  std::size_t index() const { return nodes_.size() - 1; }
  const std::vector<NodeId>& nodes() const { return nodes_; }

  void move(const Node& n) {
    const Node& from = cur();
    const Vector2d exit =
        from.axis ? from.axis->point_at(graph::meeting_point(from, n)) : from.point;
    nodes_.push_back(n.id);
    undecided_ = false;
    if (n.axis) {
      s_in_ = graph::meeting_point(n, from);
      heading_ = n.axis->direction() * (s_in_ < 0.5 * n.axis->length() ? 1 : -1);
      // Into a corridor from the side (a door): either way along it; the commands decide.
      undecided_ = s_in_ > 1.0 && s_in_ < n.axis->length() - 1.0;
    } else if ((n.point - exit).norm() > 1e-6) {
      heading_ = (n.point - exit).normalized();
    }
  }

  // The neighbours the walk can go on to (not back where it came from).
  std::vector<const Node*> exits() const {
    std::vector<const Node*> out;
    for (const graph::Edge* e : map_->out_edges(cur().id)) {
      const Node& n = map_->node(e->end);
      if (prev() && n.id == prev()->id) continue;
      out.push_back(&n);
    }
    return out;
  }

  // Straight on: in a corridor, what meets its far end; elsewhere, the exit nearest the way in,
  // within the straight tolerance.
  const Node* ahead() const {
    const Node& c = cur();
    const Node* best = nullptr;
    double best_score = 1e18;
    for (const Node* n : exits()) {
      double score;
      if (c.axis) {
        const bool forward = heading_.dot(c.axis->direction()) > 0;
        const double end = forward ? c.axis->length() : 0.0;
        if (n->place == Place::door && c.find_door(n->name)) continue;  // doors are to the side
        score = std::fabs(graph::meeting_point(c, *n) - end);
        if (score > 1.0) continue;
      } else {
        score = std::fabs(graph::signed_angle(heading_, out_direction(*n)));
        if (score > graph::kStraightTolerance) continue;
      }
      if (score < best_score) {
        best_score = score;
        best = n;
      }
    }
    return best;
  }

  // The exit on that side nearest a right angle.
  const Node* turn(graph::TurnDirection d) const {
    const Node* best = nullptr;
    double best_score = 1e18;
    for (const Node* n : exits()) {
      const double a = graph::signed_angle(heading_, out_direction(*n));
      const bool on_side = d == graph::TurnDirection::left ? a > graph::kStraightTolerance
                                                           : a < -graph::kStraightTolerance;
      if (!on_side) continue;
      const double score = std::fabs(std::fabs(a) - kRightAngle);
      if (score < best_score) {
        best_score = score;
        best = n;
      }
    }
    return best;
  }

  // The doors of the current corridor ahead of where the walk came in, nearest first, with the
  // side they are on for the way the robot goes.
  std::vector<std::pair<const graph::Door*, graph::Side>> doors_ahead() const {
    const Node& c = cur();
    std::vector<std::pair<double, std::pair<const graph::Door*, graph::Side>>> found;
    if (!c.axis) return {};
    const bool forward = heading_.dot(c.axis->direction()) > 0;
    for (const graph::Door& d : c.doors) {
      const double ahead_by = forward ? d.at - s_in_ : s_in_ - d.at;
      if (ahead_by <= 0) continue;
      const graph::Side side =
          forward ? d.side : (d.side == graph::Side::left ? graph::Side::right : graph::Side::left);
      found.push_back({ahead_by, {&d, side}});
    }
    std::sort(found.begin(), found.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::pair<const graph::Door*, graph::Side>> out;
    for (const auto& f : found) out.push_back(f.second);
    return out;
  }

  // Along the cheapest route to `goal`.
  void go_to(const Node& goal) {
    if (goal.id == cur().id) return;
    const auto r = graph::plan_route(*map_, cur().id, goal.id);
    if (!r) throw Refusal{"no way from " + cur().name + " to " + goal.name};
    for (std::size_t k = 1; k < r->nodes.size(); ++k) move(map_->node(r->nodes[k]));
  }

 private:
  Vector2d out_direction(const Node& n) const {
    return graph::far_anchor(n, cur().point) - cur().point;
  }

  const graph::TopologicalMap* map_;
  std::vector<NodeId> nodes_;
  Vector2d heading_;
  double s_in_ = 0;
  bool undecided_ = false;
};

const Node& named(const graph::TopologicalMap& map, const std::string& name) {
  const Node* n = map.find_node(name);
  if (!n) throw Refusal{"no place named '" + name + "' in the map"};
  return *n;
}

std::string what(const graph::RouteCommand& c) {
  return graph::ordinal_word(c.ordinal) + " " + graph::to_string(c.place);
}

void carry_out(Walker& w, const graph::TopologicalMap& map, const graph::RouteCommand& c) {
  switch (c.kind) {
    case CommandKind::follow_corridor: {
      if (c.target.empty()) {
        if (w.cur().place == Place::corridor) return;
        const Node* n = w.ahead();
        if (!n || n->place != Place::corridor)
          throw Refusal{"no corridor ahead of " + w.cur().name};
        w.move(*n);
        return;
      }
      const Node& t = named(map, c.target);
      if (t.id == w.cur().id) return;
      for (const Node* n : w.exits())
        if (n->id == t.id) return w.move(t);
      return w.go_to(t);
    }
    case CommandKind::turn: {
      int count = 0;
      for (int step = 0; step < 256; ++step) {
        const Node* n = w.ahead();
        if (!n) throw Refusal{"no " + what(c) + " ahead: the way ends at " + w.cur().name};
        w.move(*n);
        if (n->place == c.place && ++count == c.ordinal) {
          const Node* t = w.turn(c.direction);
          if (!t)
            throw Refusal{std::string("no way ") +
                          (c.direction == graph::TurnDirection::left ? "left" : "right") + " at " +
                          n->name};
          w.move(*t);
          return;
        }
        if (n->place != Place::corridor && n->place != Place::junction && n->place != Place::corner)
          throw Refusal{"no " + what(c) + " ahead: the way ends at " + n->name};
      }
      throw Refusal{"no " + what(c) + " ahead"};
    }
    case CommandKind::go_through_door: {
      const Node& d = named(map, c.target);
      bool adjacent = d.id == w.cur().id;
      for (const Node* n : w.exits()) adjacent = adjacent || n->id == d.id;
      if (!adjacent) w.go_to(d);
      if (w.cur().id != d.id) w.move(d);
      const auto beyond = w.exits();
      if (beyond.empty()) throw Refusal{"door " + d.name + " leads nowhere"};
      w.move(*beyond.front());
      return;
    }
    case CommandKind::stop_at_door:
      if (c.target.empty()) {
        if (w.cur().place != Place::corridor)
          throw Refusal{"not in a corridor to count doors (in " + w.cur().name + ")"};
        int count = 0;
        for (const auto& [door, side] : w.doors_ahead()) {
          if (side != c.side || ++count != c.ordinal) continue;
          return w.go_to(named(map, door->name));
        }
        throw Refusal{"no " + graph::ordinal_word(c.ordinal) + " door on the " +
                      graph::to_string(c.side) + " ahead in " + w.cur().name};
      }
      return w.go_to(named(map, c.target));
    case CommandKind::enter:
    case CommandKind::stop_at_node:
    case CommandKind::go_to:
      return w.go_to(named(map, c.target));
  }
}

}  // namespace

Interpretation interpret_commands(const graph::TopologicalMap& map, const Pose2& start,
                                  const std::vector<graph::RouteCommand>& commands) {
  Interpretation out;
  const Node* here = map.node_containing(start.translation());
  if (!here) {
    out.why = "the robot is in no place of the map";
    return out;
  }
  // Walks commands from k on; where the walk came into a corridor from the side, it tries one way
  // along it and then the other. The first refusal met is the one reported.
  struct Walked {
    std::optional<Walker> walker;
    std::vector<std::size_t> completes_at;
    int failed = -1;
    std::string why;
  };
  const std::function<Walked(Walker, std::size_t, std::vector<std::size_t>)> walk =
      [&](Walker w, std::size_t k, std::vector<std::size_t> done) -> Walked {
    for (; k < commands.size(); ++k) {
      if (w.undecided()) {
        Walked first;
        for (bool reverse : {false, true}) {
          Walker branch = w;
          branch.decide(reverse);
          Walked r = walk(std::move(branch), k, done);
          if (r.walker) return r;
          if (!reverse) first = std::move(r);
        }
        return first;
      }
      try {
        carry_out(w, map, commands[k]);
      } catch (const Refusal& r) {
        return {std::nullopt,
                {},
                static_cast<int>(k),
                "command " + std::to_string(k + 1) + " (" + commands[k].text() + "): " + r.why};
      }
      done.push_back(w.index());
    }
    return {std::move(w), std::move(done), -1, {}};
  };
  Walked walked = walk(Walker(map, *here, start), 0, {});
  if (!walked.walker) {
    out.failed = walked.failed;
    out.why = walked.why;
    return out;
  }
  const Walker& w = *walked.walker;
  CommandPlan plan;
  plan.commands = commands;
  plan.completes_at = std::move(walked.completes_at);
  plan.route.nodes = w.nodes();
  for (std::size_t k = 1; k < plan.route.nodes.size(); ++k) {
    for (const graph::Edge* e : map.out_edges(plan.route.nodes[k - 1])) {
      if (e->end != plan.route.nodes[k]) continue;
      plan.route.edges.push_back(e->id);
      plan.route.cost += e->cost;
      break;
    }
  }
  plan.waypoints = graph::route_waypoints(map, plan.route);
  if (here->axis && !plan.waypoints.empty())
    plan.waypoints.front() = here->axis->point_at(
        std::clamp(here->axis->along(start.translation()), 0.0, here->axis->length()));
  if (plan.waypoints.empty() || (plan.waypoints.front() - start.translation()).norm() > 1e-6)
    plan.waypoints.insert(plan.waypoints.begin(), start.translation());
  out.plan = std::move(plan);
  return out;
}

}  // namespace lampnav::navigation
