#include "lampnav/fusion/localizer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "audits.hpp"
#include "ceiling_rays.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::fusion {

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
  if (!(second_opinion_ratio == 0 ||
        (second_opinion_ratio >= 1 && std::isfinite(second_opinion_ratio))))
    throw InputError({"", "localizer options", "second_opinion_ratio"},
                     "must be 0 (off) or a likelihood ratio of at least 1");
  if (!(second_opinion_distance > 0 && std::isfinite(second_opinion_distance)))
    throw InputError({"", "localizer options", "second_opinion_distance"},
                     "must be a positive distance in m");
  if (audit_period < Duration::zero())
    throw InputError({"", "localizer options", "audit_period"}, "must not be negative");
  if (!(audit_ratio >= 1 && std::isfinite(audit_ratio)))
    throw InputError({"", "localizer options", "audit_ratio"},
                     "must be a likelihood ratio of at least 1");
  if (audit_look_alikes < 0 || audit_look_alikes > 1000)
    throw InputError({"", "localizer options", "audit_look_alikes"}, "must be 0 to 1000");
  if (!(audit_look_alike_fraction > 0 && audit_look_alike_fraction <= 1))
    throw InputError({"", "localizer options", "audit_look_alike_fraction"},
                     "must be a fraction of the lamps, above 0 and at most 1");
  if (audit_challenge_frames < 1)
    throw InputError({"", "localizer options", "audit_challenge_frames"}, "must be at least 1");
  if (!(audit_step_ratio >= 1 && audit_step_ratio <= audit_ratio))
    throw InputError({"", "localizer options", "audit_step_ratio"},
                     "must be a likelihood ratio of at least 1, at most audit_ratio");
  if (!(max_odometry_gap > Duration::zero()))
    throw InputError({"", "localizer options", "max_odometry_gap"}, "must be positive");
  hypotheses.validate();
  continuity.validate();
}

namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

struct Localizer::Impl {
  const graph::TopologicalMap* map;
  LocalizerOptions o;
  PoseEkf ekf;
  OdometryCalibration calibration;
  std::optional<CeilingPipeline> pipeline;
  std::optional<vision::PinholeCamera> ceiling_model;
  std::optional<CeilingGeometry> ceiling_geometry;
  std::optional<vision::LampShapePrior> ceiling_kind;  // the lamps the ceiling camera looks for
  std::optional<CeilingContinuity> continuity;  // moves the ceiling camera saw and the wheels not
  // The tilt spread the continuity check learnt (or the configured one), given to the models
  // that follow a known pose, and the one the kidnap monitor's evidence was weighed with.
  double floor_swing = 0, weighed_swing = 0;
  bool floor_measured = true;  // swing_measured() when the hypotheses were last told
  int frames_checked = 0;      // ceiling frames the continuity check has seen
  // Frames captured before this weigh no hypothesis: the robot was moved after them (a move the
  // ceiling camera saw), and the dead reckoning cannot carry them across it.
  std::optional<Stamp> moved_after;
  std::optional<vision::OmniLampDetector> omni_detector;
  std::optional<OmniCheck> omni_check;
  std::optional<GlobalLocalizer> global;
  KidnapMonitor monitor;
  // Dead reckoning in its own frame, kept whatever the filter's state: it carries hypotheses
  // between frames, and a first fix to the latest odometry.
  OdometryTrack odometry;
  std::optional<HypothesisSet> hypotheses;
  RelocalizationStatus relocalization;
  LocalizerMode mode = LocalizerMode::lost;  // until told, or found
  std::optional<std::pair<double, double>> last_wheels;
  CeilingObservation last_ceiling;
  vision::OmniDetection last_omni;
  Stamp last_omni_stamp;
  std::optional<Stamp> last_omni_check;
  struct PendingAudit {
    Stamp stamp;
    FilterState prior;
    OmniCheckResult check;
  };
  std::optional<PendingAudit> pending_audit;
  // Second opinions and audits of the omni view while the estimate is certain.
  std::optional<detail::Auditor> auditor;
  std::vector<LocalizerEvent> events;
  Stamp evidence;  // capture time of the input being taken in (LocalizerEvent::evidence)
  LocalizerCounts counts;

