#include "audits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace lampnav::fusion::detail {

namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr int kLookAlikeMatches = 3;  // blobs a look-alike place must explain to challenge
}  // namespace

EstimateSigmas estimate_sigmas(const FilterState& prior) {
  return {std::clamp(std::sqrt(std::max(prior.P(0, 0), prior.P(1, 1))), 0.05, 0.5),
          std::clamp(std::sqrt(prior.P(2, 2)), 0.5 * kDeg, 5 * kDeg)};
}

Auditor::Auditor(const graph::TopologicalMap& map, const GlobalLocalizer& global,
                 const LocalizerOptions& o)
    : global_(&global),
      look_alikes_(o.audit_period > Duration::zero()
                       ? look_alike_motions(map, o.audit_look_alike_fraction, o.audit_look_alikes)
                       : std::vector<LookAlikeMotion>{}),
      period_(o.audit_period),
      second_opinion_ratio_(o.second_opinion_ratio),
      distance_m_(o.second_opinion_distance),
      ratio_(o.audit_ratio),
      step_ratio_(o.audit_step_ratio),
      station_m_(o.hypotheses.station_m),
      challenge_frames_(o.audit_challenge_frames) {}

std::optional<Elsewhere> Auditor::elsewhere(const FilterState& prior,
                                            const vision::OmniDetection& omni, bool named) const {
  const GlobalLocalization g = global_->locate(omni);
  if (!g.found() || (named && g.ambiguous)) return std::nullopt;
  const auto end = named ? g.hypotheses.begin() + 1 : g.hypotheses.end();
  const auto far = std::find_if(g.hypotheses.begin(), end, [&](const PoseHypothesis& h) {
    return (h.pose.translation() - prior.pose().translation()).norm() >= distance_m_;
  });
  if (far == end) return std::nullopt;
  return compared(prior, far->pose, omni);
}

std::optional<Elsewhere> Auditor::likeliest_look_alike(const FilterState& prior,
                                                       const vision::OmniDetection& omni) const {
  // A carry the ceiling camera cannot see leaves the robot where the estimate's look-alike
  // stands, to the estimate's own error: each is scored where the motion puts it, and only the
  // likeliest, when likelier than the estimate, is refined on the frame.
  if (look_alikes_.empty()) return std::nullopt;
  const auto [sp, sy] = estimate_sigmas(prior);
  const GlobalLocalizer::PoseScore here = global_->score(prior.pose(), sp, sy, omni);
  // Only a place that explains at least as many of the frame's blobs as the estimate (and three
  // or more) may challenge it: what the frame shows, not only the lamps it misses. A dark or
  // empty frame misses fewer lamps where fewer are in view, and says nothing of where the robot is.
  const int needed = std::max(kLookAlikeMatches, here.matched);
  std::optional<Pose2> best;
  double best_cost = here.cost;
  for (const LookAlikeMotion& m : look_alikes_) {
    const Pose2 there = m.motion * prior.pose();
    if ((there.translation() - prior.pose().translation()).norm() < distance_m_) continue;
    const GlobalLocalizer::PoseScore sc = global_->score(there, sp, sy, omni);
    if (sc.matched >= needed && sc.cost < best_cost) best_cost = sc.cost, best = there;
  }
  if (!best) return std::nullopt;
  Elsewhere e = compared(prior, *best, omni);
  if (const std::optional<PoseHypothesis> refined = global_->refine(*best, 0.3, 3 * kDeg, omni)) {
    const Elsewhere r = compared(prior, refined->pose, omni);
    if (r.away >= distance_m_ && r.log_ratio > e.log_ratio) e = r;
  }
  return e;
}

Elsewhere Auditor::compared(const FilterState& prior, const Pose2& there,
                            const vision::OmniDetection& omni) const {
  const auto [sp, sy] = estimate_sigmas(prior);
  const double here_cost = global_->score(prior.pose(), sp, sy, omni).cost;
  const double there_cost = global_->score(there, sp, sy, omni).cost;
  return Elsewhere{there, (there.translation() - prior.pose().translation()).norm(),
                   0.5 * (here_cost - there_cost)};
}

