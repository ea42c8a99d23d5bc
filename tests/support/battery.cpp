#include "battery.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "lampnav/graph/planner.hpp"
#include "lampnav/sim/map_oracle.hpp"

namespace lampnav::test {

namespace {

using Eigen::Vector2d;
constexpr double kDeg = M_PI / 180.0;

// Where a person at the joystick goes: along the corridor the robot stands in, towards the end
// it faces, then by the planned route to a junction drawn at random, and so on.
class Driver {
 public:
  Driver(const graph::TopologicalMap& map, std::mt19937_64& rng) : map_(&map), rng_(&rng) {
    for (const auto& n : map.nodes())
      if (n.place == graph::Place::junction || n.place == graph::Place::corner ||
          n.place == graph::Place::end)
        goals_.push_back(&n);
  }

  void plan_from(const Pose2& pose) {
    waypoints_.clear();
    const graph::Node* here = map_->node_containing(pose.translation());
    last_ = here;
    if (!here || !here->axis) return;
    Vector2d dir = here->axis->direction();
    const Vector2d heading(std::cos(pose.yaw()), std::sin(pose.yaw()));
    const bool forward = dir.dot(heading) >= 0;
    const Vector2d end = forward ? here->axis->second : here->axis->first;
    waypoints_.push_back(end);
    // The node beyond that end.
    const graph::Node* next = nullptr;
    double best = 1e18;
    for (const graph::Edge* e : map_->out_edges(here->id)) {
      const graph::Node& n = map_->node(e->end);
      const double d = (n.point - end).norm();
      if (d < best) {
        best = d;
        next = &n;
      }
    }
    if (next) {
      waypoints_.push_back(next->point);
      last_ = next;
    }
  }

  // Body speeds (m/s, rad/s) towards the next waypoint: turn on the spot when far off the
  // bearing, else drive with a proportional correction.
  std::pair<double, double> command(const Pose2& pose, double speed) {
    while (!waypoints_.empty() && (waypoints_.front() - pose.translation()).norm() < 0.25)
      waypoints_.pop_front();
    if (waypoints_.empty()) extend();
    if (waypoints_.empty()) return {0.0, 0.6};
    const Vector2d d = waypoints_.front() - pose.translation();
    const double e = wrap_angle(std::atan2(d.y(), d.x()) - pose.yaw());
    if (std::abs(e) > 0.35) return {0.0, e > 0 ? 0.8 : -0.8};
    return {speed, std::clamp(2.0 * e, -0.8, 0.8)};
  }

 private:
  void extend() {
    if (!last_ || goals_.empty()) return;
    for (int tries = 0; tries < 8; ++tries) {
      const graph::Node* goal = goals_[(*rng_)() % goals_.size()];
      if (goal == last_) continue;
      const auto route = graph::plan_route(*map_, last_->id, goal->id);
      if (!route) continue;
      const auto pts = graph::route_waypoints(*map_, *route);
      for (std::size_t k = 1; k < pts.size(); ++k) waypoints_.push_back(pts[k]);
      last_ = goal;
      return;
    }
  }

  const graph::TopologicalMap* map_;
  std::mt19937_64* rng_;
  std::vector<const graph::Node*> goals_;
  std::deque<Vector2d> waypoints_;
  const graph::Node* last_ = nullptr;
};

}  // namespace

struct Battery::Impl {
  const graph::TopologicalMap* map;
  RobotDescription robot;
  BatteryOptions o;
  fusion::LocalizerOptions lo;
  sim::LampSensors sensors;
  std::optional<sim::MapOracle> oracle;
  std::vector<const graph::Node*> corridors;

  Impl(const graph::TopologicalMap& m, const RobotDescription& r, const BatteryOptions& opt,
       const fusion::LocalizerOptions& l)
      : map(&m), robot(r), o(opt), lo(l), sensors(opt.world ? *opt.world : m, r, opt.sensors) {
    for (const auto& n : m.nodes())
      if (n.place == graph::Place::corridor && n.axis) corridors.push_back(&n);
    sim::MapOracleOptions oo;
    if (o.oracle && sensors.omni_resolving_radius_m(oo.tolerance_m) > oo.border_m) {
      oo.view_radius_m = sensors.omni_resolving_radius_m(oo.tolerance_m);
      oo.failed_lamps = o.sensors.failed_lamps;
      oracle.emplace(m, oo);
    }
  }