  Impl(const graph::TopologicalMap& m, const RobotDescription& robot, LocalizerOptions opt)
      : map(&m),
        o(fix_semi_axis(std::move(opt), robot)),
        ekf(o.ekf),
        calibration(o.calibration),
        monitor(o.kidnap),
        odometry(robot.semi_axis) {
    o.validate();
    floor_swing = weighed_swing = o.continuity.tilt_sigma;
    const CameraDescription* ceiling_camera = robot.find_camera("ceiling_camera");
    if (ceiling_camera) {
      pipeline.emplace(m, *ceiling_camera, o.ceiling);
      ceiling_model.emplace(*ceiling_camera);
      ceiling_geometry.emplace(*ceiling_camera);
      ceiling_kind = shape_prior_for(m, *ceiling_camera);
      // The map's median lamp height above the floor (0 for a map without lamps).
      const double z = detail::usual_lamp_height(m, 0.0);
      if (o.continuity.enabled && z > 0) continuity.emplace(*ceiling_camera, z, o.continuity);
    }
    if (const CameraDescription* c = robot.find_camera("omni_camera")) {
      omni_detector.emplace(*c, o.omni_detector);
      omni_check.emplace(m, *c, o.omni_check);
      global.emplace(m, *c, o.global);
      auditor.emplace(m, *global, o);
    }
    hypotheses.emplace(m, ceiling_camera, global ? &*global : nullptr, o.ceiling, o.hypotheses);
  }

  // The learnt swing over the configured tilt, at least 1.
  double swing_factor(double swing) const {
    const double configured = o.continuity.tilt_sigma;
    return configured > 0 ? std::max(1.0, swing / configured) : 1.0;
  }
  // Whether the floor's swing is taken as known: measured over tilt_min_samples lamps; or not
  // being measured (no ceiling camera, no continuity check, learn_tilt off, no ceiling frame yet,
  // or tilt_window frames gone by without enough lamps seen twice to measure it): the configured
  // models are then taken as the floor's, as before.
  bool swing_measured() const {
    return !continuity || !o.continuity.learn_tilt || continuity->learnt_tilt_sigma() ||
           frames_checked == 0 || frames_checked > o.continuity.tilt_window;
  }
  // The power the margins to publish take: the swing's factor once measured; before, the
  // largest swing the continuity check could learn (max_tilt_sigma). The first images of a drive
  // on a floor swinging 0.8 degrees put a half-turn twin ahead of the truth by more than the
  // steady floor's margins before 50 lamps had measured the floor (docs/hypotheses.md, "A floor
  // not measured yet"); a set of one place, or one whose runner-up the images rule out by far,
  // publishes as before.
  double publish_factor(double factor) const {
    if (floor_measured || !o.hypotheses.unmeasured_floor_swings_most) return factor;
    return std::max(factor, swing_factor(o.continuity.max_tilt_sigma));
  }

  static LocalizerOptions fix_semi_axis(LocalizerOptions opt, const RobotDescription& robot) {
    opt.ekf.semi_axis = robot.semi_axis;
    opt.calibration.semi_axis = robot.semi_axis;
    return opt;
  }

  Stamp now() const {
    if (ekf.initialized()) return ekf.stamp();
    return odometry.empty() ? Stamp{} : odometry.last_stamp();
  }
  bool unsure() const { return !is_certain(mode); }

  void set_mode(LocalizerMode m, ModeCause cause, const std::string& why) {
    if (m == mode) return;
    const bool was_unsure = unsure();
    mode = m;
    events.push_back({now(), m, cause, why, evidence});
    if (unsure() && !was_unsure) {
      if (auditor) auditor->reset();    // audits start again with the next certain stretch
      if (pipeline) pipeline->reset();  // its labels are worthless
      calibration.forget_measurements();
    }
  }

  // The hypotheses as the estimate publishes them, carried to `t`.
  std::vector<WeightedPose> weighted(Stamp t) const {
    std::vector<WeightedPose> out;
    for (const Hypothesis& h : hypotheses->hypotheses()) {
      const Hypothesis c = hypotheses->carried(h, t, odometry);
      out.push_back({c.pose, c.covariance, h.weight, map->node_containing(c.pose.translation())});
    }
    return out;
  }

