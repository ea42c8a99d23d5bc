#include "lampnav/fusion/localizer.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

#include "lampnav/core/error.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::fusion {

const char* to_string(LocalizerMode m) {
  switch (m) {
    case LocalizerMode::tracking:
      return "tracking";
    case LocalizerMode::lost:
      return "lost";
    case LocalizerMode::relocalized:
      return "relocalized";
  }
  return "?";
}

void LocalizerOptions::validate() const {
  ekf.validate();
  calibration.validate();
  ceiling.validate();
  omni_detector.validate();
  omni_check.validate();
  kidnap.validate();
  if (omni_check_period < Duration::zero())
    throw InputError({"", "localizer options", "omni_check_period"}, "must not be negative");
  global.validate();
  if (omni_update_min_lamps < 0)
    throw InputError({"", "localizer options", "omni_update_min_lamps"}, "must not be negative");
  if (!(candidate_sigma_m > 0) || !(candidate_sigma_per_m >= 0) || !(candidate_sigma_yaw_deg > 0))
    throw InputError({"", "localizer options", "candidate_sigma"}, "must be positive");
}

namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr Duration kOdometryKept = std::chrono::seconds(120);
}  // namespace

struct Localizer::Impl {
  const graph::TopologicalMap* map;
  LocalizerOptions o;
  PoseEkf ekf;
  OdometryCalibration calibration;
  std::optional<CeilingPipeline> pipeline;
  std::optional<vision::PinholeCamera> ceiling_model;
  std::optional<CeilingGeometry> ceiling_geometry;
  std::optional<vision::OmniLampDetector> omni_detector;
  std::optional<OmniCheck> omni_check;
  std::optional<GlobalLocalizer> global;
  KidnapMonitor monitor;
  // Dead reckoning in its own frame, kept whatever the filter's state: it carries relocalization
  // candidates from one omni frame to the next, and a first fix to the latest odometry.
  std::deque<std::pair<Stamp, Pose2>> odometry;
  struct Candidate {
    PoseHypothesis hypothesis;  // score: summed over the frames it was scored on
    Pose2 odometry;             // dead-reckoned pose at its frame's capture
  };
  std::vector<Candidate> candidates;
  bool unconfirmed = false;  // the candidates come from an ambiguous image, not yet carried
  RelocalizationStatus relocalization;
  LocalizerMode mode = LocalizerMode::tracking;
  std::optional<std::pair<double, double>> last_wheels;
  CeilingObservation last_ceiling;
  vision::OmniDetection last_omni;
  Stamp last_omni_stamp;
  std::optional<Stamp> last_omni_check;
  std::vector<LocalizerEvent> events;
  LocalizerCounts counts;

  Impl(const graph::TopologicalMap& m, const RobotDescription& robot, LocalizerOptions opt)
      : map(&m),
        o(fix_semi_axis(std::move(opt), robot)),
        ekf(o.ekf),
        calibration(o.calibration),
        monitor(o.kidnap) {
    o.validate();
    if (const CameraDescription* c = robot.find_camera("ceiling_camera")) {
      pipeline.emplace(m, *c, o.ceiling);
      ceiling_model.emplace(*c);
      ceiling_geometry.emplace(*c);
    }
    if (const CameraDescription* c = robot.find_camera("omni_camera")) {
      omni_detector.emplace(*c, o.omni_detector);
      omni_check.emplace(m, *c, o.omni_check);
      global.emplace(m, *c, o.global);
    }
  }

  static LocalizerOptions fix_semi_axis(LocalizerOptions opt, const RobotDescription& robot) {
    opt.ekf.semi_axis = robot.semi_axis;
    opt.calibration.semi_axis = robot.semi_axis;
    return opt;
  }

  Stamp now() const { return ekf.initialized() ? ekf.stamp() : Stamp{}; }

  void set_mode(LocalizerMode m, const std::string& why) {
    if (m == mode) return;
    mode = m;
    events.push_back({now(), m, why});
    if (m == LocalizerMode::lost) {
      candidates.clear();
      if (pipeline) pipeline->reset();  // its labels are worthless
      calibration.forget_measurements();
    }
  }

