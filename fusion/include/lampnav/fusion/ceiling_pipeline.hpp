#pragma once
// From a ceiling-camera frame to labelled lamps and a pose measurement (paper 2, section 3):
// detect and track the lamps (vision::LampTracker), give each new track the map lamp the
// odometry-predicted pose says it is (LampLabeller), measure the pose from the labelled lamps
// (measure_pose). Identical lamps are the normal case: a label comes from geometry, never looks.

#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <vector>

#include "lampnav/core/time.hpp"
#include "lampnav/fusion/pose_from_lamps.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "lampnav/vision/lamp_tracker.hpp"

namespace lampnav::fusion {

struct LabellerOptions {
  double gate_probability = 0.99;   // chi-square gate on the predicted centre and axis
  double pixel_sigma = 1.0;         // px, a detection's centre as far as labelling is concerned
  double orientation_sigma = 0.02;  // rad, its axis
  double tilt_sigma = 0.0087;       // rad, floor bumps
  double map_sigma = 0.005;         // m, survey error of the map's lamps
  double candidate_radius = 6.0;    // m, lamps considered when the pose is in no node's region
  // A lamp seen whole whose size (long and short side, from the moments at the lamp's height)
  // is off by more than this fraction is not that lamp: a strip light is not a round one.
  double shape_tolerance = 0.35;
  void validate() const;  // throws InputError naming the field
};

enum class LabelOutcome { labelled, no_candidate, ambiguous, partial_view };
const char* to_string(LabelOutcome outcome);

struct LabelResult {
  LabelOutcome outcome = LabelOutcome::no_candidate;
  const graph::Lamp* lamp = nullptr;
  double d2 = 0;       // squared Mahalanobis distance of the chosen lamp
  int in_gate = 0;     // candidates inside the gate
  int candidates = 0;  // lamps of the current and adjacent nodes that were tried
};

// Labels one detection with a map lamp from the predicted pose and its covariance: candidates are
// the lamps of the node the pose is in and of the nodes next to it; each is projected, gated by
// the innovation covariance H P H^T + R, and only a lone lamp inside the gate is accepted. A
// failed lamp is simply absent, so it cannot shift the labels of the ones after it.
class LampLabeller {
 public:
  LampLabeller(const graph::TopologicalMap& map, const CameraDescription& camera,
               const LabellerOptions& options = {});
  LabelResult label(const vision::LampDetection& detection, const Pose2& predicted,
                    const Eigen::Matrix3d& covariance, const std::set<LampId>& taken = {}) const;
  std::vector<const graph::Lamp*> candidates(const Pose2& predicted) const;
  // The floor bumps' tilt spread (rad), as learnt while driving (CeilingContinuity). Throws
  // InputError outside [0, 0.5).
  void set_tilt_sigma(double rad);

 private:
  const graph::TopologicalMap* map_;
  CeilingGeometry geometry_;
  vision::PinholeCamera model_;
  LabellerOptions o_;
  double gate_;
  double reach_m_;  // lamps this far from the robot may be in view
};

// The detector's shape prior from a map's lamps and the camera's height: the most common kind of
// lamp (shape and size) over the places routes go through (rooms left out, unless every lamp is
// in one), and the range of its lamps' heights above the camera. Throws InputError when the map
// has no lamp above the camera.
vision::LampShapePrior shape_prior_for(const graph::TopologicalMap& map,
                                       const CameraDescription& camera);
// Whether a detector with this prior looks for the lamp: the same shape and size (to the mm).
bool detects(const vision::LampShapePrior& prior, const graph::Lamp& lamp);

// Map lamps of the kind `detected` looks for that a pose (known within `covariance`) puts so
// well inside the image that, even 3 sigma off, they would be in full view, and near which
// nothing was detected. None when the pose is too uncertain (over 0.3 m) to say.
std::vector<const graph::Lamp*> unseen_lamps(const graph::TopologicalMap& map,
                                             const vision::PinholeCamera& camera,
                                             const CeilingGeometry& geometry,
                                             const vision::LampShapePrior& detected,
                                             const std::vector<vision::LampDetection>& lamps,
                                             const Pose2& pose, const Eigen::Matrix3d& covariance);

struct CeilingPipelineOptions {
  vision::LampDetectorOptions detector;
  vision::LampTrackerOptions tracker;
  LabellerOptions labeller;
  PoseMeasurementOptions measurement;
  void validate() const;
};

struct ObservedLamp {
  int track_id = 0;
  const graph::Lamp* lamp = nullptr;                  // null while unlabelled
  LabelOutcome outcome = LabelOutcome::no_candidate;  // of this frame's labelling attempt
  vision::LampDetection detection;
};

struct CeilingObservation {
  Stamp stamp;  // capture time
  std::vector<ObservedLamp> lamps;
  std::vector<int> ended_tracks;
  std::optional<PoseMeasurement> measurement;
  std::string no_measurement_reason;  // when lamps were seen but gave no measurement
  PoseRefusal no_measurement = PoseRefusal::none;
  vision::DetectionStats detection;
};

class CeilingPipeline {
 public:
  CeilingPipeline(const graph::TopologicalMap& map, const CameraDescription& camera,
                  const CeilingPipelineOptions& options = {});
  ~CeilingPipeline();
  CeilingPipeline(CeilingPipeline&&) noexcept;

  // One frame captured at `stamp`, with the pose predicted for that instant and its covariance.
  // Throws InputError for a frame that is not an image of the camera (nothing else changes).
  CeilingObservation process(Stamp stamp, const vision::ImageView& image, const Pose2& predicted,
                             const Eigen::Matrix3d& covariance);
  // Lamps found by an outside detector, untracked: each is labelled afresh (track id 0).
  CeilingObservation process(Stamp stamp, const std::vector<vision::LampDetection>& lamps,
                             const Pose2& predicted, const Eigen::Matrix3d& covariance);
  // Forgets the tracks and their labels (after a kidnap: the old labels are worthless).
  void reset();
  // The floor's swing learnt while driving (rad, CeilingContinuity): labelling and the pose
  // measurement each take the larger of their configured tilt_sigma and this from now on.
  // Throws InputError outside [0, 0.5).
  void set_floor_swing(double rad);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::fusion
