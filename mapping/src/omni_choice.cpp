#include "omni_choice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::mapping {

namespace {

LampId lamp_name(std::size_t k) { return LampId("L" + std::to_string(k + 1)); }

// The two parts' lamps as one map, the part put where `motion` says; a part's lamp on one of the
// map's (within `same_m`) is that lamp.
graph::TopologicalMap joined(const DrivePart& map, const DrivePart& part, const Pose2& motion,
                             double same_m) {
  graph::Node node;
  node.id = NodeId(1);
  node.name = "joined";
  node.place = graph::Place::hall;
  for (const MappedLamp& l : *map.lamps)
    node.lamps.push_back(l.as_map_lamp(lamp_name(node.lamps.size())));
  const std::size_t from_map = node.lamps.size();
  for (const MappedLamp& l : *part.lamps) {
    graph::Lamp g = l.as_map_lamp(lamp_name(node.lamps.size()), motion);
    bool same = false;
    for (std::size_t i = 0; i < from_map && !same; ++i)
      same = (node.lamps[i].xyz.head<2>() - g.xyz.head<2>()).norm() < same_m;
    if (!same) node.lamps.push_back(g);
  }
  graph::TopologicalMap out("joined");
  out.add_node(node);
  return out;
}

// At most `n` of the views, spread evenly, each with the drive's pose then.
std::vector<std::pair<const OmniView*, Pose2>> posed(const std::vector<const OmniView*>& views,
                                                     const std::vector<KeyframePose>& keyframes,
                                                     int n) {
  std::vector<std::pair<const OmniView*, Pose2>> all;
  for (const OmniView* v : views)
    if (const auto p = pose_at(keyframes, v->stamp, kNoGap)) all.emplace_back(v, *p);
  if (static_cast<int>(all.size()) <= n) return all;
  std::vector<std::pair<const OmniView*, Pose2>> out;
  for (int k = 0; k < n; ++k) out.push_back(all[k * all.size() / n]);
  return out;
}

}  // namespace

std::optional<Pose2> pose_at(const std::vector<KeyframePose>& keyframes, Stamp t, double max_gap_s,
                             double max_turn) {
  if (keyframes.empty() || t < keyframes.front().stamp || t > keyframes.back().stamp)
    return std::nullopt;
  auto it = std::lower_bound(keyframes.begin(), keyframes.end(), t,
                             [](const KeyframePose& k, Stamp s) { return k.stamp < s; });
  if (it->stamp == t) return it->pose;
  const KeyframePose& a = *(it - 1);
  const double gap = to_seconds(it->stamp - a.stamp);
  if (gap > max_gap_s || std::abs(wrap_angle(it->pose.yaw() - a.pose.yaw())) > max_turn)
    return std::nullopt;
  return interpolate(a.pose, it->pose, to_seconds(t - a.stamp) / std::max(1e-9, gap));
}

OmniChoice choose_by_omni(const DrivePart& map, const DrivePart& part,
                          const std::vector<PlacementFit>& candidates,
                          const std::vector<const OmniView*>& map_views,
                          const std::vector<const OmniView*>& part_views,
                          const CameraDescription& omni_camera, const OmniChoiceOptions& o) {
  OmniChoice out;
  if (!o.tries(candidates.size())) return out;
  const auto before = posed(map_views, *map.keyframes, o.max_views);
  const auto after = posed(part_views, *part.keyframes, o.max_views);
  out.views = static_cast<int>(before.size() + after.size());
  if (out.views == 0) return out;
  fusion::GlobalLocalizerOptions lo;
  lo.parallel = false;
  // Per candidate, the lamps each view misses (the views of both parts, in one order).
  std::vector<std::vector<int>> missed;
  for (const PlacementFit& c : candidates) {
    const graph::TopologicalMap m = joined(map, part, c.motion, 0.3);
    const fusion::GlobalLocalizer localizer(m, omni_camera, lo);
    std::vector<int> per_view;
    for (const auto& [v, pose] : before)
      per_view.push_back(
          localizer.score(pose, o.position_sigma_m, o.yaw_sigma, v->detection).missing);
    for (const auto& [v, pose] : after)
      per_view.push_back(
          localizer.score(c.motion * pose, o.position_sigma_m, o.yaw_sigma, v->detection).missing);
    missed.push_back(std::move(per_view));
  }
  // What each part's views miss of its own lamps alone: the misses no joining causes.
  std::vector<int> own;
  {
    const std::vector<MappedLamp> none;
    // The localizers keep their maps by reference: each map outlives its localizer.
    const graph::TopologicalMap map_lamps = joined(map, {&none, nullptr}, Pose2::identity(), 0.3);
    const graph::TopologicalMap part_lamps = joined({&none, nullptr}, part, Pose2::identity(), 0.3);
    const fusion::GlobalLocalizer map_alone(map_lamps, omni_camera, lo);
    const fusion::GlobalLocalizer part_alone(part_lamps, omni_camera, lo);
    for (const auto& [v, pose] : before)
      own.push_back(map_alone.score(pose, o.position_sigma_m, o.yaw_sigma, v->detection).missing);
    for (const auto& [v, pose] : after)
      own.push_back(part_alone.score(pose, o.position_sigma_m, o.yaw_sigma, v->detection).missing);
  }
  out.own_missed = std::accumulate(own.begin(), own.end(), 0);
  std::vector<int> total;
  for (const auto& m : missed) total.push_back(std::accumulate(m.begin(), m.end(), 0));
  const std::size_t best =
      static_cast<std::size_t>(std::min_element(total.begin(), total.end()) - total.begin());
  out.fewest_missed = total[best];
  // Chance misses (a person in the way, a lamp's blob merged with its neighbour's; about 1 % of
  // the lamps in clear view) are mostly the same lamps at every candidate: views far from where
  // the parts meet see the same lamps at all of them. So the best is compared view by view with
  // each other candidate: the lamps only the other misses must outnumber those only the best
  // misses by far more than the latter's spread, taken as a count.
  bool clear = true;
  out.least_extra = std::numeric_limits<int>::max();
  for (std::size_t c = 0; c < missed.size(); ++c) {
    if (c == best) continue;
    int extra = 0, against = 0;
    for (std::size_t v = 0; v < missed[c].size(); ++v) {
      extra += std::max(0, missed[c][v] - missed[best][v]);
      against += std::max(0, missed[best][v] - missed[c][v]);
    }
    out.least_extra = std::min(out.least_extra, extra);
    if (extra < o.min_gap + o.gap_sigmas * std::sqrt(against + 1.0)) clear = false;
  }
  // Nor is the best taken unless it explains the views about as well as each part alone: the
  // lamps it puts in clear view that a view does not show, past those the view misses of its own
  // part's lamps, within the same allowance. A part put down where the drive before it never
  // went fits no place, but in a regular building its lamps may still fit one or a few places
  // of the map alike; the omni views see around it what those places do not hold.
  for (std::size_t v = 0; v < own.size(); ++v)
    out.joined_extra += std::max(0, missed[best][v] - own[v]);
  out.explains = out.joined_extra <= o.min_gap + o.gap_sigmas * std::sqrt(out.own_missed + 1.0);
  if (clear && out.explains) out.chosen = best;
  return out;
}

}  // namespace lampnav::mapping
