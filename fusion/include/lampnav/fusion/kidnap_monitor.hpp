#pragma once
// Is the estimate still the robot? After a kidnap the ceiling camera may simply find no map lamp
// where it looks, so refused measurements are not enough. The monitor weighs four kinds of
// evidence, each cheap and each counted:
//  - lamps seen in full view where the map (through the estimate) predicts none,
//  - map lamps the estimate puts well inside the view that are not seen,
//  - a run of measurements that do not fit: the normalised innovations (NIS) of the last N
//    measurements summed and tested against the chi-square quantile with 3N degrees of freedom,
//  - a low-rate check of the omnidirectional view: the lamps the estimate predicts overhead
//    against the blobs the omni camera sees.
// Lamps fail and people hide lamps: a missing lamp alone never declares the robot lost.

#include <Eigen/Core>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/vision/omni_detector.hpp"

namespace lampnav::fusion {

// Why the localizer's mode changed, for programs to act on; the event's text says the same to a
// person. The kidnap monitor gives the first three, the localizer the rest.
enum class ModeCause {
  ceiling_contradicts,     // ceiling frames contradict the map (lamps where it has none, or none
                           // where it has them)
  innovations_do_not_fit,  // the measurements' NIS over a window exceeds its chi-square bound
  omni_disagrees,          // omni checks in a row do not match the estimate
  omni_locates_elsewhere,  // one omni check disagrees and the frame locates the robot far away,
                           // far likelier (the second opinion)
  odometry_gap,            // no wheel odometry for too long: the motion in between is unknown
  moved_unseen,            // the ceiling camera saw a move the wheels did not (a lift)
  hypotheses_undecided,    // lost or ambiguous: the hypotheses do not settle it yet
  initialized,             // a start pose was given
  global_fix,              // relocalized: one hypothesis holds, or a fix from outside
  confirmed,               // a measurement agrees with the relocalized pose: tracking again
};
const char* to_string(ModeCause cause);

// A loss the evidence shows: its cause, and the same in words.
struct LossVerdict {
  ModeCause cause = ModeCause::ceiling_contradicts;
  std::string why;
};

struct KidnapMonitorOptions {
  int window_frames = 10;             // ceiling frames in the sliding window (1 s at 10 Hz)
  int contradicting_frames = 4;       // frames with a contradiction in the window that mean lost
  int missing_support_frames = 4;     // frames with expected lamps missing that, with two
                                      // contradicting frames, also mean lost
  int nis_window = 8;                 // measurements in the NIS window test
  double nis_probability = 0.9999;    // its chi-square quantile (3 * nis_window dof)
  int omni_failures = 2;              // consecutive inconsistent omni checks that mean lost
  int omni_strong_expected = 4;       // a check with at least this many blobs ...
  double omni_strong_fraction = 0.5;  // ... of which at most this fraction are explained (and
                                      // as few predicted lamps seen) means lost at once
  void validate() const;              // throws InputError naming the field
};

// What one ceiling frame says about the estimate it was labelled with.
struct CeilingEvidence {
  Stamp stamp;
  int lamps_in_view = 0;     // detections in full (or completed) view
  int labelled = 0;          // of those, with a map lamp
  int unexplained = 0;       // in full view, and no map lamp inside the gate
  int expected_missing = 0;  // map lamps the estimate puts well inside the view, nothing near
  bool measurement_refused = false;  // its pose measurement failed the filter's gate
  bool inconsistent = false;         // labelled lamps that do not agree with each other
  bool contradicts() const { return unexplained > 0 || measurement_refused || inconsistent; }
};

struct OmniCheckOptions {
  double max_theta_deg = 75;         // lamps and blobs used: at most this far off the axis
  double detection_sigma_deg = 0.3;  // a blob centroid's direction
  double tilt_sigma_deg = 0.6;       // floor bumps swing the camera
  double max_position_sigma = 0.5;   // m; with more uncertainty the check says nothing
  int min_expected = 3;              // fewer clear lamps predicted (and fewer blobs seen):
                                     // inconclusive
  double min_match_fraction = 0.5;   // below (for lamps, or for blobs): inconsistent
  // Count the blobs no lamp explains whose rays meet the ceiling beyond every place of the map
  // (off: they say nothing, as a map of part of a building says nothing there).
  bool count_beyond_map = false;
  void validate() const;
};

struct OmniCheckResult {
  bool conclusive = false;
  bool consistent = true;
  bool lamp_side = false, blob_side = false;  // enough predicted lamps / seen blobs to judge
  int expected = 0;         // clear lamps the estimate predicts in the used part of the view
  int matched = 0;          // of those, with a blob in the expected direction (one-to-one)
  int blobs = 0;            // blobs in the used part of the view
  int explained_blobs = 0;  // of those, in the direction of some map lamp
  int beyond_map = 0;       // blobs no map lamp explains whose ray meets the ceiling beyond
                            // every place (left out of `blobs`: the map says nothing there)
  double match_fraction() const { return expected ? double(matched) / expected : 0.0; }
  double explained_fraction() const { return blobs ? double(explained_blobs) / blobs : 1.0; }
};

// The omni view against an estimate: predicted lamp directions matched one-to-one to blob rays
// within a tolerance from the detection noise, the floor bumps and the estimate's covariance.
// Lamps whose directions crowd each other are left out (their blobs merge).
class OmniCheck {
 public:
  OmniCheck(const graph::TopologicalMap& map, const CameraDescription& omni_camera,
            const OmniCheckOptions& options = {});
  OmniCheckResult check(const Pose2& pose, const Eigen::Matrix3d& covariance,
                        const std::vector<vision::OmniBlob>& blobs) const;
  // The floor swings the camera `factor` (>= 1) times as much as configured (learnt while
  // driving, CeilingContinuity): tilt_sigma_deg becomes the configured one times it. Throws
  // InputError for a factor below 1 or not finite.
  void scale_tilt(double factor);

 private:
  const graph::TopologicalMap* map_;
  Eigen::Matrix3d mount_R_;
  Eigen::Vector3d mount_t_;
  OmniCheckOptions o_;
  double configured_tilt_deg_;
  std::vector<const graph::Lamp*> lamps_;
  double lamp_height_ = 0;  // the median lamp's above the camera, where a blob's ray meets the
                            // ceiling
  // The smallest a lamp's blob can be, per unit of cos(theta): half the smallest lamp size seen
  // from the highest lamp's height above the camera. A smaller blob is a spurious light.
  double min_blob_per_cos_ = 0;  // spurious_blobs.hpp
};

class KidnapMonitor {
 public:
  explicit KidnapMonitor(const KidnapMonitorOptions& options = {});
  // Each returns why the robot is lost, once the evidence says so.
  std::optional<LossVerdict> ceiling(const CeilingEvidence& evidence);
  std::optional<LossVerdict> innovation(double mahalanobis2);
  std::optional<LossVerdict> omni(const OmniCheckResult& result);
  // Forgets the evidence (after relocalization).
  void reset();

  // Counters over the mission.
  struct Counts {
    std::uint64_t frames = 0, contradicting_frames = 0, unexplained_lamps = 0, missing_lamps = 0,
                  refused_measurements = 0, nis_alarms = 0, omni_checks = 0, omni_inconsistent = 0,
                  losses = 0;
  };
  const Counts& counts() const { return counts_; }

 private:
  KidnapMonitorOptions o_;
  double nis_limit_;
  std::deque<CeilingEvidence> window_;
  std::deque<double> nis_;
  double nis_sum_ = 0;
  int omni_bad_ = 0;
  Counts counts_;
};

}  // namespace lampnav::fusion