  // A fix (from the hypotheses, or from outside): re-initializes the filter at its capture time.
  bool apply_fix(const GlobalFix& fix) {
    ++counts.global_fixes;
    if (!ekf.initialized()) {
      try {
        // The odometry read since the fix's capture moves it to the latest reading.
        Stamp at = fix.stamp;
        Pose2 pose = fix.pose;
        if (!odometry.empty() && odometry.last_stamp() > fix.stamp) {
          at = odometry.last_stamp();
          pose = fix.pose * odometry.at(fix.stamp).between(odometry.last());
        }
        ekf.initialize(at, pose, fix.covariance);
      } catch (const InputError&) {
        ++counts.fixes_refused;
        return false;
      }
    } else if (ekf.restart_at(fix.stamp, fix.pose, fix.covariance)) {
      ++counts.fixes_refused;
      return false;
    }
    monitor.reset();
    if (pipeline) pipeline->reset();
    calibration.forget_measurements();
    hypotheses->clear();
    set_mode(LocalizerMode::relocalized, ModeCause::global_fix,
             "global fix" + (fix.source.empty() ? std::string() : " from " + fix.source));
    return true;
  }

  // After a frame weighed the hypotheses: a fix when one holds the evidence, else the mode says
  // whether the places the robot may be are all known (ambiguous) or not (lost).
  // The relocalization status from the hypothesis set as it stands.
  void refresh_status() {
    relocalization.verdict = hypotheses->verdict();
    relocalization.why = hypotheses->why();
    relocalization.hypotheses.clear();
    for (const Hypothesis& h : hypotheses->hypotheses())
      relocalization.hypotheses.push_back({h.pose, h.covariance, h.weight, h.node});
  }

  void settle(Stamp stamp) {
    refresh_status();
    if (const Hypothesis* w = hypotheses->winner()) {
      // Carried to the newest odometry, so the fix is inside the filter's history.
      const Stamp at = odometry.empty() ? stamp : std::max(stamp, odometry.last_stamp());
      const Hypothesis c = hypotheses->carried(*w, at, odometry);
      relocalization.why.clear();
      if (apply_fix({at, c.pose, c.covariance, "omni"})) {
        hypotheses->clear();
        return;
      }
    }
    if (relocalization.verdict == HypothesisVerdict::ambiguous ||
        relocalization.verdict == HypothesisVerdict::symmetric) {
      ++counts.ambiguous_frames;
      set_mode(LocalizerMode::ambiguous, ModeCause::hypotheses_undecided, relocalization.why);
    } else {
      set_mode(LocalizerMode::lost, ModeCause::hypotheses_undecided, relocalization.why);
    }
  }

  // An omni frame while unsure: the hypotheses weighed (and born, while they are not all known).
  void relocalize(Stamp stamp) {
    if (before_odometry(stamp) || before_move(stamp)) return;
    ++counts.relocalization_frames;
    hypotheses->omni(stamp, last_omni, odometry);
    settle(stamp);
  }

  // The pending audit, if the estimate is still certain: a loss it proves is declared on its
  // frame's evidence, and that frame is the first the hypotheses weigh.
  bool run_audit() {
    if (!pending_audit) return false;
    const PendingAudit a = std::move(*pending_audit);
    pending_audit.reset();
    if (unsure()) return false;
    ++counts.audits;
    evidence = a.stamp;
    const std::optional<LossVerdict> loss =
        auditor->audit(a.stamp, a.prior, a.check, last_omni, odometry);
    if (!loss) return true;
    ++counts.second_opinions;
    ++counts.audit_losses;
    monitor.reset();
    lose(loss);
    if (unsure()) relocalize(a.stamp);
    return true;
  }

