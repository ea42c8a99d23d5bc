#pragma once
// The localizer a robot runs: wheel readings, ceiling-camera frames (or labelled-lamp
// observations from an outside pipeline), omnidirectional frames and global fixes go in, in the
// order they arrive; out come the estimate at odometry rate, its covariance, the mode and the
// node of the map the robot is in. Frames arrive late (paper 2: about 1 s): each is labelled
// with the estimate at its capture time and applied there by the EKF.
//
// Modes: tracking (the estimate is trusted), lost (the kidnap monitor says the estimate is not
// the robot: relocalization is requested, camera measurements are not applied), relocalized (a
// global fix re-initialized the filter; the first accepted ceiling measurement, or a consistent
// omni check, confirms it and the mode returns to tracking).
//
// Relocalization: while lost (or before any pose is known), each omni frame goes to the global
// localizer. One hypothesis is a fix at once. Several (a symmetric ceiling) are kept as
// candidates, each carried to the next omni frame by odometry and scored again there; when one
// stands clearly ahead of the others it becomes the fix.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/fusion/ceiling_pipeline.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/kidnap_monitor.hpp"
#include "lampnav/fusion/odometry_calibration.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/vision/image_view.hpp"
#include "lampnav/vision/omni_detector.hpp"

namespace lampnav::fusion {

enum class LocalizerMode { tracking, lost, relocalized };
const char* to_string(LocalizerMode mode);

struct LocalizerOptions {
  EkfOptions ekf;                          // semi_axis is taken from robot.json
  OdometryCalibrationOptions calibration;  // likewise
  CeilingPipelineOptions ceiling;
  vision::OmniDetectorOptions omni_detector;
  OmniCheckOptions omni_check;
  KidnapMonitorOptions kidnap;
  Duration omni_check_period = std::chrono::seconds(1);  // the low-rate omni check
  GlobalLocalizerOptions global;                         // relocalization from omni frames
  // While tracking, a consistent omni frame refines the estimate's pose on the lamps it matched
  // and is applied as a measurement (at least this many lamps; 0 turns it off).
  int omni_update_min_lamps = 4;
  // Odometry drift allowed when carrying a candidate to the next omni frame.
  double candidate_sigma_m = 0.15, candidate_sigma_per_m = 0.05;
  double candidate_sigma_yaw_deg = 3.0;
  void validate() const;
};

// A pose from global localization (or from a person), captured at `stamp`.
struct GlobalFix {
  Stamp stamp;
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  std::string source;  // "omni", "operator", ...
};

struct LocalizerEstimate {
  Stamp stamp;
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  LocalizerMode mode = LocalizerMode::tracking;
  const graph::Node* node = nullptr;  // the node whose region holds the pose, if any
};

struct LocalizerEvent {
  Stamp stamp;  // when it happened (arrival time of the evidence)
  LocalizerMode mode;
  std::string reason;
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
  std::uint64_t ambiguous_frames = 0;       // of those, with several candidates left
  std::uint64_t omni_updates = 0;           // omni pose measurements applied while tracking
};

// Where relocalization stands: the candidates kept and why the last frame did not settle it.
struct RelocalizationStatus {
  std::vector<PoseHypothesis> candidates;  // at the last omni frame, best first
  std::string why;                         // why there is no fix yet ("" once fixed)
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
  // An observation made by an outside ceiling pipeline (labelled with prior_at(stamp)).
  void ceiling_observation(const CeilingObservation& observation);
  // An omnidirectional frame captured at `stamp`: detected, kept for relocalization, and (at
  // most once per omni_check_period, while tracking) checked against the estimate.
  const vision::OmniDetection& omni_frame(Stamp stamp, const vision::ImageView& image);
  // A relocalized pose: re-initializes state and covariance at its capture time and re-applies
  // the odometry since. False (and counted) when it is older than the history or not finite.
  bool global_fix(const GlobalFix& fix);

  LocalizerEstimate estimate() const;
  // The filter's estimate at an earlier instant (a frame's capture time), if in its history.
  std::optional<FilterState> prior_at(Stamp stamp) const;
  LocalizerMode mode() const;
  bool relocalization_requested() const { return mode() == LocalizerMode::lost; }
  const RelocalizationStatus& relocalization() const;
  // The latest omni detection and its capture stamp.
  const vision::OmniDetection* last_omni() const;
  Stamp last_omni_stamp() const;
  // Mode changes with their reasons, in order.
  const std::vector<LocalizerEvent>& events() const;
  const LocalizerCounts& counts() const;
  const KidnapMonitor::Counts& kidnap_counts() const;
  const PoseEkf& filter() const;
  const OdometryCalibration& calibration() const;
  bool has_ceiling_camera() const;
  bool has_omni_camera() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::fusion
