#pragma once
// The localizer a robot runs: wheel readings, ceiling-camera frames (or labelled-lamp
// observations from an outside pipeline), omnidirectional frames (or their detections) and
// global fixes go in, in the order they arrive; out come the estimate at odometry rate, its
// covariance, the mode, the node of the map the robot is in, and, when it does not know, every
// place it may be with its weight. Frames arrive late (paper 2: about 1 s): each is labelled
// with the estimate at its capture time and applied there by the EKF.
//
// Modes:
//  - tracking: one pose holds the evidence; the EKF follows it.
//  - lost: the kidnap monitor says the estimate is not the robot (or the robot was never told
//    where it starts), and the places it may be are not all known yet: nothing is published as
//    certain.
//  - ambiguous: every place the cameras' evidence fits is a hypothesis (HypothesisSet), and
//    more than one still holds weight: "it is one of these", with the weights.
//  - relocalized: one hypothesis came to hold the evidence (posterior and likelihood ratio over
//    the runner-up, both options) and re-initialized the filter; the first accepted ceiling
//    measurement, or a consistent omni check, confirms it and the mode returns to tracking.
// A regular building (identical corridors and lamps) is the normal case: a pose is never
// published as certain while a look-alike place explains the same images.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/localizer_mode.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/fusion/ceiling_continuity.hpp"
#include "lampnav/fusion/ceiling_pipeline.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/hypothesis_set.hpp"
#include "lampnav/fusion/kidnap_monitor.hpp"
#include "lampnav/fusion/odometry_calibration.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/vision/image_view.hpp"
#include "lampnav/vision/omni_detector.hpp"