  // While tracking: the omni frame's lamps, matched near the estimate, as a pose measurement.
  // `checked`: the omni check judged the frame consistent; an update the check could not judge
  // that the filter's gate refuses is not taken as evidence of a kidnap (its matches are the
  // doubtful part).
  void omni_update(Stamp stamp, const FilterState& prior, bool checked) {
    const detail::EstimateSigmas s = detail::estimate_sigmas(prior);
    const std::optional<PoseHypothesis> h =
        global->refine(prior.pose(), s.position_m, s.yaw_rad, last_omni);
    if (!h || int(h->matches.size()) < o.omni_update_min_lamps || h->missing > h->expected / 2)
      return;
    // The least-squares covariance knows detection noise only; floor bumps add to it.
    Eigen::Matrix3d R = h->covariance;
    R.diagonal() += Eigen::Vector3d(0.06 * 0.06, 0.06 * 0.06, std::pow(0.15 * kDeg, 2));
    const UpdateResult u = ekf.update(stamp, h->pose, R);
    if (u.applied() || u.status == UpdateResult::Status::pending) ++counts.omni_updates;
    if (u.applied() || (checked && u.refusal == Refusal::gated))
      lose(monitor.innovation(u.mahalanobis2));
  }

  // A frame captured before the dead reckoning's first reading (the start, or odometry that stopped
  // and came back): no hypothesis can be carried to where it was taken, so it weighs none.
  bool before_odometry(Stamp stamp) {
    if (!odometry.empty() && stamp >= odometry.first_stamp()) return false;
    ++counts.frames_too_old;
    return true;
  }

  // A frame captured before a move the ceiling camera saw and the wheels did not.
  bool before_move(Stamp stamp) {
    if (!moved_after || stamp >= *moved_after) return false;
    ++counts.frames_before_move;
    return true;
  }

  // The ceiling camera saw a move the wheels did not (a lift): the places the drive allowed, and
  // every hypothesis carried by the wheels, are stale. While unsure they go, and the robot is
  // looked for from the frames captured since; while certain it is a kidnap alarm, the estimate
  // kept as one of the places (a false alarm then costs a few frames, never the pose).
  void moved_unseen(const ContinuityVerdict& v) {
    ++counts.unseen_moves;
    moved_after = v.moved_by;
    if (unsure()) {
      ++counts.unseen_moves_while_looking;
      hypotheses->clear(v.why);
      refresh_status();
      set_mode(LocalizerMode::lost, ModeCause::moved_unseen, v.why);
    } else {
      lose(LossVerdict{ModeCause::moved_unseen, v.why});
    }
  }

  // Odometry stopped and came back (or the clock jumped): where the robot went in between is not
  // known. Nothing from before can be carried across: the hypotheses go, dead reckoning starts
  // again from this reading, and the robot is looked for anew.
  void motion_unknown(double gap_s) {
    char why[120];
    std::snprintf(why, sizeof why,
                  "no wheel odometry for %.1f s: the motion in between is not known", gap_s);
    hypotheses->clear();
    odometry = OdometryTrack(o.ekf.semi_axis);
    if (continuity) continuity->reset();
    ++counts.odometry_gaps;
    if (unsure())
      set_mode(LocalizerMode::lost, ModeCause::odometry_gap, why);
    else
      lose(LossVerdict{ModeCause::odometry_gap, why}, false);
  }

