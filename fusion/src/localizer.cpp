#include "lampnav/fusion/localizer.hpp"

#include <cmath>

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
}

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
  KidnapMonitor monitor;
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
      if (pipeline) pipeline->reset();  // its labels are worthless
      calibration.forget_measurements();
    }
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
  if (!r) {
    m.last_wheels = {left, right};
    m.calibration.wheels(stamp, dl, dr);
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
  if (m.mode == LocalizerMode::lost) return m.last_omni;
  if (m.last_omni_check && stamp - *m.last_omni_check < m.o.omni_check_period) return m.last_omni;
  const std::optional<FilterState> prior = prior_at(stamp);
  if (!prior) return m.last_omni;
  m.last_omni_check = stamp;
  const OmniCheckResult r = m.omni_check->check(prior->pose(), prior->P, m.last_omni.blobs);
  if (m.mode == LocalizerMode::relocalized && r.conclusive && r.consistent)
    m.set_mode(LocalizerMode::tracking,
               "the omnidirectional view agrees with the relocalized pose");
  m.lose(m.monitor.omni(r));
  return m.last_omni;
}

bool Localizer::global_fix(const GlobalFix& fix) {
  Impl& m = *impl_;
  ++m.counts.global_fixes;
  if (!m.ekf.initialized()) {
    try {
      m.ekf.initialize(fix.stamp, fix.pose, fix.covariance);
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
const std::vector<LocalizerEvent>& Localizer::events() const { return impl_->events; }
const LocalizerCounts& Localizer::counts() const { return impl_->counts; }
const KidnapMonitor::Counts& Localizer::kidnap_counts() const { return impl_->monitor.counts(); }
const PoseEkf& Localizer::filter() const { return impl_->ekf; }
const OdometryCalibration& Localizer::calibration() const { return impl_->calibration; }
bool Localizer::has_ceiling_camera() const { return impl_->pipeline.has_value(); }
bool Localizer::has_omni_camera() const { return impl_->omni_detector.has_value(); }

}  // namespace lampnav::fusion
