#include "lampnav/fusion/hypothesis_set.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "hypothesis_weighing.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/core/parallel.hpp"
#include "map_evidence.hpp"
#include "map_geometry.hpp"
#include "pose_grid.hpp"
#include "unmapped_rows.hpp"

namespace lampnav::fusion {

namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr double kNegInf = -std::numeric_limits<double>::infinity();
}  // namespace

struct HypothesisSet::Impl {
  const graph::TopologicalMap* map;
  HypothesisSetOptions o;
  const GlobalLocalizer* omni;
  detail::HypothesisWeigher weigher;  // what a frame says of one hypothesis
  bool has_regions = false;

  std::vector<Hypothesis> hs;  // best first after every frame
  bool complete = false;
  // The image that completed the set was searched alone (no places carried into it) and the map
  // explains all it shows: its set may publish from it (min_omni_frames does not apply).
  bool decided_by_one_image = false;
  int omni_frames = 0;  // omni frames that weighed the set since it became complete
  // The image that completed the set showed lamps beyond the map's places: the set publishes only
  // after partial_view_travel_m of travel since `completed_at`.
  bool view_beyond_map = false;
  Stamp completed_at;
  double travel_since_complete = 0;  // m, to the last frame that weighed the set
  int next_id = 1;
  double swing = 1.0;          // set_floor_swing, at least 1
  double publish_swing = 1.0;  // at least swing
  bool swing_measured = true;
  // The power the margins to publish are raised to (publish_follows_swing).
  double publish_power() const { return o.publish_follows_swing ? publish_swing : 1.0; }
  std::string last_why = "no omni image yet";
  Counts counts;
  std::optional<std::pair<Stamp, Pose2>> last_enumeration;  // capture, dead-reckoned pose
  // While incomplete: every coarse place the images so far allow, where the last image that
  // allowed it put it (carry_places).
  struct Place {
    Pose2 pose;
    double travel = 0;  // since an image last allowed it (m)
    double cost = 0;    // -2 ln L of the drive so far, relative to the likeliest place
  };
  std::vector<Place> places;
  std::pair<Stamp, Pose2> places_at;  // the capture every place stands at, dead-reckoned pose
  mutable std::map<std::pair<int, int>, bool> twin_cache;  // by hypothesis ids
  // The last row the map does not hold that an omni image showed beside one of the likeliest
  // hypotheses (unmapped_rows.hpp), kept until the robot has travelled row_beside_memory_m
  // since: no leader is published meanwhile.
  std::optional<UnmappedRow> row_beside;
  Stamp row_seen_at;

  // How many of the last unexplained_window ceiling frames showed `h` a lamp in full view where
  // it has no map lamp; whether that is publish_unexplained_frames or more.
  int unexplained_count(const Hypothesis& h) const {
    const std::uint32_t window =
        o.unexplained_window >= 32 ? ~0u : (1u << o.unexplained_window) - 1;
    return __builtin_popcount(h.unexplained_frames & window);
  }
  bool unexplained_lately(const Hypothesis& h) const {
    return o.publish_unexplained_frames > 0 && unexplained_count(h) >= o.publish_unexplained_frames;
  }

  void note_row_beside(Stamp stamp, const OdometryTrack& odo, bool omni_frame) {
    if (row_beside && stamp > row_seen_at &&
        odo.travel(row_seen_at, stamp) >= o.row_beside_memory_m)
      row_beside.reset();
    if (!omni_frame || hs.empty() || !(o.row_beside_m > 0)) return;
    detail::UnmappedRowOptions ro;
    ro.max_offset_m = o.row_beside_m;
    ro.min_lamps = o.row_beside_min_lamps;
    ro.reach_m = o.row_beside_reach_m;
    // Every place along the mapped row sees the row beside, the truth among them or not: the
    // likeliest few are asked, and the first that sees it speaks for the set.
    const std::size_t asked = std::min<std::size_t>(hs.size(), kRowBesideAsked);
    for (std::size_t k = 0; k < asked; ++k) {
      if (hs[k].contradicted) continue;  // its image fits it nowhere: its strays are its view
      if (auto row = detail::unmapped_row_beside(*map, hs[k].pose, hs[k].strays, ro)) {
        row_beside = row;
        row_seen_at = stamp;
        ++counts.unmapped_rows;
        return;
      }
    }
  }
  static constexpr std::size_t kRowBesideAsked = 8;

