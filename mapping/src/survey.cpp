#include "lampnav/mapping/survey.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "drive_scale.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/fusion/ceiling_geometry.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav/mapping/rigid_fit.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::mapping {

using Eigen::Vector2d;
using Eigen::Vector3d;

void SurveyOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"survey options", "", field}, what);
  };
  check(moved_m > 0, "moved_m", "must be positive");
  check(match_m > moved_m, "match_m", "must be more than moved_m");
  check(min_views >= 1, "min_views", "must be at least 1");
  check(view_margin >= 0 && view_margin < 0.5, "view_margin", "must be 0 to 0.5");
  check(max_scale_change >= 0 && max_scale_change < 0.5, "max_scale_change", "must be 0 to 0.5");
  check(scale_extent_m >= 0, "scale_extent_m", "must not be negative");
}

const char* to_string(LampStatus s) {
  switch (s) {
    case LampStatus::ok:
      return "ok";
    case LampStatus::failed:
      return "failed";
    case LampStatus::moved:
      return "moved";
    case LampStatus::added:
      return "new";
  }
  return "?";
}

namespace {

bool same_kind(graph::LampShape shape, double length, const graph::Lamp& l) {
  return shape == l.shape && std::abs(length - l.length) < 0.25 * std::max(l.length, 0.1);
}

// The place next to a corridor's end: the neighbour whose point is nearest that end.
std::string place_at(const graph::TopologicalMap& map, const graph::Node& n, const Vector2d& end) {
  std::string best;
  double best_d = 1e18;
  for (const graph::Edge* e : map.out_edges(n.id)) {
    const graph::Node& m = map.node(e->end);
    const double d = (m.point - end).norm();
    if (d < best_d) {
      best_d = d;
      best = m.name;
    }
  }
  return best.empty() ? "its end" : best;
}

// "C3, 4th lamp from J2" for a lamp of the map; "C3, 5.2 m from J2" for a point.
std::string describe(const graph::TopologicalMap& map, const graph::Node& n, const Vector2d& p,
                     const graph::Lamp* lamp) {
  if (!n.axis) {
    if (!lamp) return n.name;
    for (std::size_t i = 0; i < n.lamps.size(); ++i)
      if (n.lamps[i].id == lamp->id)
        return n.name + ", lamp " + std::to_string(i + 1) + " of " + std::to_string(n.lamps.size());
    return n.name;
  }
  const double s = n.axis->along(p);
  const bool from_first = s <= n.axis->length() / 2;
  const std::string from = place_at(map, n, from_first ? n.axis->first : n.axis->second);
  if (!lamp) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f m", from_first ? s : n.axis->length() - s);
    return n.name + ", " + buf + " from " + from;
  }
  const auto order = map.lamps_in_walking_order(
      n.id, from_first ? graph::Travel::forward : graph::Travel::backward);
  // A corridor of two rows (or more): the lamp's row, left or right walking from `from`, and its
  // place in that row. Rows are groups of at least two lamps whose offsets across the axis are
  // more than 0.4 m from the next group's; a lamp alone off the row (a crossing corridor's first,
  // in the region) makes no row, and is counted in walking order among all.
  const Vector2d dir = n.axis->direction();
  const auto left_of_walk = [&](const graph::Lamp* l) {
    const Vector2d d = l->xyz.head<2>() - n.axis->first;
    return (from_first ? 1 : -1) * (dir.x() * d.y() - dir.y() * d.x());
  };
  std::vector<std::pair<double, const graph::Lamp*>> across;  // from the left
  for (const graph::Lamp* l : order) across.emplace_back(left_of_walk(l), l);
  std::sort(across.begin(), across.end(),
            [](const auto& x, const auto& y) { return x.first > y.first; });
  std::map<const graph::Lamp*, int> row_of;  // rows numbered from the left; -1: a lamp alone
  int rows = 0;
  for (std::size_t i = 0, j; i < across.size(); i = j) {
    for (j = i + 1; j < across.size() && across[j - 1].first - across[j].first <= 0.4;) ++j;
    const int r = j - i >= 2 ? rows++ : -1;
    for (std::size_t k = i; k < j; ++k) row_of[across[k].second] = r;
  }
  const int row = rows > 1 ? row_of.at(lamp) : -1;
  std::string in_words;
  if (row >= 0 && rows == 2)
    in_words = row == 0 ? " of the left row" : " of the right row";
  else if (row >= 0)
    in_words =
        " of row " + std::to_string(row + 1) + " of " + std::to_string(rows) + " from the left";
  int k = 0;
  for (const graph::Lamp* l : order) {
    if (row >= 0 && row_of.at(l) != row) continue;
    ++k;
    if (l->id == lamp->id)
      return n.name + ", " + graph::ordinal_number(k) + " lamp" + in_words + " from " + from;
  }
  return n.name;
}

}  // namespace