  // Anywhere along a corridor (not within 0.5 m of its ends), at any heading.
  Pose2 random_place(std::mt19937_64& rng) const {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const graph::Node& n = *corridors[rng() % corridors.size()];
    const double len = n.axis->length();
    const Vector2d p = n.axis->point_at(0.5 + u(rng) * std::max(0.0, len - 1.0));
    return {p, wrap_angle(2 * M_PI * u(rng))};
  }

  // Drives from `start` and scores. With `kidnap_at_m` the localizer starts tracking at the truth
  // and the robot is put down elsewhere after that much travel; without, it is never told.
  EpisodeResult run(Pose2 truth, std::optional<double> kidnap_at_m, std::uint64_t seed) {
    std::mt19937_64 rng(seed * 7919 + 17);
    std::normal_distribution<double> n01(0.0, 1.0);
    const double scale_l = 1 + o.odometry_scale_sigma * n01(rng);
    const double scale_r = 1 + o.odometry_scale_sigma * n01(rng);
    fusion::Localizer loc(*map, robot, lo);
    Driver driver(*map, rng);
    driver.plan_from(truth);
    EpisodeResult r;
    const double dt = 0.02, b = robot.semi_axis;
    double left = 0, right = 0, travel = 0, t = 0;
    double next_ceiling = 0.013, next_omni = 0.021;
    struct Pending {
      double at;
      double capture;
      bool ceiling;
      std::vector<vision::LampDetection> lamps;
      vision::OmniDetection omni;
    };
    std::deque<Pending> pending;  // in arrival order (each camera's delay is fixed)
    auto stamp = [](double s) { return Stamp(std::chrono::nanoseconds(std::llround(s * 1e9))); };
    if (kidnap_at_m)
      loc.initialize(stamp(0), truth, Eigen::Vector3d(1e-4, 1e-4, 3e-4).asDiagonal());
    std::optional<double> kidnapped_at, kidnap_travel, detected_at, fixed_at;
    bool wrong = false;
    std::vector<sim::DriveSample> drive;  // from the kidnap (or start) on, every 0.25 m
    while (true) {
      // Truth and wheels.
      const auto [v, w] = driver.command(truth, o.speed);
      truth = truth * Pose2(v * dt, 0.0, w * dt);
      const double dl = (v - w * b) * dt, dr = (v + w * b) * dt;
      const double nl = o.odometry_noise * std::sqrt(std::abs(dl)) * n01(rng);
      const double nr = o.odometry_noise * std::sqrt(std::abs(dr)) * n01(rng);
      left += dl * scale_l + nl;
      right += dr * scale_r + nr;
      travel += 0.5 * (std::abs(dl) + std::abs(dr));
      t += dt;
      if (kidnap_at_m && !kidnapped_at && travel >= *kidnap_at_m) {
        truth = random_place(rng);
        driver.plan_from(truth);
        kidnapped_at = t;
        kidnap_travel = travel;
      }
      loc.wheels(stamp(t), left, right);
      // Frames captured now, delivered after their delay.
      if (t >= next_ceiling && o.ceiling_rate > 0) {
        next_ceiling += 1.0 / o.ceiling_rate;
        pending.push_back({t + o.ceiling_delay_s, t, true, sensors.ceiling(truth, rng), {}});
      }
      if (t >= next_omni && o.omni_rate > 0) {
        next_omni += 1.0 / o.omni_rate;
        pending.push_back({t + o.omni_delay_s, t, false, {}, sensors.omni(truth, rng)});
      }
      std::stable_sort(pending.begin(), pending.end(),
                       [](const Pending& a, const Pending& c) { return a.at < c.at; });
      while (!pending.empty() && pending.front().at <= t) {
        const Pending& p = pending.front();
        const bool was_unsure = !fusion::is_certain(loc.mode());
        const std::size_t live = loc.hypotheses().hypotheses().size();
        const auto t0 = std::chrono::steady_clock::now();
        if (p.ceiling)
          loc.ceiling_detections(stamp(p.capture), p.lamps);
        else
          loc.omni_detection(stamp(p.capture), p.omni);
        loc.audit();  // as the node does, once the frame's pose is out
        const double took =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        r.localizer_s += took;
        if (was_unsure) {
          r.unsure_s += took;
          ++r.unsure_frames;
          r.unsure_hypotheses += live;
          if (live >= 50 && live <= 200) {
            r.many_s += took;
            ++r.many_frames;
            r.many_hypotheses += live;
          }
        }
        if (o.trace) o.trace(t, truth, loc);
        ++r.frames;
        pending.pop_front();
      }
      if ((!kidnap_at_m || kidnapped_at) && o.oracle) {
        const double since_m = travel - kidnap_travel.value_or(0.0);
        if (drive.empty() || since_m - drive.back().travel_m >= 0.25)
          drive.push_back({since_m, truth});
      }
      // Score what it publishes now.
      const fusion::LocalizerEstimate e = loc.estimate();
      const bool after = !kidnap_at_m || kidnapped_at;
      // Noticed: the mode left tracking (lost, ambiguous, or a fix straight from the image that
      // showed the loss).
      if (after && !detected_at && kidnap_at_m && e.mode != fusion::LocalizerMode::tracking)
        detected_at = t;
      if (after) {
        r.max_hypotheses = std::max(r.max_hypotheses, e.hypotheses.size());
        if (e.mode == fusion::LocalizerMode::ambiguous) r.ambiguous_s += dt;
        if (e.mode == fusion::LocalizerMode::lost && (!kidnap_at_m || detected_at)) r.lost_s += dt;
      }
      // Between a kidnap and its detection the tracked pose is wrong by design, for 10 s at most.
      const bool excused = kidnap_at_m && kidnapped_at && !detected_at && t - *kidnapped_at < 10;
      const double err = (e.pose.translation() - truth.translation()).norm();
      const double yaw_err = std::abs(wrap_angle(e.pose.yaw() - truth.yaw()));
      const bool certain = loc.initialized() && e.known();
      const bool off = certain && !excused && err > 0.5;
      if (off && !wrong) ++r.wrong_fixes;
      wrong = off;
      const bool fix_allowed = !kidnap_at_m || detected_at;
      if (certain && fix_allowed && !fixed_at) {
        fixed_at = t;
        r.fixed = true;
        r.fix_error_m = err;
        r.fix_correct = err <= 0.5 && yaw_err <= 5 * kDeg;
        const double from_t = kidnapped_at.value_or(0.0);
        r.latency_s = t - from_t;
        r.latency_m = travel - kidnap_travel.value_or(0.0);
      }
      const double since = travel - kidnap_travel.value_or(0.0);
      if (fixed_at && t - *fixed_at > o.after_fix_s) break;
      if ((!kidnap_at_m || kidnapped_at) && since > o.max_travel_m) break;
      if (t > 3600) break;
    }
    r.detected = kidnap_at_m && detected_at;
    if (detected_at) r.detection_s = *detected_at - *kidnapped_at;
    if (!r.fixed) r.last_why = loc.relocalization().why;
    if (oracle) {
      const sim::OracleVerdict v = oracle->judge(drive);
      r.oracle_m = v.distinguishing_m;
      r.oracle_twins = v.twins;
    }
    return r;
  }
};

Battery::Battery(const graph::TopologicalMap& map, const RobotDescription& robot,
                 const BatteryOptions& options, const fusion::LocalizerOptions& localizer)
    : impl_(std::make_unique<Impl>(map, robot, options, localizer)) {}
Battery::~Battery() = default;

EpisodeResult Battery::kidnap(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Pose2 start = impl_->random_place(rng);
  // Tracking starts facing along the corridor, as a robot does.
  const graph::Node* n = impl_->map->node_containing(start.translation());
  if (n && n->axis) {
    const Vector2d d = n->axis->direction();
    start = Pose2(start.translation(), std::atan2(d.y(), d.x()) + (rng() % 2 ? M_PI : 0.0));
  }
  return impl_->run(start, impl_->o.tracking_before_m, seed);
}

EpisodeResult Battery::unknown_start(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  return impl_->run(impl_->random_place(rng), std::nullopt, seed);
}

EpisodeResult Battery::unknown_start_at(const Pose2& start, std::uint64_t seed) {
  return impl_->run(start, std::nullopt, seed);
}

BatteryFigures figures(const std::vector<EpisodeResult>& rs) {
  BatteryFigures f;
  std::vector<double> lat_s, lat_m, past;
  double unsure_s = 0, many_s = 0, all_s = 0;
  std::size_t unsure_frames = 0, unsure_hyp = 0, many_hyp = 0, all_frames = 0;
  for (const auto& r : rs) {
    ++f.episodes;
    f.detected += r.detected;
    f.fixed += r.fixed;
    f.correct += r.fix_correct;
    f.wrong_fixes += r.wrong_fixes;
    f.max_hypotheses = std::max(f.max_hypotheses, r.max_hypotheses);
    unsure_s += r.unsure_s;
    unsure_frames += r.unsure_frames;
    unsure_hyp += r.unsure_hypotheses;
    many_s += r.many_s;
    f.many_frames += r.many_frames;
    many_hyp += r.many_hypotheses;
    all_s += r.localizer_s;
    all_frames += r.frames;
    if (r.fixed) {
      lat_s.push_back(r.latency_s);
      lat_m.push_back(r.latency_m);
    }
    if (r.oracle_m) {
      ++f.oracle_decided;
      if (r.fixed) past.push_back(r.latency_m - *r.oracle_m);
    }
    // An oracle still undecided at the end of the drive decides later than the fix, if any.
    if (r.fix_correct && (!r.oracle_m || r.latency_m <= *r.oracle_m + 10)) ++f.within_oracle_10m;
  }
  auto pct = [](std::vector<double> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5))];
  };
  f.latency_s_median = pct(lat_s, 0.5);
  f.latency_s_p95 = pct(lat_s, 0.95);
  f.latency_m_median = pct(lat_m, 0.5);
  f.latency_m_p95 = pct(lat_m, 0.95);
  f.past_oracle_m_median = pct(past, 0.5);
  f.past_oracle_m_p95 = pct(past, 0.95);
  if (unsure_frames) {
    f.unsure_us_per_frame = 1e6 * unsure_s / unsure_frames;
    f.unsure_mean_hypotheses = double(unsure_hyp) / unsure_frames;
  }
  if (f.many_frames) {
    f.many_us_per_frame = 1e6 * many_s / f.many_frames;
    f.many_mean_hypotheses = double(many_hyp) / f.many_frames;
  }
  if (all_frames) f.amortized_us_per_frame = 1e6 * all_s / all_frames;
  return f;
}