  // Whether the rigid motion taking pose a to pose b maps the map onto itself (map_geometry.hpp):
  // then the two places look alike from everywhere, whatever the robot does.
  bool twins(const Hypothesis& a, const Hypothesis& b) const {
    const auto key = std::minmax(a.id, b.id);
    if (const auto it = twin_cache.find(key); it != twin_cache.end()) return it->second;
    return twin_cache[key] = detail::maps_onto_itself(*map, b.pose * a.pose.inverse());
  }

  // Every hypothesis holding weight is a twin of the leader.
  bool all_twins() const {
    if (hs.size() < 2 || int(hs.size()) > o.symmetry_check_max) return false;
    for (std::size_t k = 1; k < hs.size(); ++k)
      if (!twins(hs.front(), hs[k])) return false;
    return true;
  }

  static HypothesisSetOptions validated(const HypothesisSetOptions& opt) {
    opt.validate();
    return opt;
  }

  Impl(const graph::TopologicalMap& m, const CameraDescription* ceiling_camera,
       const GlobalLocalizer* g, const CeilingPipelineOptions& co, const HypothesisSetOptions& opt)
      : map(&m), o(validated(opt)), omni(g), weigher(m, ceiling_camera, g, co, o) {
    for (const auto& n : m.nodes())
      if (n.region.size() >= 3) has_regions = true;
  }

  // Whether a pose stands in (or within the margin of) some node's region.
  bool inside(const Pose2& p) const {
    if (!has_regions) return true;
    return map->node_near(p.translation(), o.wall_margin_m) != nullptr;
  }

  Hypothesis carried(const Hypothesis& h, Stamp t, const OdometryTrack& odo) const {
    Hypothesis c = h;
    const Pose2 odo_t = odo.at(t);
    const Pose2 delta = h.odometry.between(odo_t);
    const double cy = std::cos(h.pose.yaw()), sy = std::sin(h.pose.yaw());
    const double dx = delta.x(), dy = delta.y();
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    F(0, 2) = -sy * dx - cy * dy;
    F(1, 2) = cy * dx - sy * dy;
    const double travel = odo.travel(h.stamp, t);
    const double sp = o.sigma_per_m * travel, syaw = o.sigma_yaw_deg_per_m * kDeg * travel;
    c.pose = h.pose * delta;
    c.covariance = F * h.covariance * F.transpose() +
                   Eigen::Vector3d(sp * sp, sp * sp, syaw * syaw).asDiagonal().toDenseMatrix();
    c.stamp = t;
    c.odometry = odo_t;
    return c;
  }

  // Carries every hypothesis to `stamp`, kills those that went through a wall, and weighs each
  // with `weigh`; the costs of one frame are taken relative to the best, less `tie`, and capped.
  // Returns whether the frame contradicted every hypothesis (never, for a frame that does not
  // judge that: the hypotheses then keep what the last frame that judged said of each). The
  // hypotheses are weighed on every core (each alone, so the result does not depend on how many): a
  // frame with a hundred of them is a few milliseconds of work.
  template <class Weigh>
  bool weigh_all(Stamp stamp, const OdometryTrack& odo, double cap, double tie, Weigh weigh) {
    std::vector<Hypothesis> next;
    next.reserve(hs.size());
    for (const Hypothesis& h : hs) {
      Hypothesis c = carried(h, stamp, odo);
      if (!inside(c.pose)) {
        ++counts.through_walls;
        continue;
      }
      next.push_back(std::move(c));
    }
    std::vector<detail::Weighed> weighed(next.size());
    // Three or fewer stay on this thread: starting one costs about what weighing one does.
    // `next` is in the order of `hs`, likeliest first (tidy()): weigh() is told each one's rank.
    for_each_costly_index(next.size(), o.weigh_in_parallel ? 3 : next.size(),
                          [&](std::size_t k) { weighed[k] = weigh(next[k], k); });
    bool all_contradicted = true;
    double best = std::numeric_limits<double>::infinity();
    for (const detail::Weighed& w : weighed) {
      all_contradicted = all_contradicted && w.contradicted.value_or(false);
      best = std::min(best, w.cost);
    }
    for (std::size_t k = 0; k < next.size(); ++k) {
      next[k].last_cost = weighed[k].cost;
      if (weighed[k].contradicted) next[k].contradicted = *weighed[k].contradicted;
      next[k].log_weight -= 0.5 * std::min(cap, std::max(0.0, weighed[k].cost - best - tie));
      next[k].node = map->node_containing(next[k].pose.translation());
    }
    hs = std::move(next);
    return all_contradicted && !hs.empty();
  }