  void track_odometry(Stamp stamp, double dl, double dr) {
    if (!std::isfinite(dl) || !std::isfinite(dr)) return;
    if (odometry.empty()) {
      odometry.emplace_back(stamp, Pose2());
      return;
    }
    if (stamp <= odometry.back().first) return;
    const StateVector x = predict_motion(odometry.back().second.vector(), dl, dr, o.ekf.semi_axis);
    odometry.emplace_back(stamp, Pose2(x.x(), x.y(), wrap_angle(x.z())));
    while (odometry.size() > 2 && stamp - odometry.front().first > kOdometryKept)
      odometry.pop_front();
  }

  // The dead-reckoned pose at `t`, interpolated; the nearest end outside the kept span.
  Pose2 odometry_at(Stamp t) const {
    if (odometry.empty()) return {};
    auto it = std::lower_bound(odometry.begin(), odometry.end(), t,
                               [](const auto& a, Stamp s) { return a.first < s; });
    if (it == odometry.begin()) return it->second;
    if (it == odometry.end()) return odometry.back().second;
    const auto& [tb, b] = *it;
    const auto& [ta, a] = *std::prev(it);
    const double f = to_seconds(t - ta) / std::max(1e-12, to_seconds(tb - ta));
    return Pose2(a.translation() + f * (b.translation() - a.translation()),
                 wrap_angle(a.yaw() + f * wrap_angle(b.yaw() - a.yaw())));
  }

