#include "lampnav/sim/map_oracle.hpp"

#include <cmath>
#include <unordered_set>

#include "lampnav/core/error.hpp"

namespace lampnav::sim {

using Eigen::Vector2d;
using graph::Lamp;

void MapOracleOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"map oracle options", "", field}, what);
  };
  check(view_radius_m > 0 && view_radius_m < 1000, "view_radius_m", "must be 0 to 1000 m");
  check(tolerance_m > 0 && tolerance_m < 1, "tolerance_m", "must be 0 to 1 m");
  check(border_m >= 0 && border_m < view_radius_m, "border_m", "must be 0 to the view radius");
  check(same_place_m > 0, "same_place_m", "must be positive");
  check(wall_margin_m >= 0, "wall_margin_m", "must not be negative");
  check(max_twins > 0, "max_twins", "must be positive");
}

namespace {

constexpr double kDeg = M_PI / 180.0;

// Lamps of one kind: shape, size and height alike.
bool same_kind(const Lamp& a, const Lamp& b, double tol) {
  return a.shape == b.shape && std::fabs(a.length - b.length) <= 0.05 &&
         std::fabs(a.width - b.width) <= 0.05 && std::fabs(a.xyz.z() - b.xyz.z()) <= tol;
}

// Two lamps that the cameras cannot tell apart: of one kind and (rectangles) on the same axis
// once the first is turned by `turn`.
bool alike(const Lamp& a, const Lamp& b, double turn, double tol) {
  if (!same_kind(a, b, tol)) return false;
  if (a.shape == graph::LampShape::disc) return true;
  const double d = wrap_angle(2 * (a.yaw + turn - b.yaw)) / 2;  // an axis: modulo pi
  return std::fabs(d) < 5 * kDeg;
}

struct Twin {
  Pose2 motion;  // the drive moved: twin pose = motion * true pose
  std::unordered_set<const Lamp*> checked_true, checked_twin;
  bool alive = true;
};

}  // namespace

MapOracle::MapOracle(const graph::TopologicalMap& map, const MapOracleOptions& options)
    : map_(&map), o_(options) {
  o_.validate();
}

OracleVerdict MapOracle::judge(const std::vector<DriveSample>& drive) const {
  const graph::TopologicalMap& map = *map_;
  auto works = [&](const Lamp& l) { return !o_.failed_lamps.count(l.id.value); };
  auto view = [&](const Vector2d& p, double radius) {
    std::vector<const Lamp*> v;
    for (const Lamp* l : map.lamps_within(p, radius))
      if (works(*l)) v.push_back(l);
    return v;  // nearest first
  };
  // A working lamp alike `l` (turned by `turn`) within the tolerance of `at`.
  auto has_alike = [&](const Lamp& l, const Vector2d& at, double turn) {
    for (const Lamp* m : map.lamps_within(at, o_.tolerance_m))
      if (works(*m) && alike(l, *m, turn, o_.tolerance_m)) return true;
    return false;
  };
  auto inside = [&](const Vector2d& p) {
    if (map.node_containing(p)) return true;
    for (int k = 0; k < 8; ++k) {
      const double a = k * M_PI / 4;
      if (map.node_containing(p + o_.wall_margin_m * Vector2d(std::cos(a), std::sin(a))))
        return true;
    }
    return false;
  };
  auto is_truth = [&](const Pose2& twin_pose, const Pose2& truth) {
    return (twin_pose.translation() - truth.translation()).norm() < o_.same_place_m &&
           std::fabs(wrap_angle(twin_pose.yaw() - truth.yaw())) < 5 * kDeg;
  };

  OracleVerdict out;
  // The first view with two lamps gives the twins.
  std::size_t first = 0;
  std::vector<const Lamp*> seen;
  for (; first < drive.size(); ++first) {
    seen = view(drive[first].pose.translation(), o_.view_radius_m - o_.border_m);
    if (seen.size() >= 2) break;
  }
  if (first == drive.size()) return out;  // never two lamps in view: nothing to tell apart
  const Lamp& a1 = *seen[0];
  const Lamp& a2 = *seen[1];
  const Vector2d pa1 = a1.xyz.head<2>(), pa2 = a2.xyz.head<2>();
  const double spacing = (pa2 - pa1).norm();
  const double heading_a = std::atan2(pa2.y() - pa1.y(), pa2.x() - pa1.x());
  std::vector<Twin> twins;
  const Pose2& p0 = drive[first].pose;
  for (const auto& node : map.nodes()) {
    for (const Lamp& b1 : node.lamps) {
      if (!works(b1) || !same_kind(a1, b1, o_.tolerance_m)) continue;
      for (const Lamp* b2 : map.lamps_within(b1.xyz.head<2>(), spacing + o_.tolerance_m)) {
        if (b2 == &b1 || !works(*b2)) continue;
        const Vector2d pb1 = b1.xyz.head<2>(), pb2 = b2->xyz.head<2>();
        if (std::fabs((pb2 - pb1).norm() - spacing) > o_.tolerance_m) continue;
        const double turn =
            wrap_angle(std::atan2(pb2.y() - pb1.y(), pb2.x() - pb1.x()) - heading_a);
        if (!alike(a1, b1, turn, o_.tolerance_m) || !alike(a2, *b2, turn, o_.tolerance_m)) continue;
        const Pose2 rot(0, 0, turn);
        const Vector2d t = pb1 - rot.transform_from(pa1);
        Twin tw;
        tw.motion = Pose2(t, turn);
        if (is_truth(tw.motion * p0, p0)) continue;
        twins.push_back(std::move(tw));
        if (twins.size() >= o_.max_twins) break;
      }
      if (twins.size() >= o_.max_twins) break;
    }
  }
  out.twins = twins.size();

  // Carry every twin along the whole drive (from its start: the views before the first pair
  // must match too) until it dies.
  const double inner = o_.view_radius_m - o_.border_m;
  std::size_t alive = twins.size();
  double last_death = 0.0;  // travel at which the last twin died (0: none was enumerated)
  for (const DriveSample& s : drive) {
    if (alive == 0) break;
    const std::vector<const Lamp*> truth_view = view(s.pose.translation(), inner);
    for (Twin& tw : twins) {
      if (!tw.alive) continue;
      const Pose2 q = tw.motion * s.pose;
      bool ok = inside(q.translation());
      for (std::size_t k = 0; ok && k < truth_view.size(); ++k) {
        const Lamp* l = truth_view[k];
        if (!tw.checked_true.insert(l).second) continue;
        ok = has_alike(*l, tw.motion.transform_from(l->xyz.head<2>()), tw.motion.yaw());
      }
      if (ok) {
        const Pose2 back = tw.motion.inverse();
        for (const Lamp* l : view(q.translation(), inner)) {
          if (!tw.checked_twin.insert(l).second) continue;
          if (!has_alike(*l, back.transform_from(l->xyz.head<2>()), back.yaw())) {
            ok = false;
            break;
          }
        }
      }
      if (!ok) {
        tw.alive = false;
        --alive;
        last_death = s.travel_m;
      }
    }
  }
  out.alive_at_end = alive;
  if (alive == 0) out.distinguishing_m = last_death;
  return out;
}

}  // namespace lampnav::sim