  // Merges near-duplicates (the likelier stays, their weights add), drops the unlikely, sorts
  // best first and normalizes.
  void tidy() {
    std::stable_sort(hs.begin(), hs.end(), [](const Hypothesis& a, const Hypothesis& b) {
      return a.log_weight > b.log_weight;
    });
    std::vector<Hypothesis> kept;
    for (Hypothesis& h : hs) {
      bool merged = false;
      for (Hypothesis& k : kept)
        if ((h.pose.translation() - k.pose.translation()).norm() < o.merge_m &&
            std::abs(wrap_angle(h.pose.yaw() - k.pose.yaw())) < o.merge_deg * kDeg) {
          const double m = std::max(k.log_weight, h.log_weight);
          k.log_weight = m + std::log(std::exp(k.log_weight - m) + std::exp(h.log_weight - m));
          if (h.origin == HypothesisOrigin::kept) k.origin = HypothesisOrigin::kept;
          ++counts.merged;
          merged = true;
          break;
        }
      if (!merged) kept.push_back(std::move(h));
    }
    hs = std::move(kept);
    if (hs.empty()) return;
    const double floor = hs.front().log_weight + std::log(o.drop_ratio);
    const std::size_t before = hs.size();
    hs.erase(std::remove_if(hs.begin(), hs.end(),
                            [&](const Hypothesis& h) { return !(h.log_weight >= floor); }),
             hs.end());
    if (int(hs.size()) > o.max_hypotheses) hs.resize(o.max_hypotheses);
    counts.dropped += before - hs.size();
    // Normalized so that the best is 0 (no drift to -inf over a long ambiguity).
    const double top = hs.front().log_weight;
    double total = 0;
    for (Hypothesis& h : hs) {
      h.log_weight -= top;
      total += std::exp(h.log_weight);
    }
    for (Hypothesis& h : hs) h.weight = std::exp(h.log_weight) / total;
  }

  Hypothesis born(const PoseHypothesis& p, Stamp stamp, const OdometryTrack& odo,
                  double log_weight) {
    Hypothesis h;
    h.id = next_id++;
    h.origin = HypothesisOrigin::omni;
    h.stamp = stamp;
    h.pose = p.pose;
    // One image's least squares knows its noise, not the floor's bumps nor its own aliasing: a
    // newborn is held loosely until the next frames have refined it.
    h.covariance = p.covariance;
    const double grow = o.births_follow_swing ? swing : 1.0;
    const double m = o.birth_sigma_m * grow, deg = o.birth_sigma_deg * grow;
    h.covariance.diagonal() += Eigen::Vector3d(m * m, m * m, std::pow(deg * kDeg, 2));
    h.odometry = odo.at(stamp);
    h.log_weight = log_weight;
    h.node = p.node;
    // What the image said (births() weighs the newborn with it bounded alike).
    weigher.charge_image(h, p.missed, p.unexplained, p.strays, p.lamp_costs);
    ++counts.born;
    return h;
  }