  // An omni frame while lost (or before any pose): global localization, or the candidates
  // of earlier frames carried here by odometry and scored again.
  void relocalize(Stamp stamp, Localizer& self) {
    ++counts.relocalization_frames;
    const Pose2 odo = odometry_at(stamp);
    std::vector<Candidate> next;
    for (const Candidate& c : candidates) {
      const Pose2 delta = c.odometry.between(odo);
      const double travel = delta.translation().norm() + o.ekf.semi_axis * std::abs(delta.yaw());
      const double sp = o.candidate_sigma_m + o.candidate_sigma_per_m * travel;
      const double sy = o.candidate_sigma_yaw_deg * kDeg + o.candidate_sigma_per_m * travel;
      std::optional<PoseHypothesis> h =
          global->refine(c.hypothesis.pose * delta, sp, sy, last_omni);
      if (!h) continue;
      h->score += c.hypothesis.score;
      next.push_back({std::move(*h), odo});
    }
    candidates = std::move(next);
    if (candidates.empty()) {
      const GlobalLocalization r = global->locate(last_omni);
      if (!r.found()) {
        relocalization = {{}, r.why};
        return;
      }
      // The paper's method names one pose (its argmin); the default one names all that remain.
      const std::size_t n = r.method == GlobalMethod::paper ? 1 : r.hypotheses.size();
      for (std::size_t k = 0; k < n; ++k) candidates.push_back({r.hypotheses[k], odo});
      // An ambiguous image (a regular ceiling whose look-alikes were not all scored) fixes
      // nothing on its own, whatever is left: the next frame must agree.
      unconfirmed = r.ambiguous;
    } else {
      unconfirmed = false;
    }
    std::stable_sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
      return a.hypothesis.score < b.hypothesis.score;
    });
    const double limit = candidates.front().hypothesis.score + o.global.pairs.ambiguity_margin;
    candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                    [&](const Candidate& c) { return c.hypothesis.score > limit; }),
                     candidates.end());
    relocalization.candidates.clear();
    for (const Candidate& c : candidates) relocalization.candidates.push_back(c.hypothesis);
    if (candidates.size() > 1 || unconfirmed) {
      ++counts.ambiguous_frames;
      relocalization.why =
          candidates.size() > 1
              ? std::to_string(candidates.size()) +
                    " poses explain the omni view (a symmetric ceiling): waiting for the next "
                    "frame to choose"
              : "the omni view is ambiguous (a regular ceiling): waiting for the next frame to "
                "confirm";
      return;
    }
    const PoseHypothesis& h = candidates.front().hypothesis;
    Eigen::Matrix3d P = h.covariance;
    P.diagonal() += Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, std::pow(0.5 * kDeg, 2));
    candidates.clear();
    relocalization.why.clear();
    self.global_fix({stamp, h.pose, P, "omni"});
  }

  // While tracking: the omni frame's lamps, matched near the estimate, as a pose measurement.
  void omni_update(Stamp stamp, const FilterState& prior) {
    const double sp = std::clamp(std::sqrt(std::max(prior.P(0, 0), prior.P(1, 1))), 0.05, 0.5);
    const double sy = std::clamp(std::sqrt(prior.P(2, 2)), 0.5 * kDeg, 5 * kDeg);
    const std::optional<PoseHypothesis> h = global->refine(prior.pose(), sp, sy, last_omni);
    if (!h || int(h->matches.size()) < o.omni_update_min_lamps || h->missing > h->expected / 2)
      return;
    // The least-squares covariance knows detection noise only; floor bumps add to it.
    Eigen::Matrix3d R = h->covariance;
    R.diagonal() += Eigen::Vector3d(0.06 * 0.06, 0.06 * 0.06, std::pow(0.15 * kDeg, 2));
    const UpdateResult u = ekf.update(stamp, h->pose, R);
    if (u.applied() || u.status == UpdateResult::Status::pending) ++counts.omni_updates;
    if (u.applied() || u.refusal == Refusal::gated) lose(monitor.innovation(u.mahalanobis2));
  }

  void lose(const std::optional<std::string>& why) {
    if (why && mode != LocalizerMode::lost) set_mode(LocalizerMode::lost, *why);
  }

  // Map lamps the prior puts so well inside the image that, even 3 sigma off, they would be in
  // full view; and whether anything was seen near each.
  int expected_missing(const CeilingObservation& ob, const FilterState& prior) const {
    const double sigma = std::sqrt(std::max(prior.P(0, 0), prior.P(1, 1)));
    if (sigma > 0.3) return 0;
    const vision::PinholeCamera& cam = *ceiling_model;
    const double fx = cam.parameters().fx;
    int missing = 0;
    const Pose2 pose = prior.pose();
    for (const graph::Lamp* l : map->lamps_within(pose.translation(), 4.0)) {
      const auto n = ceiling_geometry->predict(pose, l->xyz);
      if (!n) continue;
      const double h = std::max(0.5, l->xyz.z() - ceiling_geometry->mount_origin().z());
      // Margin: 3 sigma of position, 3 sigma of heading over a 2 m lever, and most of the lamp.
      const double margin =
          fx * (3 * sigma + std::sqrt(prior.P(2, 2)) * 3 * 2.0 + 0.6 * l->length) / h;
      const Eigen::Vector2d px = cam.pixel_of_normalized(*n);
      if (px.x() < margin || px.y() < margin || px.x() > cam.width() - 1 - margin ||
          px.y() > cam.height() - 1 - margin)
        continue;
      bool seen = false;
      for (const auto& d : ob.lamps)
        if ((d.detection.centre_px - px).norm() < margin + 0.5 * fx * l->length / h) seen = true;
      if (!seen) ++missing;
    }
    return missing;
  }

  void observe(const CeilingObservation& ob, const FilterState& prior) {
    ++counts.ceiling_frames;
    CeilingEvidence e;
    e.stamp = ob.stamp;
    for (const auto& l : ob.lamps) {
      if (l.detection.view == vision::LampView::partial) continue;
      ++e.lamps_in_view;
      if (l.lamp) ++e.labelled;
      if (!l.lamp && l.outcome == LabelOutcome::no_candidate) ++e.unexplained;
    }
    if (ceiling_model) e.expected_missing = expected_missing(ob, prior);
    e.inconsistent = ob.no_measurement == PoseRefusal::labels_disagree;
    if (mode == LocalizerMode::lost) {
      ++counts.frames_while_lost;
      return;
    }
    if (ob.measurement) {
      const UpdateResult r =
          ekf.update(ob.measurement->stamp, ob.measurement->pose, ob.measurement->covariance);
      if (r.applied() || r.status == UpdateResult::Status::pending) {
        ++counts.measurements_applied;
        if (r.applied())
          calibration.heading(ob.measurement->stamp, ob.measurement->pose.yaw(),
                              ob.measurement->covariance(2, 2));
        if (mode == LocalizerMode::relocalized && r.applied())
          set_mode(LocalizerMode::tracking,
                   "a ceiling measurement agrees with the relocalized pose");
      } else {
        ++counts.measurements_refused;
      }
      if (r.refusal == Refusal::gated) e.measurement_refused = true;
      if (r.applied() || r.refusal == Refusal::gated) lose(monitor.innovation(r.mahalanobis2));
      if (mode == LocalizerMode::lost) return;
    }
    lose(monitor.ceiling(e));
  }
};