namespace lampnav::fusion {

// The mode and its word live in core (localizer_mode.hpp): the mission log records them too.
using lampnav::is_certain;
using lampnav::LocalizerMode;
using lampnav::to_string;

struct LocalizerOptions {
  EkfOptions ekf;                          // semi_axis is taken from robot.json
  OdometryCalibrationOptions calibration;  // likewise
  CeilingPipelineOptions ceiling;
  vision::OmniDetectorOptions omni_detector;
  OmniCheckOptions omni_check;
  KidnapMonitorOptions kidnap;
  Duration omni_check_period = std::chrono::seconds(1);  // the low-rate omni check
  GlobalLocalizerOptions global;                         // relocalization from omni frames
  HypothesisSetOptions hypotheses;                       // where the robot may be while unsure
  // Ceiling frames held against the last one through the wheels: a move they did not see (a
  // lift) makes every place the drive allowed stale (ceiling_continuity.hpp).
  CeilingContinuityOptions continuity;
  // While tracking, a consistent omni frame refines the estimate's pose on the lamps it matched
  // and is applied as a measurement (at least this many lamps; 0 turns it off).
  int omni_update_min_lamps = 4;
  // The same when the omni check cannot judge the frame (fewer than its min_expected lamps within
  // its 75 degrees: round lamps 4.5 m apart, panels 3 m apart, a corridor's end). The refinement
  // matches lamps out to 88 degrees, and where the wheels alone carried the heading 8 degrees off
  // over 9 m between discs it holds it (docs/localization.md). Such an update that the filter's
  // gate refuses is not counted as a kidnap's evidence.
  bool omni_update_unchecked = true;
  // One omni check that disagrees with the estimate is not yet a loss (people hide lamps). It is
  // when the same frame locates the robot elsewhere (farther than second_opinion_distance) with
  // this likelihood ratio over the estimate, both scored alike: the frame then proves the jump
  // and the robot is looked for at once (the estimate stays one of the places it may be). 0 off.
  double second_opinion_ratio = 1000;
  double second_opinion_distance = 1.0;  // m
  // The same question asked of an omni frame at least this long after the last one asked, while
  // the estimate is certain, whatever the omni check said. A robot put down in a look-alike spot
  // (a corridor of the same lamps, at the same phase between two of them, turned so that the
  // lamps it had in view fit again) passes every local check: the ceiling camera sees the lamp
  // where the wheels put it and the omni check's near lamps are where the estimate predicts
  // them; only the lamps further off, which the whole frame's search weighs, tell the twin
  // apart. Each audit costs one global search (docs/localization.md, "Audits"). 0 off. The
  // search of a regular ceiling is cut short (look-alike places tie near the zenith) and finds
  // the true place in some images only. Carries into the office's twin corridors went unnoticed
  // for 1.1 to 81 s with audits every 5 s that did not add up, 1.1 to 21.5 s every 2 s adding up,
  // 1.1 to 17.5 s every 1 s, 1.1 to 6.5 s every 2 s weighing the building's own look-alikes too
  // (16 drives carried twice, docs/localization.md, "Audits that add up").
  Duration audit_period = std::chrono::seconds(2);
  // The likelihood ratio an audit needs, far above the second opinion's: nothing local doubts
  // the estimate then. Measured: places likelier than a right estimate by at most e^10.4 (a map
  // of part of the building), than a wrong one by e^57.5 to e^79.4. e^30 is about 1e13.
  double audit_ratio = 1e13;
  // Audits add up. A place more than second_opinion_distance away that an audit finds likelier
  // than the estimate by audit_step_ratio or more (short of audit_ratio), the challenger, is
  // carried by the wheels and weighed against the estimate in each omni frame that follows,
  // refined on it; the images taken at least HypothesisSetOptions::station_m apart add up, and
  // reaching audit_ratio calls the robot lost. A frame where it is the less likely clears it, as
  // do audit_challenge_frames frames short of audit_ratio. A carry into the office's twin
  // corridor (its half turn, or the corridor across it) shows only the rooms that differ: e^9 to
  // e^28 an image, seldom e^30 in one (docs/localization.md, "Audits that add up"). 1000 is
  // e^6.9, publish_ratio's figure.
  double audit_step_ratio = 1000;
  int audit_challenge_frames = 10;
  // Each audit also weighs the places the building's own look-alikes carry the estimate to: the
  // rigid motions of the map that carry at least audit_look_alike_fraction of its lamps onto
  // lamps alike (a regular office's half turn, slides along its rows of lamps), at most
  // audit_look_alikes of them, each place refined on the frame (docs/localization.md, "The
  // building's own look-alikes"). The search alone often misses them: it is cut short where
  // look-alike places tie. 0 off.
  int audit_look_alikes = 24;
  double audit_look_alike_fraction = 0.5;
  // Wheel readings further apart than this (odometry that stopped and came back, a clock that
  // jumped) leave the motion in between unknown: the estimate is no longer certain, and the
  // localizer looks for the robot again (keeping the estimate as one of the places it may be).
  Duration max_odometry_gap = std::chrono::seconds(2);
  void validate() const;
};

// A pose from global localization (or from a person), captured at `stamp`.
struct GlobalFix {
  Stamp stamp;
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  std::string source;  // "omni", "operator", ...
};

// One place the robot may be, with its share of the evidence.
struct WeightedPose {
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  double weight = 0;
  const graph::Node* node = nullptr;
};

struct LocalizerEstimate {
  Stamp stamp;
  Pose2 pose;  // lost or ambiguous: the most likely hypothesis (or the last estimate), NOT a fix
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  LocalizerMode mode = LocalizerMode::tracking;
  const graph::Node* node = nullptr;     // the node whose region holds the pose, if any
  std::vector<WeightedPose> hypotheses;  // lost or ambiguous: every place it may be, best first
  bool undecidable = false;              // ambiguous between symmetry twins: no motion can decide
  std::string why;                       // lost or ambiguous: why, in words
  bool known() const { return is_certain(mode); }
};

struct LocalizerEvent {
  Stamp stamp;  // when it happened (arrival time of the evidence)
  LocalizerMode mode;
  ModeCause cause;     // what programs act on
  std::string reason;  // the same for a person, with the evidence's figures
  // Capture time of the input it rests on (the frame, wheel reading or fix being taken in): a
  // fix made from a frame captured before the robot was carried knew nothing of the carry.
  Stamp evidence;
};

// Inputs the localizer did not use, by reason (besides the EKF's own refusals).
struct LocalizerCounts {
  std::uint64_t wheel_readings = 0, ceiling_frames = 0, omni_frames = 0, global_fixes = 0;
  std::uint64_t frames_too_old = 0;     // captured before the filter's history
  std::uint64_t frames_while_lost = 0;  // processed for evidence only
  std::uint64_t measurements_applied = 0, measurements_refused = 0;
  std::uint64_t fixes_refused = 0;
  std::uint64_t wheel_rebaselined = 0;      // after a refused jump, the new reading is the baseline
  std::uint64_t relocalization_frames = 0;  // omni frames given to the global localizer
  std::uint64_t ambiguous_frames = 0;       // of those, leaving several hypotheses
  std::uint64_t omni_updates = 0;           // omni pose measurements applied while tracking
  std::uint64_t odometry_gaps = 0;          // wheel readings further apart than max_odometry_gap
  std::uint64_t second_opinions = 0;  // losses an omni frame proved by locating the robot elsewhere
  std::uint64_t audits = 0;           // omni frames asked where the robot is while tracking
  std::uint64_t audit_losses = 0;     // of those, the losses an audit proved (in second_opinions)
  std::uint64_t unseen_moves = 0;     // ceiling frames that saw a move the wheels did not
  std::uint64_t unseen_moves_while_looking = 0;  // of those, while the robot was looked for
  std::uint64_t frames_before_move = 0;  // captured before such a move: weighed no hypothesis
};

// Where relocalization stands: the hypotheses and why they do not settle it yet.
struct RelocalizationStatus {
  HypothesisVerdict verdict = HypothesisVerdict::empty;
  std::vector<WeightedPose> hypotheses;  // at the last frame that weighed them, best first
  std::string why;                       // why there is no fix yet ("" once fixed)
};

class Localizer {
 public:
  // Throws InputError when the robot lacks a camera it needs or options are bad. Cameras missing
  // from robot.json (no "ceiling_camera", no "omni_camera") simply disable that input.
  Localizer(const graph::TopologicalMap& map, const RobotDescription& robot,
            const LocalizerOptions& options = {});
  ~Localizer();
  Localizer(Localizer&&) noexcept;