  bool same_station = false;  // carry_places: this image was taken where the last one was
  // The places carried to `stamp` (those gone through a wall left behind), and the gate an
  // image's poses must fall within to be one of them.
  EnumerationPrior carry_places(Stamp stamp, const OdometryTrack& odo) {
    EnumerationPrior prior;
    std::vector<Place> kept;
    double travel = 0;
    const Pose2 at = odo.at(stamp);
    const Pose2 moved = places_at.second.between(at);
    const double step = places.empty() ? 0.0 : odo.travel(places_at.first, stamp);
    places_at = {stamp, at};
    for (Place p : places) {
      p.travel += step;
      p.pose = p.pose * moved;
      if (!inside(p.pose)) continue;
      travel = std::max(travel, p.travel);
      prior.poses.push_back(p.pose);
      prior.costs.push_back(p.cost);
      kept.push_back(p);
    }
    places = std::move(kept);
    prior.gate_m = o.place_gate_m + 3 * o.sigma_per_m * travel;
    prior.gate_rad = (o.place_gate_deg + 3 * o.sigma_yaw_deg_per_m * travel) * kDeg;
    // An image from where the last one was taken (a turn on the spot: the omni camera sees the
    // same ceiling turned) says again what that one said: it narrows the places, it adds no cost.
    same_station = !places.empty() && moved.translation().norm() < o.station_m;
    prior.view_cost_cap = same_station ? 0.0 : o.frame_cost_cap;
    prior.cost_max = o.place_cost_max;
    prior.view_allowance = same_station ? 0.0 : o.place_allowance;
    return prior;
  }

  // After an image's enumeration: its places, and the carried ones it did not allow at all,
  // at the cost of one image's cap, while the drive still allows them. Returns the latter.
  std::vector<Place> update_places(const GlobalLocalization& r, const EnumerationPrior* prior,
                                   Stamp stamp, const OdometryTrack& odo) {
    std::vector<Place> next, missed;
    places_at = {stamp, odo.at(stamp)};  // the carried ones stand there already
    for (std::size_t k = 0; k < r.candidates.size(); ++k)
      next.push_back({r.candidates[k], 0.0,
                      prior ? r.candidate_costs[k]
                            : std::max(0.0, std::min(o.frame_cost_cap, r.candidate_costs[k]) -
                                                o.place_allowance)});
    if (prior) {
      const detail::PoseGrid allowed(r.candidates, prior->gate_m);
      // An image with two lamps near the zenith may miss the true place (one of them off its
      // lamp): it says nothing of the places it did not allow.
      const bool says = r.seeds >= 3;
      for (Place p : places) {
        if (allowed.near(p.pose, prior->gate_m, prior->gate_rad)) continue;
        if (says) {
          if (!same_station) p.cost += o.frame_cost_cap - o.place_allowance;
          if (p.cost > o.place_cost_max) continue;
          missed.push_back(p);
        }
        next.push_back(p);
      }
    }
    places = std::move(next);
    return missed;
  }

  // Whether a place's blobs no lamp explains include one beyond every place of the map: the
  // image shows what the map lacks.
  bool beyond_map(const PoseHypothesis& h) const {
    return std::any_of(h.strays.begin(), h.strays.end(),
                       [&](const StraySighting& b) { return weigher.beyond_places(b); });
  }