  // `keep_estimate`: the estimate tracked until now stays one of the places the robot may be (a
  // false alarm then costs a few frames, never the pose); not when the motion since it is unknown
  // (odometry that stopped), where it would only be a likely-looking guess.
  void lose(const std::optional<LossVerdict>& loss, bool keep_estimate = true) {
    if (!loss || unsure()) return;
    if (keep_estimate && ekf.initialized())
      hypotheses->keep(ekf.stamp(), ekf.pose(), ekf.covariance(), odometry);
    refresh_status();  // not the last loss's verdict
    set_mode(LocalizerMode::lost, loss->cause, loss->why);
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
    if (ceiling_model) {
      std::vector<vision::LampDetection> seen;
      for (const auto& l : ob.lamps) seen.push_back(l.detection);
      e.expected_missing = static_cast<int>(unseen_lamps(*map, *ceiling_model, *ceiling_geometry,
                                                         *ceiling_kind, seen, prior.pose(), prior.P)
                                                .size());
    }
    e.inconsistent = ob.no_measurement == PoseRefusal::labels_disagree;
    if (unsure()) {
      ++counts.frames_while_lost;
      return;
    }
    if (ob.measurement) {
      const UpdateResult r =
          ekf.update(ob.measurement->stamp, ob.measurement->pose, ob.measurement->covariance);
      if (r.applied() || r.status == UpdateResult::Status::pending) {
        ++counts.measurements_applied;
        // One round lamp measures no heading, and its position (2.6 cm of noise under a 2.8 m
        // ceiling's discs) set the travel 0.8 to 1.5 % off on wheels that were right: the wheels
        // learn from poses only (docs/localization.md, "The wheels' travel").
        if (r.applied() && ob.measurement->heading_measured) {
          const PoseMeasurement& pm = *ob.measurement;
          calibration.heading(pm.stamp, pm.pose.yaw(), pm.covariance(2, 2));
          calibration.position(pm.stamp, pm.pose.x(), pm.pose.y(), pm.covariance(0, 0),
                               pm.covariance(0, 1), pm.covariance(1, 1));
        }
        if (mode == LocalizerMode::relocalized && r.applied())
          set_mode(LocalizerMode::tracking, ModeCause::confirmed,
                   "a ceiling measurement agrees with the relocalized pose");
      } else {
        ++counts.measurements_refused;
      }
      if (r.refusal == Refusal::gated) e.measurement_refused = true;
      if (r.applied() || r.refusal == Refusal::gated) lose(monitor.innovation(r.mahalanobis2));
      if (unsure()) return;
    }
    lose(monitor.ceiling(e));
  }
  static std::vector<vision::LampDetection> detections(const CeilingObservation& ob) {
    std::vector<vision::LampDetection> lamps;
    for (const auto& l : ob.lamps) lamps.push_back(l.detection);
    return lamps;
  }
  void check_continuity(Stamp stamp, const std::vector<vision::LampDetection>& lamps) {
    if (!continuity) return;
    // While the robot is looked for, a move must not hide in the floor's swing: the gates stay
    // as configured there (a false alarm then costs the hypotheses a few frames, never a pose).
    const ContinuityVerdict v = continuity->frame(stamp, lamps, odometry, unsure());
    if (frames_checked <= o.continuity.tilt_window) ++frames_checked;
    // The floor's swing as the frames show it: the models that follow a known pose weigh the
    // lamps with it (labelling, the pose measurement, the omni check, scaled alike: the omni
    // camera rides the same base). The hypotheses are weighed with the configured models
    // (weighed for the swing they made wrong fixes in a regular building, docs/localization.md);
    // only their newborns are held more loosely (HypothesisSetOptions::births_follow_swing) and
    // their margins to publish raised to the factor (publish_follows_swing).
    const double swing = continuity->tilt_sigma();
    const bool measured = swing_measured();
    if (swing != floor_swing || measured != floor_measured) {
      floor_swing = swing;
      floor_measured = measured;
      pipeline->set_floor_swing(swing);
      const double factor = swing_factor(swing);
      if (omni_check) omni_check->scale_tilt(factor);
      if (hypotheses) hypotheses->set_floor_swing(factor, publish_factor(factor), measured);
    }
    // The kidnap monitor's windows were weighed for a steadier floor than there is: once the
    // swing has grown by a quarter over the one they were weighed with, they start again.
    if (floor_swing > 1.25 * weighed_swing) {
      weighed_swing = floor_swing;
      monitor.reset();
    }
    if (v.broken) moved_unseen(v);
  }

