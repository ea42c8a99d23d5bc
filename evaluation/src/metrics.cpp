// Scoring a replay against the log's truth (spec/cli.md's metrics.json). The definitions here are
// what every figure in docs and bench/ means: keep them in one place.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "lampnav/evaluation/replay.hpp"

namespace lampnav::evaluation {

namespace {

constexpr double kDeg = M_PI / 180.0;

ErrorStats stats_of(const std::vector<double>& v) {
  ErrorStats s;
  s.n = v.size();
  if (v.empty()) return s;
  double sum = 0, sum2 = 0;
  for (double x : v) {
    sum += x;
    sum2 += x * x;
    s.max = std::max(s.max, x);
  }
  s.mean = sum / v.size();
  s.rms = std::sqrt(sum2 / v.size());
  return s;
}

}  // namespace

Metrics score(const ReplayResult& r, const io::MissionLog& log) {
  Metrics m;
  m.ceiling_frames = r.outcome.ceiling_frames;
  m.omni_frames = r.outcome.omni_frames;
  m.frames = m.ceiling_frames + m.omni_frames;
  m.duration_s = r.outcome.duration_s();
  for (const auto& f : r.lamp_frames)
    for (const auto& l : f.observations.lamps) {
      ++m.lamps_seen;
      if (l.label) ++m.lamps_labelled;
    }
  // Time lost, time ambiguous.
  for (std::size_t k = 1; k < r.estimates.size(); ++k) {
    const double dt = to_seconds(r.estimates[k].stamp - r.estimates[k - 1].stamp);
    if (r.estimates[k - 1].mode == fusion::LocalizerMode::lost) m.lost_s += dt;
    if (r.estimates[k - 1].mode == fusion::LocalizerMode::ambiguous) m.ambiguous_s += dt;
  }
  // Kidnaps and the fixes after them.
  // A fix or a mode change counts after a kidnap only when it rests on an input captured after
  // it: one made from a frame captured before the robot was carried, and published after, knew
  // nothing of the carry (the cameras' frames arrive late), as the tracking poses that follow a
  // carry until the localizer sees it know nothing of it.
  std::vector<Stamp> kidnaps;
  std::vector<const fusion::LocalizerEvent*> fixes;
  for (const auto& e : log.events)
    if (e.value.type() == io::EventKind::kidnap) kidnaps.push_back(e.value.stamp);
  std::sort(kidnaps.begin(), kidnaps.end());
  for (const auto& e : r.events)
    if (e.mode == fusion::LocalizerMode::relocalized) fixes.push_back(&e);
  // (A frame captured at the instant of the kidnap event shows the robot before the move.)
  const auto after = [](const fusion::LocalizerEvent& e, Stamp k) {
    return e.stamp >= k && e.evidence > k;
  };
  m.kidnaps = static_cast<int>(kidnaps.size());
  std::vector<double> latency;
  // From a kidnap to the first fix after it, which may come after the next kidnap (carried again
  // before it was found): the poses until then are not scored, those after it are. A recovery
  // is a fix before the next kidnap.
  std::vector<std::pair<Stamp, std::optional<Stamp>>> unsure;
  for (std::size_t k = 0; k < kidnaps.size(); ++k) {
    const Stamp until = k + 1 < kidnaps.size() ? kidnaps[k + 1] : Stamp::max();
    auto fix = std::find_if(fixes.begin(), fixes.end(),
                            [&](const fusion::LocalizerEvent* e) { return after(*e, kidnaps[k]); });
    if (fix != fixes.end() && (*fix)->stamp < until) {
      ++m.recoveries;
      latency.push_back(to_seconds((*fix)->stamp - kidnaps[k]));
    }
    unsure.push_back(
        {kidnaps[k], fix != fixes.end() ? std::optional<Stamp>((*fix)->stamp) : std::nullopt});
  }
  m.relocalization_latency_s = stats_of(latency);
  // Errors: tracking estimates outside [kidnap, its fix] (one at the fix's instant was published
  // before the frame that made the fix was taken in: a loss and a fix from one omni frame).
  m.has_truth = !log.truth.empty();
  for (int s = 0; s < 3; ++s) m.input_faults[s] = r.outcome.faults[s];
  if (!m.has_truth) return m;
  const io::TruthTrack truth(log.truth);
  std::vector<double> pos, yaw;
  for (const auto& e : r.estimates) {
    if (e.mode != fusion::LocalizerMode::tracking) continue;
    bool skip = false;
    for (const auto& [from, to] : unsure)
      if (e.stamp >= from && (!to || e.stamp <= *to)) skip = true;
    if (skip) continue;
    const Pose2 t = truth.at(e.stamp);
    pos.push_back((e.pose.translation() - t.translation()).norm());
    yaw.push_back(std::fabs(wrap_angle(e.pose.yaw() - t.yaw())) / kDeg);
  }
  m.position_error_m = stats_of(pos);
  m.yaw_error_deg = stats_of(yaw);
  // Wrong fixes: a pose published as certain more than 0.5 m off, except between a kidnap and
  // the localizer noticing it (the first mode change after it, on an input captured after it),
  // 10 s at most.
  std::vector<std::pair<Stamp, Stamp>> unnoticed;
  for (const Stamp k : kidnaps) {
    Stamp until = k + std::chrono::seconds(10);
    for (const auto& e : r.events)
      if (after(e, k) && e.mode != fusion::LocalizerMode::tracking) {
        until = std::min(until, e.stamp);
        break;
      }
    unnoticed.emplace_back(k, until);
  }
  bool wrong = false;
  for (const auto& e : r.estimates) {
    const bool certain = fusion::is_certain(e.mode);
    bool excused = false;
    for (const auto& [from, to] : unnoticed)
      if (e.stamp >= from && e.stamp <= to) excused = true;  // an estimate at the instant of
    // the event was published before the frame that showed it
    const bool off = certain && !excused &&
                     (e.pose.translation() - truth.at(e.stamp).translation()).norm() > 0.5;
    if (off && !wrong) ++m.wrong_fixes;
    wrong = off;
  }
  return m;
}

std::string metrics_json(const Metrics& m) {
  using Json = nlohmann::ordered_json;
  auto err = [&](const ErrorStats& s) -> Json {
    if (!m.has_truth || s.n == 0) return nullptr;
    return Json{{"mean", s.mean}, {"rms", s.rms}, {"max", s.max}, {"samples", s.n}};
  };
  Json j;
  j["frames"] = m.frames;
  j["ceiling_frames"] = m.ceiling_frames;
  j["omni_frames"] = m.omni_frames;
  j["duration_s"] = m.duration_s;
  j["has_truth"] = m.has_truth;
  j["position_error_m"] = err(m.position_error_m);
  j["yaw_error_deg"] = err(m.yaw_error_deg);
  j["lost_s"] = m.lost_s;
  j["ambiguous_s"] = m.ambiguous_s;
  j["wrong_fixes"] = m.has_truth ? Json(m.wrong_fixes) : Json(nullptr);
  j["kidnaps"] = m.kidnaps;
  j["recoveries"] = m.recoveries;
  j["relocalization_latency_s"] =
      m.relocalization_latency_s.n
          ? Json{{"mean", m.relocalization_latency_s.mean}, {"max", m.relocalization_latency_s.max}}
          : Json(nullptr);
  j["lamps_seen"] = m.lamps_seen;
  j["lamps_labelled"] = m.lamps_labelled;
  Json faults;
  for (int s = 0; s < 3; ++s) {
    const navigation::InputFaultCounts& f = m.input_faults[s];
    faults[s == 0   ? "wheels"
           : s == 1 ? "ceiling"
                    : "omni"] = {{"gaps", f.gaps},
                                 {"longest_gap_s", f.longest_gap_s},
                                 {"duplicates", f.duplicates},
                                 {"out_of_order", f.out_of_order}};
  }
  j["input_faults"] = faults;
  j["frames_too_old"] = m.frames_too_old;
  j["runtime_s"] = m.runtime_s;
  j["realtime_factor"] = m.realtime_factor;
  return j.dump(2) + "\n";
}

}  // namespace lampnav::evaluation