  // Births from one image's enumeration. A complete one starts the set again from every place
  // it found, weighed by the image and by what the drive said of the place before it (the kept
  // estimate, if still alive, keeps its prior share and what this image said of it, capped); an
  // incomplete one shows the places found, weighed alike, beside the kept estimate (omni()
  // removed the previous image's). While incomplete, each enumeration considers only the places
  // the images before it allowed.
  void births(Stamp stamp, const vision::OmniDetection& d, const OdometryTrack& odo) {
    last_enumeration = {stamp, odo.at(stamp)};
    ++counts.enumerations;
    const double margin = -2 * std::log(o.birth_ratio);
    const EnumerationPrior prior = o.carry_places ? carry_places(stamp, odo) : EnumerationPrior{};
    const bool with_prior = !prior.poses.empty();
    bool r_with_prior = with_prior;  // r was enumerated within the carried places
    GlobalLocalization r =
        omni->enumerate(d, o.max_hypotheses, margin, with_prior ? &prior : nullptr);
    // The places the drive allowed are stale when this image alone puts the robot somewhere it
    // explains far better than at any of them (carried away while lost: the wheels did not see
    // it): start again from this image. Scores are never negative, so when the drive's best place
    // scores within stale_places_cost no place can beat it by that much: no second search.
    if (with_prior && r.found() && r.hypotheses.front().score > o.stale_places_cost) {
      GlobalLocalization alone = omni->enumerate(d, o.max_hypotheses, margin);
      if (alone.found() &&
          alone.hypotheses.front().score + o.stale_places_cost < r.hypotheses.front().score) {
        ++counts.stale_places;
        places.clear();
        r = std::move(alone);
        r_with_prior = false;
      }
    }
    std::vector<Place> missed;
    if (o.carry_places && (r.found() || r.seeds >= 2)) {
      missed = update_places(r, r_with_prior ? &prior : nullptr, stamp, odo);
      if (r_with_prior && places.empty()) {
        // Every place the drive allowed is gone (this image allowed none of them, and what it
        // cost them dropped the rest): the places were lost, or the robot carried away again.
        // Start again from this image alone.
        ++counts.place_restarts;
        r = omni->enumerate(d, o.max_hypotheses, margin);
        r_with_prior = false;
        missed = update_places(r, nullptr, stamp, odo);
      }
    }
    if (!r.found()) {
      last_why = r.why;
      return;
    }
    // Every hypothesis within the birth ratio: the runners-up make the likelihood ratio.
    const double best_score = r.hypotheses.front().score;
    std::size_t n = 0;
    while (n < r.hypotheses.size() && r.hypotheses[n].score <= best_score + margin) ++n;
    // Weighed with each lamp the image missed costing at most lamp_out_cost, each blob no lamp
    // explains at most unmapped_lamp_cost, the far ones as the far account charges them.
    const auto capped = [&](const PoseHypothesis& h) {
      const auto& q = omni->options().pairs;
      const auto strays = weigher.count_strays(h.strays);  // each stray asks the map once
      const double far = weigher.far_cost(h.unexplained, strays.spots);
      double spent = 0;
      return detail::with_each_bounded(
                 detail::with_each_bounded(h.score, h.missing, q.miss_cost, o.lamp_out_cost),
                 strays.spots, q.spurious_cost, o.unmapped_lamp_cost) -
             far + weigher.far_charge(spent, far, strays.beyond);
    };
    double capped_best = capped(r.hypotheses.front());
    std::size_t best = 0;
    for (std::size_t k = 1; k < n; ++k)
      if (const double c = capped(r.hypotheses[k]); c < capped_best) {
        capped_best = c;
        best = k;
      }
    // An image whose best place's lamps misfit past odd_image_misfit weighs its newborns as any
    // frame does: the likeliest then leads the next by at most frame_cost_cap, short of
    // publish_ratio. Nor does it complete the set: the truth may not even be among its places
    // (born only within birth_ratio of a best that fits nowhere well), and a complete set never
    // takes a place in again.
    const PoseHypothesis& likeliest = r.hypotheses[best];
    const bool odd =
        weigher.odd(likeliest.score, likeliest.expected, likeliest.missing, likeliest.unexplained);
    const double image_cap = odd ? o.frame_cost_cap : std::numeric_limits<double>::infinity();
    // What the drive said before this image: each hypothesis is born with the cost of the
    // carried place it continues (the least within the gate), so that the places the drive has
    // told apart from the truth are born behind it, not level with it.
    std::optional<detail::PoseGrid> drive;
    if (r_with_prior) drive.emplace(prior.poses, prior.gate_m, &prior.costs);
    const auto drive_cost = [&](const Pose2& p) {
      if (!drive) return 0.0;
      return std::min(drive->least(p, prior.gate_m, prior.gate_rad), o.place_cost_max);
    };
    const auto cost_of = [&](const PoseHypothesis& h) {
      return std::min(image_cap, capped(h) - capped_best) + drive_cost(h.pose);
    };
    // A place of the drive this image did not allow still counts while its cost stays within
    // place_cost_max (one odd image, a lamp hidden, never removes the truth): it is born too,
    // at its cost, and the frames that follow weigh it like the others.
    if (r.complete && !odd && n + missed.size() <= std::size_t(o.max_hypotheses)) {
      ++counts.complete_enumerations;
      std::vector<Hypothesis> next;
      double kept_share = 0;
      for (const Hypothesis& h : hs)
        if (h.origin == HypothesisOrigin::kept) {
          next.push_back(h);
          next.back().log_weight =
              std::log(o.kept_prior) - 0.5 * std::min(o.frame_cost_cap, h.last_cost - capped_best);
          kept_share = o.kept_prior;
        }
      const double each = std::log((1 - kept_share) /
                                   double(std::max<std::size_t>(1, r.plausible + missed.size())));
      for (std::size_t k = 0; k < n; ++k)
        next.push_back(born(r.hypotheses[k], stamp, odo, each - 0.5 * cost_of(r.hypotheses[k])));
      for (const Place& p : missed) {
        PoseHypothesis coarse;
        coarse.pose = p.pose;
        coarse.covariance =
            Eigen::Vector3d(std::pow(prior.gate_m / 2, 2), std::pow(prior.gate_m / 2, 2),
                            std::pow(prior.gate_rad / 2, 2))
                .asDiagonal();
        coarse.node = map->node_containing(p.pose.translation());
        next.push_back(born(coarse, stamp, odo, each - 0.5 * p.cost));
      }
      hs = std::move(next);
      complete = true;
      places.clear();
      last_enumeration.reset();
      omni_frames = 1;  // this image weighed them
      view_beyond_map = beyond_map(r.hypotheses.front());
      decided_by_one_image = !r_with_prior && !view_beyond_map;
      completed_at = stamp;
      travel_since_complete = 0;
      last_why.clear();
      return;
    }
    if (r.complete && odd)
      last_why = "the image's lamps fit no place well: its places may not hold the robot";
    else
      last_why = r.why.empty() ? "the image fits more places than were enumerated" : r.why;
    for (std::size_t k = 0; k < n; ++k)
      hs.push_back(born(r.hypotheses[k], stamp, odo, -0.5 * cost_of(r.hypotheses[k])));
  }