std::string summarize(const std::vector<EpisodeResult>& rs) {
  const BatteryFigures f = figures(rs);
  std::ostringstream s;
  s << f.episodes << " episodes: " << f.detected << " detected, " << f.fixed << " fixed, "
    << f.correct << " correct, " << f.wrong_fixes << " wrong fixes; latency median "
    << f.latency_s_median << " s / " << f.latency_m_median << " m, p95 " << f.latency_s_p95
    << " s / " << f.latency_m_p95 << " m; at most " << f.max_hypotheses << " hypotheses; oracle "
    << "decided " << f.oracle_decided << ", fixed within its distance + 10 m "
    << f.within_oracle_10m << ", travel past it median " << f.past_oracle_m_median << " m, p95 "
    << f.past_oracle_m_p95 << " m";
  return s.str();
}

sim::BuildingOptions asymmetric_building(int nodes) {
  sim::BuildingOptions o;
  o.nodes = nodes;
  o.missing_corridors = 1;
  o.wing_lamp_spacing_m = 2.7;
  o.lobby = true;
  o.seed = 5;
  return o;
}

std::string imperfect_map(const std::string& geojson, double sigma_m, double unmapped_percent,
                          std::mt19937_64& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> percent(0.0, 100.0);
  nlohmann::json j = nlohmann::json::parse(geojson);
  for (auto& f : j["features"]) {
    auto& props = f["properties"];
    if (!props.contains("lampnav") || !props["lampnav"].contains("lamps")) continue;
    nlohmann::json kept = nlohmann::json::array();
    for (nlohmann::json l : props["lampnav"]["lamps"]) {
      if (percent(rng) < unmapped_percent) continue;
      for (int k = 0; k < 3; ++k)
        l["xyz"][k] = l["xyz"][k].get<double>() + (k == 2 ? 0.5 : 1.0) * sigma_m * n01(rng);
      kept.push_back(l);
    }
    props["lampnav"]["lamps"] = kept;
  }
  return j.dump();
}

}  // namespace lampnav::test
