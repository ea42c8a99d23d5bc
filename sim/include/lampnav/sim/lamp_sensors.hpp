#pragma once
// What the lamp detectors report for a pose, without rendering: the working lamps projected
// through each camera's model and mount, with the detectors' noise. For batteries of thousands
// of frames (a hundred kidnaps on a building of a thousand nodes) where rendering and detecting
// every frame would take hours; the rendered path (renderers, detectors) is tested on its own.
//  - omni: one blob per lamp within the view (the detector's second threshold splits blooms
//    that touch), direction noise;
//  - ceiling: lamps wholly inside the image (full view), centre noise in pixels, axis noise.

#include <cstdint>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/sim/renderers.hpp"
#include "lampnav/vision/lamp_detector.hpp"
#include "lampnav/vision/omni_detector.hpp"

namespace lampnav::sim {

struct LampSensorOptions {
  double omni_sigma_deg = 0.1;                  // a blob's direction
  double omni_max_theta_deg = 88.0;             // blobs further off the axis are not reported
  double omni_halo = OmniRenderOptions{}.halo;  // a blob's radius / its lamp face's (IR bloom)
  double ceiling_sigma_px = 0.3;                // a lamp's centre
  double ceiling_orientation_sigma = 0.004;     // rad, its axis
  double bump_sigma_deg = 0.5;         // floor bumps: both cameras tilt alike in one instant
  std::set<std::string> failed_lamps;  // lamp ids that do not light
  void validate() const;               // throws InputError naming the field
};

class LampSensors {
 public:
  // Cameras the robot lacks report nothing. Throws InputError for bad options.
  LampSensors(const graph::TopologicalMap& map, const RobotDescription& robot,
              const LampSensorOptions& options = {});
  ~LampSensors();
  LampSensors(LampSensors&&) noexcept;

  vision::OmniDetection omni(const Pose2& pose, std::mt19937_64& rng) const;
  std::vector<vision::LampDetection> ceiling(const Pose2& pose, std::mt19937_64& rng) const;
  // How far (horizontally, m) the omni camera places the highest lamps within `tolerance_m`,
  // given its direction noise (3 sigma): the view the map oracle may fairly assume. A blob's
  // direction error d(theta) moves its lamp by h d(theta) / cos^2(theta) on the ceiling, so far
  // lamps, near the horizon, are seen but not placed. 0 without an omni camera.
  double omni_resolving_radius_m(double tolerance_m) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::sim