  // Whether an incomplete set should enumerate this image: the first after a loss, then once the
  // robot has moved on enough for the view to fit other places.
  bool enumeration_due(Stamp stamp, const OdometryTrack& odo) const {
    if (!last_enumeration || hs.empty()) return true;
    const Pose2 moved = last_enumeration->second.between(odo.at(stamp));
    return odo.travel(last_enumeration->first, stamp) >= o.enumerate_every_m ||
           std::abs(moved.yaw()) >= o.enumerate_every_deg * kDeg;
  }

  int frames_to_publish() const { return decided_by_one_image ? 1 : o.min_omni_frames; }
  // Metres the robot must still travel before the set may publish.
  double travel_to_publish() const {
    return view_beyond_map ? std::max(0.0, o.partial_view_travel_m - travel_since_complete) : 0.0;
  }
  void note_travel(Stamp stamp, const OdometryTrack& odo) {
    if (complete && stamp > completed_at) travel_since_complete = odo.travel(completed_at, stamp);
  }

  void reset(const std::string& why) {
    ++counts.resets;
    last_enumeration.reset();
    places.clear();
    hs.clear();
    complete = false;
    omni_frames = 0;
    view_beyond_map = false;
    last_why = why;
  }
};

void Hypothesis::keep_strays(const std::vector<StraySighting>& latest, int images) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < strays.size(); ++k) {
    if (stray_age[k] + 1 >= images) continue;
    strays[kept] = strays[k];
    stray_age[kept++] = stray_age[k] + 1;
  }
  strays.resize(kept);
  stray_age.resize(kept);
  strays.insert(strays.end(), latest.begin(), latest.end());
  stray_age.resize(strays.size(), 0);
}

HypothesisSet::HypothesisSet(const graph::TopologicalMap& map,
                             const CameraDescription* ceiling_camera, const GlobalLocalizer* omni,
                             const CeilingPipelineOptions& ceiling_options,
                             const HypothesisSetOptions& options)
    : impl_(std::make_unique<Impl>(map, ceiling_camera, omni, ceiling_options, options)) {}
HypothesisSet::~HypothesisSet() = default;
HypothesisSet::HypothesisSet(HypothesisSet&&) noexcept = default;