std::optional<LossVerdict> Auditor::second_opinion(const FilterState& prior,
                                                   const OmniCheckResult& r,
                                                   const vision::OmniDetection& omni) const {
  if (second_opinion_ratio_ <= 0) return std::nullopt;
  const std::optional<Elsewhere> e = elsewhere(prior, omni, true);
  if (!e || e->log_ratio < std::log(second_opinion_ratio_)) return std::nullopt;
  char why[240];
  std::snprintf(why, sizeof why,
                "the omnidirectional view does not match the estimate (%d of %d predicted "
                "lamps seen) and puts the robot %.1f m away, e^%.0f times likelier",
                r.matched, r.expected, e->away, e->log_ratio);
  return LossVerdict{ModeCause::omni_locates_elsewhere, why};
}

bool Auditor::due(Stamp stamp) {
  if (period_ <= Duration::zero()) return false;
  const bool started = last_ && stamp >= *last_;  // else a new schedule
  // While a challenger stands, every omni frame weighs it.
  if (started && !challenger_ && stamp - *last_ < period_) return false;
  last_ = stamp;
  return started;
}

void Auditor::reset() {
  last_.reset();
  challenger_.reset();
}

std::optional<LossVerdict> Auditor::audit(Stamp stamp, const FilterState& prior,
                                          const OmniCheckResult& r,
                                          const vision::OmniDetection& omni,
                                          const OdometryTrack& odometry) {
  if (challenger_) return challenge(stamp, prior, r, omni, odometry);
  std::optional<Elsewhere> e = elsewhere(prior, omni, false);
  if (const std::optional<Elsewhere> twin = likeliest_look_alike(prior, omni))
    if (!e || twin->log_ratio > e->log_ratio) e = twin;
  if (!e || e->log_ratio < std::log(step_ratio_)) return std::nullopt;
  if (e->log_ratio >= std::log(ratio_)) return loss(*e, e->log_ratio, 1, r);
  if (odometry.empty()) return std::nullopt;
  const Pose2 at = odometry.at(stamp);
  challenger_ = Challenger{e->pose, at, at, e->log_ratio, 1, 1};
  return std::nullopt;
}

std::optional<LossVerdict> Auditor::challenge(Stamp stamp, const FilterState& prior,
                                              const OmniCheckResult& r,
                                              const vision::OmniDetection& omni,
                                              const OdometryTrack& odometry) {
  Challenger& c = *challenger_;
  const Pose2 now = odometry.at(stamp);
  Pose2 there = c.pose * c.odometry.between(now);
  if (const std::optional<PoseHypothesis> refined = global_->refine(there, 0.3, 3 * kDeg, omni))
    there = refined->pose;
  const Elsewhere e = compared(prior, there, omni);
  c.pose = there;
  c.odometry = now;
  ++c.frames;
  if (e.log_ratio < 0 || e.away < distance_m_) {
    challenger_.reset();
    return std::nullopt;
  }
  if ((c.counted_odometry.translation() - now.translation()).norm() >= station_m_) {
    c.log_sum += e.log_ratio;
    ++c.images;
    c.counted_odometry = now;
  }
  if (c.log_sum >= std::log(ratio_)) {
    const double sum = c.log_sum;
    const int images = c.images;
    challenger_.reset();
    return loss(e, sum, images, r);
  }
  if (c.frames >= challenge_frames_) challenger_.reset();
  return std::nullopt;
}

LossVerdict Auditor::loss(const Elsewhere& e, double log_sum, int images,
                          const OmniCheckResult& r) {
  char why[320];
  if (images == 1)
    std::snprintf(why, sizeof why,
                  "an audit of the omnidirectional view puts the robot %.1f m away, e^%.0f "
                  "times likelier than the estimate, whose near lamps it matches (%d of %d): "
                  "a look-alike place",
                  e.away, log_sum, r.matched, r.expected);
  else
    std::snprintf(why, sizeof why,
                  "audits of %d omnidirectional images put the robot %.1f m away, e^%.0f times "
                  "likelier than the estimate in all, whose near lamps the last matches (%d of "
                  "%d): a look-alike place",
                  images, e.away, log_sum, r.matched, r.expected);
  return LossVerdict{ModeCause::omni_locates_elsewhere, why};
}

}  // namespace lampnav::fusion::detail
