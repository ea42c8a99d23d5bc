#include "lampnav/navigation/executor.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lampnav/core/error.hpp"
#include "lampnav/graph/planner.hpp"

namespace lampnav::navigation {

void ExecutorOptions::validate() const {
  auto check = [](bool ok, const char* field) {
    if (!ok) throw InputError({"", "executor options", field}, "must be positive");
  };
  check(max_speed > 0, "max_speed");
  check(max_turn_rate > 0, "max_turn_rate");
  check(lookahead > 0, "lookahead");
  check(goal_tolerance > 0, "goal_tolerance");
  check(max_lost_s > 0, "max_lost_s");
  check(off_route_m > 0, "off_route_m");
  if (!(explore_m >= 0))
    throw InputError({"", "executor options", "explore_m"}, "must not be negative");
  check(explore_speed > 0, "explore_speed");
}

const char* to_string(ExecutorStatus s) {
  switch (s) {
    case ExecutorStatus::idle:
      return "idle";
    case ExecutorStatus::driving:
      return "driving";
    case ExecutorStatus::waiting:
      return "waiting";
    case ExecutorStatus::arrived:
      return "arrived";
    case ExecutorStatus::failed:
      return "failed";
  }
  return "?";
}

namespace {

// Distance from p to the polyline.
double distance_to_path(const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector2d& p) {
  double best = pts.empty() ? 0.0 : (pts.front() - p).norm();
  for (std::size_t k = 1; k < pts.size(); ++k) {
    const Eigen::Vector2d a = pts[k - 1], b = pts[k];
    const double t =
        std::clamp((p - a).dot(b - a) / std::max(1e-12, (b - a).squaredNorm()), 0.0, 1.0);
    best = std::min(best, (a + t * (b - a) - p).norm());
  }
  return best;
}

std::string joined(const std::vector<graph::RouteCommand>& commands) {
  std::string s;
  for (const auto& c : commands) s += (s.empty() ? "" : ", ") + c.text();
  return s;
}

}  // namespace

Executor::Executor(const graph::TopologicalMap& map, double semi_axis,
                   const ExecutorOptions& options)
    : map_(&map), semi_axis_(semi_axis), o_(options) {
  o_.validate();
  if (!(semi_axis > 0))
    throw InputError({"", "robot.json", "wheels.semi_axis"}, "must be positive");
}

bool Executor::adopt(Stamp stamp, const Pose2& pose,
                     const std::vector<graph::RouteCommand>& commands) {
  Interpretation i = interpret_commands(*map_, pose, commands);
  if (!i.plan) {
    fail(stamp, i.why);
    return false;
  }
  plan_ = std::move(*i.plan);
  goal_ = map_->node(plan_.route.nodes.back()).name;
  follower_.emplace(plan_.waypoints, PathFollower::Options{o_.max_speed, o_.max_turn_rate,
                                                           o_.lookahead, o_.goal_tolerance});
  reached_ = 0;
  last_node_ = &map_->node(plan_.route.nodes.front());
  status_ = ExecutorStatus::driving;
  return true;
}

std::optional<WheelSpeeds> Executor::explore(const fusion::LocalizerEstimate& e) {
  if (explore_stamp_ && e.stamp > *explore_stamp_)
    explored_m_ += std::abs(explore_v_) * to_seconds(e.stamp - *explore_stamp_);
  explore_stamp_ = e.stamp;
  explore_v_ = 0;
  if (explored_m_ >= o_.explore_m || e.hypotheses.empty()) return std::nullopt;
  // How far the corridor runs ahead, in every place the robot may be: the motion must be
  // possible in all of them.
  const auto ahead = [&](const Pose2& p) -> std::optional<std::pair<double, Eigen::Vector2d>> {
    const graph::Node* n = map_->node_containing(p.translation());
    if (!n || !n->axis) return std::nullopt;
    Eigen::Vector2d d = n->axis->direction();
    if (d.dot(Eigen::Vector2d(std::cos(p.yaw()), std::sin(p.yaw()))) < 0) d = -d;
    const Eigen::Vector2d end =
        d.dot(n->axis->second - n->axis->first) > 0 ? n->axis->second : n->axis->first;
    return std::pair{(end - p.translation()).dot(d), d};
  };
  const auto lead = ahead(e.pose);
  if (!lead) return std::nullopt;
  double reach = lead->first;
  for (const auto& h : e.hypotheses) {
    const auto a = ahead(h.pose);
    if (!a) return std::nullopt;  // one of them stands at a junction: wait for the views
    reach = std::min(reach, a->first);
  }
  // To the end of the shortest, and a metre into the place beyond it, where views differ.
  const double go = reach + 1.0;
  if (go < 0.3) return std::nullopt;
  const Eigen::Vector2d target = e.pose.translation() + go * lead->second;
  const Eigen::Vector2d to = target - e.pose.translation();
  const double err = wrap_angle(std::atan2(to.y(), to.x()) - e.pose.yaw());
  double v = 0, w = 0;
  if (std::abs(err) > 0.35) {
    w = std::copysign(std::min(o_.max_turn_rate, 0.6), err);
  } else {
    v = o_.explore_speed;
    w = std::clamp(2.0 * err, -o_.max_turn_rate, o_.max_turn_rate);
  }
  explore_v_ = v;
  if (!explore_noted_) {
    explore_noted_ = true;
    note(e.stamp, "ambiguous: driving along the corridor to where the look-alike places differ");
  }
  return WheelSpeeds{v - w * semi_axis_, v + w * semi_axis_};
}

bool Executor::start(Stamp stamp, const Pose2& pose,
                     const std::vector<graph::RouteCommand>& commands) {
  if (commands.empty()) {
    fail(stamp, "no command to carry out");
    return false;
  }
  if (!adopt(stamp, pose, commands)) return false;
  note(stamp, "started: " + joined(commands) + " (to " + goal_ + ")");
  return true;
}

bool Executor::replan(Stamp stamp, const Pose2& pose, const std::string& why) {
  const graph::Node* goal = map_->find_node(goal_);
  const graph::Node* here = map_->node_containing(pose.translation());
  if (!here) {
    fail(stamp, why + ", and the robot is in no place of the map");
    return false;
  }
  const auto route = graph::plan_route(*map_, here->id, goal->id);
  if (!route) {
    fail(stamp, why + ", and there is no way from " + here->name + " to " + goal_);
    return false;
  }
  const auto commands = graph::route_to_commands(*map_, *route);
  if (!adopt(stamp, pose, commands)) return false;
  ++replans_;
  note(stamp, why + ": planned again from " + here->name + ": " + joined(commands));
  return true;
}

void Executor::fail(Stamp stamp, const std::string& why) {
  status_ = ExecutorStatus::failed;
  reason_ = why;
  follower_.reset();
  note(stamp, "failed: " + why);
}

std::size_t Executor::command() const {
  for (std::size_t k = 0; k < plan_.completes_at.size(); ++k)
    if (plan_.completes_at[k] > reached_) return k;
  return plan_.completes_at.empty() ? 0 : plan_.completes_at.size() - 1;
}

WheelSpeeds Executor::step(const fusion::LocalizerEstimate& e) {
  if (status_ == ExecutorStatus::idle || status_ == ExecutorStatus::arrived ||
      status_ == ExecutorStatus::failed)
    return {};
  if (!e.known()) {
    if (!lost_since_) {
      lost_since_ = e.stamp;
      explored_m_ = 0;
      explore_stamp_.reset();
      explore_noted_ = false;
      status_ = ExecutorStatus::waiting;
      note(e.stamp,
           std::string(fusion::to_string(e.mode)) + ": stopped, waiting for relocalization");
    }
    if (e.mode == fusion::LocalizerMode::ambiguous && e.undecidable) {
      fail(e.stamp, "the robot cannot tell where it is: " + e.why);
      return {};
    }
    if (e.mode == fusion::LocalizerMode::ambiguous) {
      if (const auto speeds = explore(e)) return *speeds;
    } else {
      explore_stamp_.reset();
    }
    if (to_seconds(e.stamp - *lost_since_) > o_.max_lost_s) {
      std::ostringstream why;
      why << "lost for more than " << o_.max_lost_s << " s";
      fail(e.stamp, why.str());
    }
    return {};
  }
  if (lost_since_) {
    lost_since_.reset();
    if (!replan(e.stamp, e.pose, "relocalized")) return {};
  } else if (distance_to_path(plan_.waypoints, e.pose.translation()) > o_.off_route_m) {
    if (!replan(e.stamp, e.pose, "off the route")) return {};
  }
  // Progress: the places the localizer reports entering, in the route's order.
  if (e.node && e.node != last_node_) {
    last_node_ = e.node;
    for (std::size_t k = reached_ + 1; k < plan_.route.nodes.size() && k <= reached_ + 3; ++k) {
      if (plan_.route.nodes[k] != e.node->id) continue;
      const std::size_t before = command();
      reached_ = k;
      if (command() != before)
        note(e.stamp, "entered " + e.node->name + ": " + plan_.commands[command()].text());
      break;
    }
  }
  status_ = ExecutorStatus::driving;
  const auto [v, w] = follower_->command(e.pose);
  if (follower_->arrived()) {
    status_ = ExecutorStatus::arrived;
    reached_ = plan_.route.nodes.size() - 1;
    note(e.stamp, "arrived at " + goal_);
    return {};
  }
  return {v - w * semi_axis_, v + w * semi_axis_};
}

}  // namespace lampnav::navigation