void HypothesisSet::set_floor_swing(double factor, double publish_factor, bool measured) {
  impl_->swing = std::max(1.0, factor);
  impl_->publish_swing = std::max(impl_->swing, publish_factor);
  impl_->swing_measured = measured;
}

void HypothesisSet::clear(const std::string& why) {
  Impl& m = *impl_;
  m.hs.clear();
  m.complete = false;
  m.omni_frames = 0;
  m.view_beyond_map = false;
  m.row_beside.reset();
  m.twin_cache.clear();
  m.last_enumeration.reset();
  m.places.clear();
  m.last_why = why;
}

void HypothesisSet::keep(Stamp stamp, const Pose2& pose, const Eigen::Matrix3d& covariance,
                         const OdometryTrack& odometry) {
  Impl& m = *impl_;
  clear();
  Hypothesis h;
  h.id = m.next_id++;
  h.origin = HypothesisOrigin::kept;
  h.ceiling_fitted = true;
  h.stamp = stamp;
  h.pose = pose;
  h.covariance = covariance;
  h.odometry = odometry.at(stamp);
  h.log_weight = std::log(m.o.kept_prior);
  h.weight = 1;
  h.node = m.map->node_containing(pose.translation());
  m.hs.push_back(h);
  m.last_why =
      "the kidnap alarm fired: the tracked pose is one hypothesis among those the "
      "omni camera will find";
}

void HypothesisSet::omni(Stamp stamp, const vision::OmniDetection& d,
                         const OdometryTrack& odometry) {
  Impl& m = *impl_;
  if (!m.omni) return;
  // While the places are not all known nothing can be published, so only the kept estimate is
  // weighed; the others are born again from this image, when the robot has moved on enough.
  if (!m.complete && !m.enumeration_due(stamp, odometry)) return;
  if (!m.complete)
    m.hs.erase(
        std::remove_if(m.hs.begin(), m.hs.end(),
                       [](const Hypothesis& h) { return h.origin != HypothesisOrigin::kept; }),
        m.hs.end());
  if (!m.hs.empty()) {
    const bool all_contradicted = m.weigh_all(
        stamp, odometry, m.o.frame_cost_cap, m.o.omni_tie_cost,
        [&](Hypothesis& h, std::size_t rank) {
          return m.weigher.omni(h, d, rank < std::size_t(m.o.odd_image_search_hypotheses));
        });
    if (m.complete) ++m.omni_frames;
    m.note_travel(stamp, odometry);
    m.tidy();
    // Every hypothesis contradicted: the robot is none of them (carried away again, or the set
    // lost it). Starting again costs what was learnt, never the pose.
    if (m.complete && (m.hs.empty() || all_contradicted))
      m.reset(m.hs.empty() ? "every hypothesis went through a wall"
                           : "the omni view contradicts every hypothesis");
  }
  if (!m.complete) {
    m.births(stamp, d, odometry);
    m.tidy();
  }
  m.note_row_beside(stamp, odometry, true);
}

void HypothesisSet::ceiling(Stamp stamp, const std::vector<vision::LampDetection>& lamps,
                            const OdometryTrack& odometry) {
  Impl& m = *impl_;
  // Until the places are all known the omni frames do the weighing (see omni()).
  if (!m.weigher.weighs_ceiling() || m.hs.empty() || !m.complete) return;
  m.weigh_all(stamp, odometry, m.o.ceiling_cost_cap, 0.0,
              [&](Hypothesis& h, std::size_t) { return m.weigher.ceiling(h, lamps); });
  m.note_travel(stamp, odometry);
  m.tidy();
  if (m.complete && m.hs.empty()) m.reset("every hypothesis went through a wall");
  m.note_row_beside(stamp, odometry, false);
}

const std::vector<Hypothesis>& HypothesisSet::hypotheses() const { return impl_->hs; }
bool HypothesisSet::complete() const { return impl_->complete; }

