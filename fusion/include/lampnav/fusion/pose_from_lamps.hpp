#pragma once
// The robot pose measured from labelled lamps of one ceiling frame (paper 2, section 3): one
// rectangular lamp gives (x, y, yaw) up to the rectangle's 180-degree symmetry, resolved by the
// predicted yaw; one round lamp the position for a given heading; several lamps give a weighted
// least-squares pose. The covariance is propagated from the pixel noise of each detection through
// the geometry, plus the floor bumps' tilt, which moves every lamp of a frame alike and so is not
// averaged away by more lamps.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/ids.hpp"
#include "lampnav/core/pose2.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/fusion/ceiling_geometry.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::fusion {

struct PoseMeasurementOptions {
  double pixel_sigma = 0.3;                    // px, centre of a fully visible lamp
  double completed_pixel_sigma = 1.0;          // px, centre of a lamp completed at the border
  double orientation_sigma = 0.004;            // rad, axis of a fully visible lamp (about 0.25 deg)
  double completed_orientation_sigma = 0.015;  // rad, axis of a completed lamp
  double tilt_sigma = 0.0087;  // rad, camera swing on floor bumps (sim default 0.5 deg)
  double map_sigma = 0.005;    // m, survey error of a lamp's position in the map
  double consistency_probability = 0.9999;  // chi-square gate on the fit's residuals: beyond
                                            // it the lamps disagree (a mislabel), refused
  // One round lamp alone gives the robot's position for a given heading: measured as such
  // (heading_measured false), or refused (round_lamp_no_heading).
  bool round_lamp_position = true;
  void validate() const;  // throws InputError naming the field
};

struct LabelledLamp {
  const graph::Lamp* lamp = nullptr;
  vision::LampDetection detection;  // full or completed (partial views carry no pose)
};

struct PoseMeasurement {
  Stamp stamp;  // capture time of the frame
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  std::vector<LampId> lamps;
  double chi2 = 0;  // weighted squared residuals of the fit (0 for a single lamp)
  int dof = 0;      // residual degrees of freedom
  // False for one round lamp: `pose` is the predicted heading's point of the position-heading
  // line the lamp allows, and `covariance` is free along that line (its information is the
  // lamp's two degrees of freedom). Learn no heading from it.
  bool heading_measured = true;
};

// Why the lamps gave no pose.
enum class PoseRefusal {
  none,
  no_usable_lamp,
  round_lamp_no_heading,
  undetermined,
  labels_disagree
};

// Measures the pose; nullopt with `why` (words) and `refusal` (kind) when the lamps cannot give
// one. `camera` converts pixel sigmas to the normalized plane where each lamp is seen.
std::optional<PoseMeasurement> measure_pose(const CeilingGeometry& geometry,
                                            const vision::PinholeCamera& camera,
                                            const std::vector<LabelledLamp>& lamps,
                                            const Pose2& predicted, Stamp stamp,
                                            const PoseMeasurementOptions& options,
                                            std::string* why = nullptr,
                                            PoseRefusal* refusal = nullptr);

}  // namespace lampnav::fusion