  // A ceiling frame: an image, or the lamps an outside detector found in one (the pipeline
  // takes either). While unsure, its lamps weigh every hypothesis (labelled from the likeliest
  // place only so that the tracker keeps going).
  template <class Frame>
  const CeilingObservation& ceiling(Stamp stamp, const Frame& frame, Localizer& self) {
    if (!pipeline)
      throw InputError({"", "robot.json", "cameras"}, "the robot has no ceiling_camera");
    const auto process = [&](const Pose2& pose, const Eigen::Matrix3d& P) {
      return pipeline->process(stamp, frame, pose, P);
    };
    last_ceiling = CeilingObservation{};
    last_ceiling.stamp = stamp;
    evidence = stamp;
    const std::optional<FilterState> prior = self.prior_at(stamp);
    if (unsure()) {
      Pose2 pose;
      Eigen::Matrix3d P = Eigen::Vector3d(100, 100, 10).asDiagonal();
      const auto& hs = hypotheses->hypotheses();
      if (!hs.empty()) {
        const Hypothesis c = hypotheses->carried(hs.front(), stamp, odometry);
        pose = c.pose;
        P = c.covariance;
      } else if (prior) {
        pose = prior->pose();
        P = prior->P;
      }
      last_ceiling = process(pose, P);
      ++counts.ceiling_frames;
      ++counts.frames_while_lost;
      const std::vector<vision::LampDetection> lamps = detections(last_ceiling);
      check_continuity(stamp, lamps);
      if (hypotheses->hypotheses().empty()) return last_ceiling;
      if (before_odometry(stamp) || before_move(stamp)) return last_ceiling;
      hypotheses->ceiling(stamp, lamps, odometry);
      settle(stamp);
      return last_ceiling;
    }
    if (!prior) {
      ++counts.frames_too_old;
      last_ceiling.no_measurement_reason = "captured before the filter's history";
      return last_ceiling;
    }
    last_ceiling = process(prior->pose(), prior->P);
    check_continuity(stamp, detections(last_ceiling));
    observe(last_ceiling, *prior);
    return last_ceiling;
  }
};

Localizer::Localizer(const graph::TopologicalMap& map, const RobotDescription& robot,
                     const LocalizerOptions& options)
    : impl_(std::make_unique<Impl>(map, robot, options)) {}
Localizer::~Localizer() = default;
Localizer::Localizer(Localizer&&) noexcept = default;

void Localizer::initialize(Stamp stamp, const Pose2& pose, const Eigen::Matrix3d& P) {
  Impl& m = *impl_;
  m.pending_audit.reset();  // told where the robot is
  m.ekf.initialize(stamp, pose, P);
  m.monitor.reset();
  if (m.pipeline) m.pipeline->reset();
  m.hypotheses->clear();
  m.mode = LocalizerMode::tracking;
  m.evidence = stamp;
  m.events.push_back(
      {stamp, LocalizerMode::tracking, ModeCause::initialized, "initialized", stamp});
}

bool Localizer::initialized() const { return impl_->ekf.initialized(); }