const Hypothesis* HypothesisSet::winner() const {
  const Impl& m = *impl_;
  if (!m.complete || m.hs.empty() || m.omni_frames < m.frames_to_publish() ||
      m.travel_to_publish() > 0)
    return nullptr;
  const Hypothesis& best = m.hs.front();
  const double s = m.publish_power();
  if (std::log1p(-best.weight) > s * std::log1p(-m.o.publish_posterior) || best.contradicted ||
      m.row_beside || m.unexplained_lately(best))
    return nullptr;
  if (m.hs.size() > 1 && m.hs[0].log_weight - m.hs[1].log_weight < s * std::log(m.o.publish_ratio))
    return nullptr;
  return &best;
}

HypothesisVerdict HypothesisSet::verdict() const {
  const Impl& m = *impl_;
  if (m.hs.empty()) return HypothesisVerdict::empty;
  if (!m.complete) return HypothesisVerdict::incomplete;
  if (winner()) return HypothesisVerdict::decided;
  return m.all_twins() ? HypothesisVerdict::symmetric : HypothesisVerdict::ambiguous;
}

std::string HypothesisSet::why() const {
  const Impl& m = *impl_;
  std::ostringstream s;
  switch (verdict()) {
    case HypothesisVerdict::empty:
      return m.last_why.empty() ? "no hypothesis" : m.last_why;
    case HypothesisVerdict::incomplete:
      s << m.hs.size() << " hypotheses so far, but " << m.last_why;
      return s.str();
    case HypothesisVerdict::ambiguous:
      s << m.hs.size() << " places explain what the cameras saw (best " << m.hs.front().weight
        << (m.hs.front().node ? " in " + m.hs.front().node->name : std::string()) << ")";
      if (const int more = m.frames_to_publish() - m.omni_frames; more > 0)
        s << ", waiting for " << more << " more omni frame" << (more > 1 ? "s" : "");
      if (const double more = m.travel_to_publish(); more > 0) {
        char metres[32];
        std::snprintf(metres, sizeof metres, "%.1f", more);
        s << ", waiting for " << metres
          << " m more of travel: the view shows lamps beyond the map's places, so the robot may "
             "be where the map has nothing";
      }
      // Said when the margins raised for the floor's swing are what keeps the leader back.
      if (const double gap = m.hs.size() > 1 ? m.hs[0].log_weight - m.hs[1].log_weight : 0;
          gap >= std::log(m.o.publish_ratio) &&
          gap < m.publish_power() * std::log(m.o.publish_ratio)) {
        char text[200];
        std::snprintf(text, sizeof text,
                      ", the likeliest e^%.1f times the next where %s (%s%.1f times the models') "
                      "asks for e^%.1f",
                      gap, m.swing_measured ? "the floor's swing" : "a floor not measured yet",
                      m.swing_measured ? "" : "its swing up to ", m.publish_swing,
                      m.publish_power() * std::log(m.o.publish_ratio));
        s << text;
      }
      if (m.unexplained_lately(m.hs.front()))
        s << ", and from the likeliest the ceiling camera saw lamps where the map has none in "
          << m.unexplained_count(m.hs.front()) << " of its last " << m.o.unexplained_window
          << " frames";
      if (const auto& row = m.row_beside) {
        char text[160];
        std::snprintf(text, sizeof text,
                      ", and the omni camera sees a row of %d lamps %.1f m beside the mapped row "
                      "that the map does not hold: the robot may be under that row",
                      row->lamps, row->offset_m);
        s << text;
      }
      return s.str();
    case HypothesisVerdict::symmetric:
      s << "the building looks the same from " << m.hs.size() << " places (";
      for (std::size_t k = 0; k < m.hs.size(); ++k)
        s << (k ? ", " : "") << (m.hs[k].node ? m.hs[k].node->name : std::string("?"));
      s << "): every lamp maps onto a lamp alike, so no motion can tell them apart";
      return s.str();
    case HypothesisVerdict::decided:
      return "one place holds the evidence";
  }
  return {};
}

Hypothesis HypothesisSet::carried(const Hypothesis& h, Stamp t,
                                  const OdometryTrack& odometry) const {
  return impl_->carried(h, t, odometry);
}

const HypothesisSet::Counts& HypothesisSet::counts() const { return impl_->counts; }
const HypothesisSetOptions& HypothesisSet::options() const { return impl_->o; }

}  // namespace lampnav::fusion
