// Method `default`: pairs of blobs matched to pairs of map lamps spaced alike vote for poses;
// those inside the graph's regions are scored, the best refined, ranked and weighed.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <unordered_map>

#include "global_localizer_impl.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/core/parallel.hpp"
#include "pose_grid.hpp"
#include "pose_votes.hpp"
#include "spurious_blobs.hpp"

namespace lampnav::fusion {

using namespace detail;

GlobalLocalizer::Impl::Seeds GlobalLocalizer::Impl::seeds_of(const std::vector<BlobRay>& blobs,
                                                             const LampPairOptions& q,
                                                             std::size_t max, bool oblique) const {
  Seeds s;
  // Nearest the optical axis, where a ray says most about position; never a blob too small to be
  // a lamp (a glint among the few seeds would hide the true pose).
  for (const BlobRay& b : blobs)
    if (b.theta <= q.pair_max_theta_deg * kDeg && (mount_R * b.ray).z() > 0.05 &&
        !is_spurious_blob(spurious_limit, b.theta, b.angular_radius))
      s.rays.push_back(b);
  std::sort(s.rays.begin(), s.rays.end(),
            [](const BlobRay& a, const BlobRay& b) { return a.theta < b.theta; });
  if (s.rays.size() > max) s.rays.resize(max);
  const double sa = std::hypot(q.detection_sigma_deg, q.tilt_sigma_deg) * kDeg;
  const std::size_t nc = classes.size(), ns = s.rays.size();
  s.at.resize(ns * nc);
  s.sigma.assign(ns * nc, -1);
  for (std::size_t j = 0; j < ns; ++j) {
    const Vector3d rb = mount_R * s.rays[j].ray;
    for (std::size_t c = 0; c < nc; ++c) {
      const double h = classes[c].height;
      if (h < 0.2) continue;
      s.at[j * nc + c] = mount_t.head<2>() + (h / rb.z()) * rb.head<2>();
      // A long lamp seen obliquely: its blob's centroid is not the image of its centre, and
      // puts it up to a quarter of its length off (measured on rendered views, 45 to 72
      // degrees off-axis: docs/hypotheses.md); none overhead. The vote keeps its tuned tenth
      // of the length (it ranks; the enumeration must not lose the truth).
      const double off_centre = oblique ? q.seed_centroid_shift * classes[c].length *
                                              std::sqrt(std::max(0.0, 1 - rb.z() * rb.z()))
                                        : 0.1 * classes[c].length;
      const double sj = h * sa / (rb.z() * rb.z()) + off_centre;
      // A seed that puts the lamp no better than this says nothing of the pose.
      if (sj <= 0.5) s.sigma[j * nc + c] = sj;
    }
  }
  return s;
}

template <class Fn>
void GlobalLocalizer::Impl::pair_poses(const Seeds& s, std::size_t j, std::size_t k, Fn fn) const {
  const std::size_t nc = classes.size();
  for (const auto& [key, group] : pair_groups) {
    const double sj = s.sigma[j * nc + key.first], sk = s.sigma[k * nc + key.second];
    if (sj < 0 || sk < 0) continue;
    const Vector2d& qi = s.at[j * nc + key.first];
    const Vector2d& ql = s.at[k * nc + key.second];
    const Vector2d dq = ql - qi;
    const double dn = dq.norm(), dq_angle = std::atan2(dq.y(), dq.x());
    const double tol = 3 * std::hypot(sj, sk) + 0.02;
    auto lo = std::lower_bound(group.begin(), group.end(), dn - tol,
                               [](const LampPair& p, double v) { return p.distance < v; });
    for (auto it = lo; it != group.end() && it->distance <= dn + tol; ++it) {
      const graph::Lamp& La = *lamps[it->a];
      const graph::Lamp& Lb = *lamps[it->b];
      const Vector2d Li(La.xyz.x(), La.xyz.y()), Ll(Lb.xyz.x(), Lb.xyz.y());
      const double yaw = wrap_angle(it->angle - dq_angle);
      const double c = std::cos(yaw), si = std::sin(yaw);
      const Vector2d mid_q = 0.5 * (qi + ql), mid_L = 0.5 * (Li + Ll);
      fn(Pose2(mid_L - Vector2d(c * mid_q.x() - si * mid_q.y(), si * mid_q.x() + c * mid_q.y()),
               yaw));
    }
  }
}

namespace {
// The cell of a pose in the exhaustive search, which keeps one pose a cell: 0.25 m x 3 degrees.
// Unsigned, from clamped floors: a map far from its origin wraps the key, never overflows it.
std::int64_t cell_of(const Pose2& p) {
  const double cell_m = 0.25, cell_rad = 3 * kDeg;
  return static_cast<std::int64_t>(
      detail::cell_key(detail::clamped_floor(p.x() / cell_m), detail::clamped_floor(p.y() / cell_m),
                       detail::clamped_floor((p.yaw() + M_PI) / cell_rad)));
}
std::string too_few_seeds(std::size_t n, const LampPairOptions& q) {
  return std::to_string(n) + " lamp(s) within " + std::to_string(int(q.pair_max_theta_deg)) +
         " degrees of the optical axis: a pose needs two";
}
}  // namespace

GlobalLocalization GlobalLocalizer::Impl::lamp_pairs(const vision::OmniDetection& d,
                                                     const LampPairOptions& q,
                                                     int max_hypotheses) const {
  GlobalLocalization out;
  out.method = GlobalMethod::lamp_pairs;
  const std::vector<BlobRay> blobs = blob_rays(d, q.max_theta_deg * kDeg);
  out.blobs = static_cast<int>(blobs.size());
  const Seeds seeds = seeds_of(blobs, q, std::size_t(q.pair_max_blobs), false);
  const std::size_t ns = seeds.size();
  if (ns < 2) {
    out.why = too_few_seeds(ns, q);
    return out;
  }
  // Vote: every pair of seeds matched to a pair of lamps at the same spacing is a pose. The
  // lamp pairs come from the index, looked up by spacing.
  PoseVotes votes;
  for (std::size_t j = 0; j < ns; ++j)
    for (std::size_t k = j + 1; k < ns; ++k)
      pair_poses(seeds, j, k, [&](const Pose2& p) { votes.add(p); });
  // The most voted places, best first; only the few that can be scored.
  const std::vector<PoseVotes::Place> voted = votes.best(8 * std::size_t(q.candidates));
  // The graph: a robot stands in a node's region.
  std::vector<std::pair<double, Pose2>> scored;
  std::size_t handled = 0;  // voted places scored or found outside the regions
  for (const PoseVotes::Place& place : voted) {
    if (int(scored.size()) >= q.candidates) break;
    ++handled;
    if (q.restrict_to_graph && has_regions && !node_of(place.pose)) continue;
    scored.emplace_back(
        evaluate(place.pose, {}, 0.3, 3 * kDeg, q.tilt_sigma_deg * kDeg, blobs).cost, place.pose);
  }
  // On a regular ceiling many places get the most votes alike (the lamps near the axis repeat);
  // when more of them reach the top votes than could be scored, the search did not see them all,
  // and says so.
  const bool truncated =
      !scored.empty() && votes.places_with_at_least(voted.front().votes, handled) > handled;
  out.merit_evaluations = static_cast<int>(scored.size());
  if (scored.empty()) {
    out.why = voted.empty() ? "no pair of map lamps is spaced like any pair of the " +
                                  std::to_string(ns) + " lamps seen"
                            : "every pose the lamps suggest lies outside the map's regions";
    return out;
  }
  std::stable_sort(scored.begin(), scored.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  if (scored.size() > std::size_t(q.refined)) scored.resize(q.refined);
  std::vector<PoseHypothesis> refined(scored.size());
  for_each_costly_index(scored.size(), serial_up_to(2), [&](std::size_t k) {
    refined[k] = refine(scored[k].second, 0.3, 3 * kDeg, blobs);
  });
  drop_outside_graph(refined);
  finish(out, refined, d, q, max_hypotheses, true);
  out.complete = !truncated && out.plausible < max_hypotheses;
  if (truncated && out.found()) {
    out.ambiguous = true;
    out.why = "more places look alike to the lamps near the optical axis than the " +
              std::to_string(scored.size()) +
              " scored (a regular ceiling): more images are needed to choose";
  }
  return out;
}

// Every pose that puts a map lamp under each of two blobs near the optical axis: the pair of
// blobs matched to every pair of map lamps spaced like them (both ways round), for the three
// pairs of the three blobs nearest the axis, so that one spurious or merged blob among them
// cannot hide the true pose. The other seeds must mostly land on lamps too (a cheap check
// through the map's spatial index) before a pose is scored; the plausible ones are refined.
GlobalLocalization GlobalLocalizer::Impl::exhaustive(const vision::OmniDetection& d, int cap,
                                                     double margin,
                                                     const EnumerationPrior* prior) const {
  const LampPairOptions& q = o.pairs;
  GlobalLocalization out;
  out.method = GlobalMethod::lamp_pairs;
  const std::vector<BlobRay> blobs = blob_rays(d, q.max_theta_deg * kDeg);
  out.blobs = static_cast<int>(blobs.size());
  const Seeds seeds = seeds_of(blobs, q, 6, true);
  const std::size_t ns = seeds.size(), nc = classes.size();
  out.seeds = static_cast<int>(ns);
  if (ns < 2) {
    out.why = too_few_seeds(ns, q);
    return out;
  }
  // Candidate poses, one per 0.25 m x 3 degree cell.
  std::unordered_map<std::int64_t, Pose2> cells;
  const std::size_t first = std::min<std::size_t>(3, ns);
  for (std::size_t j = 0; j < first; ++j)
    for (std::size_t k = j + 1; k < first; ++k)
      pair_poses(seeds, j, k, [&](const Pose2& p) { cells.emplace(cell_of(p), p); });
  const double screen = q.screen_max_theta_deg * kDeg;
  std::vector<BlobRay> near;
  for (const BlobRay& b : blobs)
    if (b.theta <= screen) near.push_back(b);
  // Near a place an earlier image allowed, in the graph, and the other seeds on lamps (all but
  // a minority of them, below).
  std::optional<PoseGrid> allowed;
  if (prior) {
    if (!prior->costs.empty() && prior->costs.size() != prior->poses.size())
      throw Error("enumerate: the prior has " + std::to_string(prior->costs.size()) +
                  " costs for " + std::to_string(prior->poses.size()) + " poses");
    allowed.emplace(prior->poses, prior->gate_m, prior->costs.empty() ? nullptr : &prior->costs);
  }
  std::vector<std::pair<std::int64_t, Pose2>> poses(cells.begin(), cells.end());
  std::sort(poses.begin(), poses.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  // Seeds off their lamps (merged with a neighbour, cut by the bloom of another) are let off,
  // up to a minority of them: one of three, two of five.
  const int allowed_misses = std::max<int>(1, (int(ns) - 1) / 2);
  // Each pose screened alone (on every core), kept in the order of its cell.
  std::vector<double> screened(poses.size(), 0.0), before(poses.size(), 0.0);
  std::vector<char> passed(poses.size(), 0);
  for_each_costly_index(poses.size(), serial_up_to(16), [&](std::size_t i) {
    const Pose2& pose = poses[i].second;
    if (allowed) {
      before[i] = allowed->least(pose, prior->gate_m, prior->gate_rad);
      if (!(before[i] < std::numeric_limits<double>::infinity())) return;
    }
    if (q.restrict_to_graph && has_regions && !node_of(pose)) return;
    int misses = 0;
    const double c = std::cos(pose.yaw()), s = std::sin(pose.yaw());
    for (std::size_t j = 0; j < ns && misses <= allowed_misses; ++j) {
      bool on_lamp = false, beyond = has_regions && !q.count_beyond_map;
      for (std::size_t cl = 0; cl < nc && !on_lamp; ++cl) {
        const double sg = seeds.sigma[j * nc + cl];
        if (sg < 0) continue;
        const Vector2d& b = seeds.at[j * nc + cl];
        const Vector2d w =
            pose.translation() + Vector2d(c * b.x() - s * b.y(), s * b.x() + c * b.y());
        const double r = 3 * sg + 0.3;
        on_lamp = lamp_of_class_within(w, r, int(cl));
        beyond = beyond && !on_lamp && map->node_near(w, r) == nullptr;
      }
      // A seed beyond every place of the map is a lamp the map cannot have: no miss.
      if (!on_lamp && !beyond) ++misses;
    }
    if (misses > allowed_misses) return;
    // Screened on the lamps the camera places well (screen_max_theta_deg): the seeds' and their
    // neighbours', a room or a side corridor beside the robot; the survivors scored in full.
    screened[i] = evaluate(pose, {}, 0.3, 3 * kDeg, q.tilt_sigma_deg * kDeg, near, screen).cost;
    passed[i] = 1;
  });
  struct Scored {
    double cost;  // screening, this image
    Pose2 pose;
    double drive;  // with a prior: the drive's cost so far, this image's included
  };
  std::vector<Scored> scored;
  for (std::size_t i = 0; i < poses.size(); ++i)
    if (passed[i]) scored.push_back({screened[i], poses[i].second, before[i]});
  out.merit_evaluations = static_cast<int>(scored.size());
  if (scored.empty()) {
    out.why = prior ? "no place the earlier images allowed has lamps where the " +
                          std::to_string(ns) + " lamps nearest the zenith are seen"
                    : "no place of the map has lamps where the " + std::to_string(ns) +
                          " lamps nearest the zenith are seen";
    return out;
  }
  std::stable_sort(scored.begin(), scored.end(),
                   [](const Scored& a, const Scored& b) { return a.cost < b.cost; });
  const double best = scored.front().cost;
  if (prior) {
    // The drive's evidence: a place's cost is its best carried predecessor's plus what this
    // image says (capped: one odd image never decides alone) less the allowance, never below
    // zero, relative to the likeliest.
    double least = std::numeric_limits<double>::infinity();
    for (Scored& c : scored) {
      c.drive = std::max(
          0.0, c.drive + std::min(prior->view_cost_cap, c.cost - best) - prior->view_allowance);
      least = std::min(least, c.drive);
    }
    for (Scored& c : scored) c.drive -= least;
    scored.erase(std::remove_if(scored.begin(), scored.end(),
                                [&](const Scored& c) { return c.drive > prior->cost_max; }),
                 scored.end());
  } else {
    for (Scored& c : scored) c.drive = c.cost - best;
  }
  // Refined: the screening scores within reach of the best (a coarse pose is up to a cell off,
  // and the screen sees only part of the view), at most four times the cap; then every refined
  // pose within `margin` of the best must fit under the cap for the search to be complete.
  const double reach = best + margin + 30.0;
  const std::size_t limit = 4 * std::size_t(cap);
  std::size_t in_reach = 0;
  while (in_reach < scored.size() && !(scored[in_reach].cost > reach)) ++in_reach;
  out.candidates.reserve(in_reach);
  out.candidate_costs.reserve(in_reach);
  for (std::size_t k = 0; k < in_reach; ++k) {
    out.candidates.push_back(scored[k].pose);
    out.candidate_costs.push_back(scored[k].drive);
  }
  // With two seeds, or more candidates in reach than the limit, the search cannot be complete:
  // its hypotheses are shown, not born as the set, and only the `cap` it returns are refined
  // (not four times as many, nor scored again with the floor's tilt, below). Those searches
  // were two thirds of the enumerations' time on the 100-node kidnaps (docs/hypotheses.md).
  const bool can_be_complete = ns >= 3 && in_reach <= limit;
  // A candidate's lamps are matched within its cell's reach: a coarse pose is up to a cell off.
  constexpr double cell_m = 0.3, cell_deg = 3.0;
  // One round each, at a level floor: enough to rank the candidates; the hypothesis set refines
  // in full.
  std::vector<PoseHypothesis> refined(
      std::min(in_reach, can_be_complete ? limit : std::size_t(cap)));
  for_each_costly_index(refined.size(), serial_up_to(2), [&](std::size_t k) {
    refined[k] = refine(scored[k].pose, cell_m, cell_deg * kDeg, blobs, 1, false);
  });
  // A floor bump tilts the camera alike whatever the pose, and a degree of it costs a level fit
  // of the true pose more than the birth margin on the wide view (33 against 7 with the tilt,
  // on a 1,000-node kidnap). When the best candidate, refined with the tilt, finds the floor
  // tilted, every candidate is scored again holding that tilt, so that they compare.
  Tilt tilt;
  if (can_be_complete && !refined.empty()) {
    std::size_t b = 0;
    for (std::size_t k = 1; k < refined.size(); ++k)
      if (refined[k].score < refined[b].score) b = k;
    refine(refined[b].pose, 0.1, 1 * kDeg, blobs, 3, true, {}, &tilt);
    if (tilt.roll != 0 || tilt.pitch != 0)
      for_each_costly_index(refined.size(), serial_up_to(2), [&](std::size_t k) {
        refined[k] = refine(scored[k].pose, cell_m, cell_deg * kDeg, blobs, 1, false, tilt);
      });
  }
  // A candidate whose refinement left the tolerance its matching assumed (its cell's) may
  // have matched some blob to another lamp than the truth's: refined again from it with a tight
  // tolerance, both kept (refine_moved_again), holding the floor's tilt the others were held at.
  if (q.refine_moved_again) {
    const std::size_t first_pass = refined.size();
    std::vector<std::size_t> moved;
    for (std::size_t k = 0; k < first_pass; ++k)
      if (distinct(refined[k].pose, scored[k].pose, cell_m, cell_deg)) moved.push_back(k);
    refined.resize(first_pass + moved.size());
    for_each_costly_index(moved.size(), serial_up_to(2), [&](std::size_t i) {
      refined[first_pass + i] = refine(scored[moved[i]].pose, 0.1, 1 * kDeg, blobs, 1, false, tilt);
    });
  }
  drop_outside_graph(refined);
  // The plausible ones (within the ambiguity margin of the best, 32 at most) refined in full,
  // with the floor's tilt: one of them may be published from this image alone.
  std::stable_sort(
      refined.begin(), refined.end(),
      [](const PoseHypothesis& a, const PoseHypothesis& b) { return a.score < b.score; });
  if (!refined.empty()) {
    // Which are plausible is judged on the one round all of them had: against the best's full
    // refinement, exact twins of it (a regular building's turned places, tied after one round)
    // were left at their one-round score, 35 behind, and one image made the first of them, by
    // the order of its cell, the only place (docs/hypotheses.md, "Twins left unrefined").
    const double one_round_best = refined.front().score;
    refined.front() = refine(refined.front().pose, 0.1, 1 * kDeg, blobs);
    std::size_t plausible = 1;
    while (plausible < refined.size() && plausible < 32 &&
           !(refined[plausible].score > one_round_best + q.ambiguity_margin))
      ++plausible;
    for_each_costly_index(plausible - 1, serial_up_to(1), [&](std::size_t k) {
      refined[k + 1] = refine(refined[k + 1].pose, 0.1, 1 * kDeg, blobs);
    });
  }
  // No paper merit: the hypothesis set weighs by score, and the merit's projection of the map
  // for each of up to 4 x cap hypotheses was a fifth of a kidnapped robot's time on 1,000 nodes.
  finish(out, refined, d, q, static_cast<int>(limit), false);
  std::size_t kept = 0;
  for (const auto& h : out.hypotheses)
    if (h.score <= out.hypotheses.front().score + margin) ++kept;
  // With two seeds, one blob off its lamp (merged with a neighbour, or cut) hides the true
  // place; with three, the pair of the other two still finds it.
  out.complete = out.found() && can_be_complete && kept <= std::size_t(cap);
  if (out.hypotheses.size() > std::size_t(cap)) out.hypotheses.resize(cap);
  if (!out.complete && out.found() && ns < 3)
    out.why = "two lamps near the zenith fit " + std::to_string(std::max(kept, in_reach)) +
              " poses, and one of them may be off its lamp: more images are needed";
  else if (!out.complete && out.found())
    out.why = std::to_string(std::max(kept, in_reach)) + " poses fit the lamps near the zenith" +
              (prior ? " and the drive so far" : "") + ", more than the " + std::to_string(cap) +
              " that can be followed: more images are needed";
  return out;
}

}  // namespace lampnav::fusion