Localizer::Localizer(const graph::TopologicalMap& map, const RobotDescription& robot,
                     const LocalizerOptions& options)
    : impl_(std::make_unique<Impl>(map, robot, options)) {}
Localizer::~Localizer() = default;
Localizer::Localizer(Localizer&&) noexcept = default;

void Localizer::initialize(Stamp stamp, const Pose2& pose, const Eigen::Matrix3d& P) {
  Impl& m = *impl_;
  m.ekf.initialize(stamp, pose, P);
  m.monitor.reset();
  if (m.pipeline) m.pipeline->reset();
  m.mode = LocalizerMode::tracking;
  m.events.push_back({stamp, LocalizerMode::tracking, "initialized"});
}

bool Localizer::initialized() const { return impl_->ekf.initialized(); }

std::optional<Refusal> Localizer::wheels(Stamp stamp, double left, double right) {
  Impl& m = *impl_;
  ++m.counts.wheel_readings;
  // The first reading is the baseline (no motion); NaN or inf is refused by the filter.
  const auto [left0, right0] = m.last_wheels.value_or(std::pair{left, right});
  const double dl = left - left0, dr = right - right0;
  const auto [cl, cr] = m.calibration.correct(dl, dr);
  const auto r = m.ekf.predict(stamp, cl, cr);
  if (!r || *r == Refusal::not_initialized) {
    // Before the first pose the readings still count: relocalization dead-reckons with them.
    m.last_wheels = {left, right};
    if (!r) m.calibration.wheels(stamp, dl, dr);
    m.track_odometry(stamp, cl, cr);
  } else if (*r == Refusal::wheel_jump) {
    // An encoder glitch or reset: the jump is not motion; measure from the new reading on.
    m.last_wheels = {left, right};
    ++m.counts.wheel_rebaselined;
  }
  return r;
}

std::optional<FilterState> Localizer::prior_at(Stamp stamp) const {
  const PoseEkf& f = impl_->ekf;
  if (!f.initialized()) return std::nullopt;
  if (stamp > f.stamp()) return f.current();  // captured after the latest odometry
  return f.state_at(stamp);
}

const CeilingObservation& Localizer::ceiling_frame(Stamp stamp, const vision::ImageView& image) {
  Impl& m = *impl_;
  m.last_ceiling = CeilingObservation{};
  m.last_ceiling.stamp = stamp;
  if (!m.pipeline)
    throw InputError({"", "robot.json", "cameras"}, "the robot has no ceiling_camera");
  const std::optional<FilterState> prior = prior_at(stamp);
  if (!prior) {
    ++m.counts.frames_too_old;
    m.last_ceiling.no_measurement_reason = "captured before the filter's history";
    return m.last_ceiling;
  }
  m.last_ceiling = m.pipeline->process(stamp, image, prior->pose(), prior->P);
  m.observe(m.last_ceiling, *prior);
  return m.last_ceiling;
}

void Localizer::ceiling_observation(const CeilingObservation& ob) {
  const std::optional<FilterState> prior = prior_at(ob.stamp);
  if (!prior) {
    ++impl_->counts.frames_too_old;
    return;
  }
  impl_->observe(ob, *prior);
}