SurveyResult survey(const graph::TopologicalMap& map, const MappingResult& drive_as_mapped,
                    const RobotDescription& robot, const SurveyOptions& o) {
  o.validate();
  MappingResult drive = drive_as_mapped;  // scaled to the map below
  const CameraDescription* cam = robot.find_camera("ceiling_camera");
  if (!cam) throw InputError({"robot.json", "", "cameras"}, "no camera named \"ceiling_camera\"");
  const auto& seen = drive.lamps;
  if (seen.size() < 3)
    throw JobFailed("the drive mapped " + std::to_string(seen.size()) +
                    " lamps: too few to place it in the map");
  const double inlier_m = 0.3;

  // 1. The rigid motion most of the drive's lamps agree on: from two nearby lamps of the drive
  // put on every pair of map lamps alike and as far apart.
  auto agreeing = [&](const Pose2& T, double within) {
    int n = 0;
    for (const auto& l : seen) {
      for (const graph::Lamp* m : map.lamps_within(T.transform_from(l.xyz.head<2>()), within)) {
        if (same_kind(l.shape, l.length, *m)) {
          ++n;
          break;
        }
      }
    }
    return n;
  };
  std::vector<std::size_t> order(seen.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return seen[a].sightings > seen[b].sightings; });
  struct Candidate {
    Pose2 T;
    int votes = 0;
  };
  std::vector<Candidate> best;  // the best few, distinct
  if (o.start) best.push_back({*o.start * drive.keyframes.front().pose.inverse(), 0});
  for (std::size_t k = 0; !o.start && k < std::min<std::size_t>(order.size(), 8); ++k) {
    const MappedLamp& a1 = seen[order[k]];
    const MappedLamp* a2 = nullptr;
    double d = 1e18;
    for (const auto& l : seen) {
      const double dd = (l.xyz - a1.xyz).head<2>().norm();
      if (&l != &a1 && dd > 0.5 && dd < d) {
        d = dd;
        a2 = &l;
      }
    }
    if (!a2) continue;
    const Vector2d pa1 = a1.xyz.head<2>(), pa2 = a2->xyz.head<2>();
    const double heading_a = std::atan2(pa2.y() - pa1.y(), pa2.x() - pa1.x());
    for (const auto& node : map.nodes()) {
      for (const graph::Lamp& b1 : node.lamps) {
        if (!same_kind(a1.shape, a1.length, b1)) continue;
        for (const graph::Lamp* b2 : map.lamps_within(b1.xyz.head<2>(), d + 0.15)) {
          if (b2 == &b1 || !same_kind(a2->shape, a2->length, *b2)) continue;
          const Vector2d pb1 = b1.xyz.head<2>(), pb2 = b2->xyz.head<2>();
          if (std::abs((pb2 - pb1).norm() - d) > 0.15) continue;
          const double yaw =
              wrap_angle(std::atan2(pb2.y() - pb1.y(), pb2.x() - pb1.x()) - heading_a);
          const Pose2 rot(0, 0, yaw);
          const Pose2 T(pb1 - rot.transform_from(pa1), yaw);
          const int votes = agreeing(T, inlier_m);
          bool merged = false;
          for (auto& c : best) {
            if ((c.T.translation() - T.translation()).norm() < 1.0 &&
                std::abs(wrap_angle(c.T.yaw() - T.yaw())) < 0.1) {
              if (votes > c.votes) c = {T, votes};
              merged = true;
            }
          }
          if (!merged) best.push_back({T, votes});
          std::sort(best.begin(), best.end(),
                    [](const Candidate& x, const Candidate& y) { return x.votes > y.votes; });
          if (best.size() > 4) best.resize(4);
        }
      }
    }
  }
  if (o.start) best.front().votes = agreeing(best.front().T, inlier_m);
  if (best.empty() || best.front().votes < 3 ||
      best.front().votes < static_cast<int>(seen.size()) / 2)
    throw JobFailed("the drive's " + std::to_string(seen.size()) +
                    " lamps fit nowhere in the map (at best " +
                    std::to_string(best.empty() ? 0 : best.front().votes) + " agree)");
  if (best.size() > 1 && best[1].votes >= best.front().votes) {
    std::string where;
    for (const auto& c : best) {
      if (c.votes < best.front().votes) break;
      const Pose2 p = c.T * drive.keyframes.front().pose;
      char buf[80];
      std::snprintf(buf, sizeof buf, "%s(%.1f, %.1f) facing %.0f deg", where.empty() ? "" : ", ",
                    p.x(), p.y(), p.yaw() * 180 / M_PI);
      where += buf;
    }
    throw JobFailed(
        "the drive's lamps fit several places of the map alike (a regular "
        "building): it may have started at " +
        where +
        "; give the start (--initial-pose X,Y,YAW) or drive on past a place "
        "that tells them apart");
  }
  // Refine on the lamps that agree closely (moved lamps kept out), and scale the drive to the map:
  // wheels 1 % long put lamps 40 m away 40 cm off, so the lamps within the gate are taken again
  // after each fit, until the gate holds them all and the last round keeps the close ones.
  SurveyResult out;
  Similarity fit{best.front().T, 1.0};
  for (int round = 0; round < 5; ++round) {
    std::vector<std::pair<Vector2d, Vector2d>> pairs;
    for (const auto& l : seen) {
      const auto near =
          map.lamps_within(fit.transform_from(l.xyz.head<2>()), round == 4 ? 0.08 : inlier_m);
      if (!near.empty()) pairs.emplace_back(l.xyz.head<2>(), near.front()->xyz.head<2>());
    }
    if (pairs.size() >= 3) {
      Vector2d middle = Vector2d::Zero();
      for (const auto& p : pairs) middle += p.first;
      middle /= static_cast<double>(pairs.size());
      double spread = 0;
      for (const auto& p : pairs) spread += (p.first - middle).squaredNorm();
      const bool scale_seen = std::sqrt(spread / pairs.size()) >= o.scale_extent_m;
      fit = scale_seen ? fit_similarity(pairs) : Similarity{fit_rigid(pairs), 1.0};
    }
    double sum = 0;
    for (const auto& [a, b] : pairs) sum += (fit.transform_from(a) - b).squaredNorm();
    out.alignment_rms_m = pairs.empty() ? 0 : std::sqrt(sum / pairs.size());
    out.agreeing = static_cast<int>(pairs.size());
  }
  if (std::abs(fit.scale - 1) > o.max_scale_change) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "the drive's lamps fit the map only %.1f %% %s than the wheels measured them "
                  "(more than %.1f %%): not this building, or wheels far off their calibration",
                  100 * std::abs(fit.scale - 1), fit.scale > 1 ? "further apart" : "closer",
                  100 * o.max_scale_change);
    throw JobFailed(buf);
  }
  // The drive in the map's scale: its lamps, heights and keyframes (scale_drive), so that every
  // step below sees it as the map would have it.
  scale_drive(drive, fit.scale, Vector2d::Zero(), cam->mount.xyz.z());
  out.drive_scale = fit.scale;
  const Pose2 T = fit.motion;
  out.drive_to_map = T;

  // 2. Map lamps the ceiling camera had clearly in view, and how often. Only lamps of a kind the
  // drive saw: its detector looks for one kind, and a lamp of another (a room's round lamp seen
  // from a corridor of long ones) is not judged, never taken for failed and out of the map.
  std::vector<const MappedLamp*> kinds;
  for (const MappedLamp& s : seen) {
    bool known = false;
    for (const MappedLamp* k : kinds)
      known = known || (k->shape == s.shape && std::abs(k->length - s.length) < 0.1 * k->length);
    if (!known) kinds.push_back(&s);
  }
  auto looked_for = [&](const graph::Lamp& l) {
    for (const MappedLamp* k : kinds)
      if (same_kind(k->shape, k->length, l)) return true;
    return false;
  };
  const fusion::CeilingGeometry geometry(*cam);
  const vision::PinholeCamera pinhole(*cam);
  const double mu = o.view_margin * cam->width, mv = o.view_margin * cam->height;
  std::map<const graph::Lamp*, int> views;
  for (const auto& k : drive.keyframes) {
    const Pose2 q = T * k.pose;
    for (const graph::Lamp* l : map.lamps_within(q.translation(), 4.0)) {
      if (!looked_for(*l)) continue;
      const auto n = geometry.predict(q, l->xyz);
      if (!n) continue;
      const auto px = pinhole.project(Vector3d(n->x(), n->y(), 1.0));
      if (px && px->x() >= mu && px->y() >= mv && px->x() <= cam->width - mu &&
          px->y() <= cam->height - mv)
        ++views[l];
    }
  }

  // 3. Each judged map lamp against the nearest lamp of the drive (closest pairs first).
  struct Pair {
    double d;
    const graph::Lamp* m;
    std::size_t s;
  };
  std::vector<Pair> pairs;
  for (const auto& [m, v] : views) {
    if (v < o.min_views) continue;
    ++out.judged;
    for (std::size_t i = 0; i < seen.size(); ++i) {
      const double d = (T.transform_from(seen[i].xyz.head<2>()) - m->xyz.head<2>()).norm();
      if (d < o.match_m && same_kind(seen[i].shape, seen[i].length, *m)) pairs.push_back({d, m, i});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.d < b.d; });
  std::map<const graph::Lamp*, std::size_t> claimed;
  std::vector<bool> used(seen.size(), false);
  for (const auto& p : pairs) {
    if (claimed.count(p.m) || used[p.s]) continue;
    claimed[p.m] = p.s;
    used[p.s] = true;
  }
  auto seen_in_map = [&](std::size_t i) {
    Vector3d x = seen[i].xyz;
    x.head<2>() = T.transform_from(seen[i].xyz.head<2>());
    return x;
  };
  std::map<std::string, std::vector<std::pair<const graph::Lamp*, Vector3d>>> moved_in;
  std::map<std::string, std::vector<Vector3d>> added_in;
  std::vector<const graph::Lamp*> failed;
  for (const auto& [m, v] : views) {
    if (v < o.min_views) continue;
    const graph::Node& n = map.node(m->node);
    auto it = claimed.find(m);
    SurveyFinding f;
    f.lamp = m->id.value;
    f.node = n.name;
    f.map_xyz = m->xyz;
    f.where = describe(map, n, m->xyz.head<2>(), m);
    if (it == claimed.end()) {
      f.status = LampStatus::failed;
      failed.push_back(m);
      out.findings.push_back(f);
      continue;
    }
    f.seen_xyz = seen_in_map(it->second);
    f.offset_m = (f.seen_xyz - m->xyz).head<2>().norm();
    if (f.offset_m > o.moved_m) {
      f.status = LampStatus::moved;
      moved_in[n.name].push_back({m, f.seen_xyz});
      out.findings.push_back(f);
    } else {
      ++out.ok;
    }
  }
  for (std::size_t i = 0; i < seen.size(); ++i) {
    if (used[i]) continue;
    const Vector3d x = seen_in_map(i);
    // Near a map lamp the drive never had clearly in view: not judged, not new.
    bool near_known = false;
    for (const graph::Lamp* m : map.lamps_within(x.head<2>(), o.match_m))
      near_known = near_known || same_kind(seen[i].shape, seen[i].length, *m);
    if (near_known) continue;
    const graph::Node* n = map.node_containing(x.head<2>());
    SurveyFinding f;
    f.status = LampStatus::added;
    f.seen_xyz = x;
    f.node = n ? n->name : "";
    f.where = n ? describe(map, *n, x.head<2>(), nullptr) : "outside every place of the map";
    if (n) {
      f.lamp = n->name + "-N" + std::to_string(added_in[n->name].size() + 1);
      added_in[n->name].push_back(x);
    }
    out.findings.push_back(f);
  }
  std::stable_sort(out.findings.begin(), out.findings.end(),
                   [](const SurveyFinding& a, const SurveyFinding& b) { return a.node < b.node; });

  // 4. The corrected map.
  graph::TopologicalMap up(map.name());
  up.set_nav2_keys(map.nav2_keys());
  for (const graph::Node& n : map.nodes()) {
    graph::Node c = n;
    c.lamps.clear();
    for (const graph::Lamp& l : n.lamps) {
      if (std::find(failed.begin(), failed.end(), &l) != failed.end()) continue;
      graph::Lamp copy = l;
      for (const auto& [m, x] : moved_in[n.name])
        if (m == &l && c.region.contains(x.head<2>())) copy.xyz = x;
      c.lamps.push_back(copy);
    }
    int k = 0;
    for (const Vector3d& x : added_in[n.name]) {
      // The new lamp is of the kind of its nearest neighbour in the map.
      const auto near = map.lamps_within(x.head<2>(), 10.0);
      graph::Lamp l = near.empty() ? graph::Lamp{} : *near.front();
      l.id = LampId(n.name + "-N" + std::to_string(++k));
      l.xyz = x;
      c.lamps.push_back(l);
    }
    if (c.axis) {
      std::stable_sort(c.lamps.begin(), c.lamps.end(), [&](const auto& a, const auto& b) {
        return c.axis->along(a.xyz.template head<2>()) < c.axis->along(b.xyz.template head<2>());
      });
    }
    up.add_node(std::move(c));
  }
  for (const graph::Edge& e : map.edges()) up.add_edge(e);
  out.updated = std::move(up);
  return out;
}

}  // namespace lampnav::mapping