  // The starting pose (tracking). Throws InputError for a non-finite pose or a bad covariance.
  void initialize(Stamp stamp, const Pose2& pose, const Eigen::Matrix3d& covariance);
  bool initialized() const;

  // Cumulative travel of each wheel (m), read at `stamp`. Returns the EKF's refusal, if any.
  std::optional<Refusal> wheels(Stamp stamp, double left, double right);
  // A ceiling-camera frame captured at `stamp`. Throws InputError for a frame that is not an
  // image of the camera; nothing changes then.
  const CeilingObservation& ceiling_frame(Stamp stamp, const vision::ImageView& image);
  // The lamps of a ceiling frame found by an outside detector (untracked: labelled afresh).
  const CeilingObservation& ceiling_detections(Stamp stamp,
                                               const std::vector<vision::LampDetection>& lamps);
  // An observation made by an outside ceiling pipeline (labelled with prior_at(stamp)).
  void ceiling_observation(const CeilingObservation& observation);
  // An omnidirectional frame captured at `stamp`: detected, kept for relocalization, and (at
  // most once per omni_check_period, while tracking) checked against the estimate.
  const vision::OmniDetection& omni_frame(Stamp stamp, const vision::ImageView& image);
  // The same with the frame's detections (from an outside detector, or a test).
  void omni_detection(Stamp stamp, const vision::OmniDetection& detection);
  // The audit an omni frame left due (LocalizerOptions::audit_period): one global search, work
  // that can wait until the frame's pose is out. Every other input runs it first, so a caller
  // that never calls this still has its frames audited, one input later. True when one ran.
  bool audit();
  // A relocalized pose: re-initializes state and covariance at its capture time and re-applies
  // the odometry since. False (and counted) when it is older than the history or not finite.
  bool global_fix(const GlobalFix& fix);

  LocalizerEstimate estimate() const;
  // The filter's estimate at an earlier instant (a frame's capture time), if in its history.
  std::optional<FilterState> prior_at(Stamp stamp) const;
  LocalizerMode mode() const;
  bool relocalization_requested() const { return mode() == LocalizerMode::lost; }
  const RelocalizationStatus& relocalization() const;
  const HypothesisSet& hypotheses() const;
  // The latest omni detection and its capture stamp.
  const vision::OmniDetection* last_omni() const;
  Stamp last_omni_stamp() const;
  // Mode changes with their reasons, in order.
  const std::vector<LocalizerEvent>& events() const;
  const LocalizerCounts& counts() const;
  const KidnapMonitor::Counts& kidnap_counts() const;
  const PoseEkf& filter() const;
  const OdometryCalibration& calibration() const;
  // The ceiling frames held against one another (the floor's swing it learnt among them); null
  // without a ceiling camera or with continuity off.
  const CeilingContinuity* continuity() const;
  bool has_ceiling_camera() const;
  bool has_omni_camera() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::fusion