const vision::OmniDetection& Localizer::omni_frame(Stamp stamp, const vision::ImageView& image) {
  Impl& m = *impl_;
  if (!m.omni_detector)
    throw InputError({"", "robot.json", "cameras"}, "the robot has no omni_camera");
  m.last_omni = m.omni_detector->detect(image);
  m.last_omni_stamp = stamp;
  ++m.counts.omni_frames;
  if (m.mode == LocalizerMode::lost || !m.ekf.initialized()) {
    m.relocalize(stamp, *this);
    return m.last_omni;
  }
  if (m.last_omni_check && stamp - *m.last_omni_check < m.o.omni_check_period) return m.last_omni;
  const std::optional<FilterState> prior = prior_at(stamp);
  if (!prior) return m.last_omni;
  m.last_omni_check = stamp;
  const OmniCheckResult r = m.omni_check->check(prior->pose(), prior->P, m.last_omni.blobs);
  if (m.mode == LocalizerMode::relocalized && r.conclusive && r.consistent)
    m.set_mode(LocalizerMode::tracking,
               "the omnidirectional view agrees with the relocalized pose");
  m.lose(m.monitor.omni(r));
  if (m.mode == LocalizerMode::lost) {
    m.relocalize(stamp, *this);  // the frame that showed the loss shows where the robot is
  } else if (r.conclusive && r.consistent && m.o.omni_update_min_lamps > 0) {
    m.omni_update(stamp, *prior);
  }
  return m.last_omni;
}

bool Localizer::global_fix(const GlobalFix& fix) {
  Impl& m = *impl_;
  ++m.counts.global_fixes;
  if (!m.ekf.initialized()) {
    try {
      // The odometry read since the fix's capture moves it to the latest reading.
      Stamp at = fix.stamp;
      Pose2 pose = fix.pose;
      if (!m.odometry.empty() && m.odometry.back().first > fix.stamp) {
        at = m.odometry.back().first;
        pose = fix.pose * m.odometry_at(fix.stamp).between(m.odometry.back().second);
      }
      m.ekf.initialize(at, pose, fix.covariance);
    } catch (const InputError&) {
      ++m.counts.fixes_refused;
      return false;
    }
  } else if (m.ekf.restart_at(fix.stamp, fix.pose, fix.covariance)) {
    ++m.counts.fixes_refused;
    return false;
  }
  m.monitor.reset();
  if (m.pipeline) m.pipeline->reset();
  m.calibration.forget_measurements();
  m.set_mode(LocalizerMode::relocalized,
             "global fix" + (fix.source.empty() ? std::string() : " from " + fix.source));
  return true;
}

LocalizerEstimate Localizer::estimate() const {
  const Impl& m = *impl_;
  LocalizerEstimate e;
  e.mode = m.mode;
  if (!m.ekf.initialized()) return e;
  e.stamp = m.ekf.stamp();
  e.pose = m.ekf.pose();
  e.covariance = m.ekf.covariance();
  e.node = m.map->node_containing(e.pose.translation());
  return e;
}

LocalizerMode Localizer::mode() const { return impl_->mode; }
const vision::OmniDetection* Localizer::last_omni() const {
  return impl_->counts.omni_frames > 0 ? &impl_->last_omni : nullptr;
}
Stamp Localizer::last_omni_stamp() const { return impl_->last_omni_stamp; }
const RelocalizationStatus& Localizer::relocalization() const { return impl_->relocalization; }
const std::vector<LocalizerEvent>& Localizer::events() const { return impl_->events; }
const LocalizerCounts& Localizer::counts() const { return impl_->counts; }
const KidnapMonitor::Counts& Localizer::kidnap_counts() const { return impl_->monitor.counts(); }
const PoseEkf& Localizer::filter() const { return impl_->ekf; }
const OdometryCalibration& Localizer::calibration() const { return impl_->calibration; }
bool Localizer::has_ceiling_camera() const { return impl_->pipeline.has_value(); }
bool Localizer::has_omni_camera() const { return impl_->omni_detector.has_value(); }

}  // namespace lampnav::fusion