std::optional<Refusal> Localizer::wheels(Stamp stamp, double left, double right) {
  Impl& m = *impl_;
  m.run_audit();
  m.evidence = stamp;
  ++m.counts.wheel_readings;
  // The first reading is the baseline (no motion); NaN or inf is refused by the filter.
  const auto [left0, right0] = m.last_wheels.value_or(std::pair{left, right});
  const double dl = left - left0, dr = right - right0;
  const auto [cl, cr] = m.calibration.correct(dl, dr);
  const bool gap = !m.odometry.empty() && stamp - m.odometry.last_stamp() > m.o.max_odometry_gap;
  const auto r = m.ekf.predict(stamp, cl, cr);
  if (gap) m.motion_unknown(to_seconds(stamp - m.odometry.last_stamp()));
  if (!r || *r == Refusal::not_initialized) {
    // Before the first pose the readings still count: relocalization dead-reckons with them.
    m.last_wheels = {left, right};
    if (!r) m.calibration.wheels(stamp, dl, dr);
    m.odometry.add(stamp, cl, cr);
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
  impl_->run_audit();
  return impl_->ceiling(stamp, image, *this);
}

const CeilingObservation& Localizer::ceiling_detections(
    Stamp stamp, const std::vector<vision::LampDetection>& lamps) {
  impl_->run_audit();
  return impl_->ceiling(stamp, lamps, *this);
}

void Localizer::ceiling_observation(const CeilingObservation& ob) {
  impl_->run_audit();
  impl_->evidence = ob.stamp;
  if (impl_->unsure()) {
    ++impl_->counts.frames_while_lost;  // labelled from a pose that is not known
    return;
  }
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
  omni_detection(stamp, m.omni_detector->detect(image));
  return m.last_omni;
}

void Localizer::omni_detection(Stamp stamp, const vision::OmniDetection& detection) {
  Impl& m = *impl_;
  if (!m.global) throw InputError({"", "robot.json", "cameras"}, "the robot has no omni_camera");
  m.run_audit();  // on the frame before this one
  m.last_omni = detection;
  m.last_omni_stamp = stamp;
  m.evidence = stamp;
  ++m.counts.omni_frames;
  if (m.unsure() || !m.ekf.initialized()) {
    m.relocalize(stamp);
    return;
  }
  if (m.last_omni_check && stamp - *m.last_omni_check < m.o.omni_check_period) return;
  const std::optional<FilterState> prior = prior_at(stamp);
  if (!prior) return;
  m.last_omni_check = stamp;
  const OmniCheckResult r = m.omni_check->check(prior->pose(), prior->P, m.last_omni.blobs);
  if (m.mode == LocalizerMode::relocalized && r.conclusive && r.consistent)
    m.set_mode(LocalizerMode::tracking, ModeCause::confirmed,
               "the omnidirectional view agrees with the relocalized pose");
  std::optional<LossVerdict> loss = m.monitor.omni(r);
  if (!loss && r.conclusive && !r.consistent) {
    loss = m.auditor->second_opinion(*prior, r, m.last_omni);
    if (loss) {
      ++m.counts.second_opinions;
      m.monitor.reset();
    }
  }
  m.lose(loss);
  if (m.unsure()) {
    m.relocalize(stamp);  // the frame that showed the loss shows where the robot is
    return;
  }
  // (A frame the check found inconsistent was asked the same already: second_opinion.)
  if (m.auditor->due(stamp) && !(r.conclusive && !r.consistent))
    m.pending_audit = Impl::PendingAudit{stamp, *prior, r};
  if (m.o.omni_update_min_lamps > 0 && (r.conclusive ? r.consistent : m.o.omni_update_unchecked))
    m.omni_update(stamp, *prior, r.conclusive);
}

bool Localizer::global_fix(const GlobalFix& fix) {
  impl_->pending_audit.reset();  // told where the robot is
  impl_->evidence = fix.stamp;
  return impl_->apply_fix(fix);
}

bool Localizer::audit() { return impl_->run_audit(); }

LocalizerEstimate Localizer::estimate() const {
  const Impl& m = *impl_;
  LocalizerEstimate e;
  e.mode = m.mode;
  e.stamp = m.now();
  if (m.ekf.initialized()) {
    e.pose = m.ekf.pose();
    e.covariance = m.ekf.covariance();
  }
  if (m.unsure()) {
    e.undecidable = m.relocalization.verdict == HypothesisVerdict::symmetric;
    e.why = m.relocalization.why;
    e.hypotheses = m.weighted(e.stamp);
    if (!e.hypotheses.empty()) {
      e.pose = e.hypotheses.front().pose;
      e.covariance = e.hypotheses.front().covariance;
    }
  }
  e.node = m.map->node_containing(e.pose.translation());
  return e;
}

LocalizerMode Localizer::mode() const { return impl_->mode; }
const vision::OmniDetection* Localizer::last_omni() const {
  return impl_->counts.omni_frames > 0 ? &impl_->last_omni : nullptr;
}
Stamp Localizer::last_omni_stamp() const { return impl_->last_omni_stamp; }
const RelocalizationStatus& Localizer::relocalization() const { return impl_->relocalization; }
const HypothesisSet& Localizer::hypotheses() const { return *impl_->hypotheses; }
const std::vector<LocalizerEvent>& Localizer::events() const { return impl_->events; }
const LocalizerCounts& Localizer::counts() const { return impl_->counts; }
const KidnapMonitor::Counts& Localizer::kidnap_counts() const { return impl_->monitor.counts(); }
const PoseEkf& Localizer::filter() const { return impl_->ekf; }
const CeilingContinuity* Localizer::continuity() const {
  return impl_->continuity ? &*impl_->continuity : nullptr;
}

const OdometryCalibration& Localizer::calibration() const { return impl_->calibration; }
bool Localizer::has_ceiling_camera() const { return impl_->pipeline.has_value(); }
bool Localizer::has_omni_camera() const { return impl_->omni_detector.has_value(); }

}  // namespace lampnav::fusion
