#pragma once
// Camera renderers of the simulated world: what the ceiling webcam (pinhole with distortion) and
// the IR-filtered omnidirectional camera (Pajdla-Bakstein) would see from a true pose.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "lampnav/core/image.hpp"
#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::sim {

// The swing of the cameras when a wheel rolls over a floor irregularity (paper 1).
struct CameraTilt {
  double roll = 0, pitch = 0;  // rad, of the robot body
};

// The pose of a camera in the map: rotation (camera -> map) and optical centre.
struct CameraPose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d to_camera(const Eigen::Vector3d& p_map) const {
    return rotation.transpose() * (p_map - origin);
  }
};
CameraPose camera_pose(const Pose2& robot, const CameraTilt& tilt, const Mount& mount);

struct CeilingRenderOptions {
  double background = 10.0;    // grey level of the dark ceiling
  double lamp_level = 235.0;   // grey level of a lamp's face at exposure 1
  double fringe_level = 60.0;  // grey level of the metallic-grid fringe, at the image border
  double fringe_width = 0.04;  // m, width of the fringe band around the light
  double noise_sigma = 2.0;    // grey levels, sensor noise
  double exposure = 1.0;       // gain on the light
  int supersample = 4;         // samples per pixel side (anti-aliasing)
  void validate() const;       // throws InputError naming the field
};

class CeilingRenderer {
 public:
  CeilingRenderer(const CameraDescription& camera, CeilingRenderOptions options);
  ~CeilingRenderer();
  CeilingRenderer(CeilingRenderer&&) noexcept;

  Image8 render(const Pose2& robot, const CameraTilt& tilt,
                const std::vector<const graph::Lamp*>& lamps, std::mt19937_64& rng) const;
  // The pixel where a map point projects (for tests and labels).
  std::optional<Eigen::Vector2d> project(const Pose2& robot, const CameraTilt& tilt,
                                         const Eigen::Vector3d& p_map) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The radius (m) of a disc of a lamp's face: a disc lamp's own, a rectangle's of equal area. The
// omni camera's IR bloom grows a blob from it (OmniRenderOptions::halo).
double lamp_face_radius(const graph::Lamp& lamp);

struct OmniRenderOptions {
  double background = 8.0;              // grey level
  double peak = 255.0;                  // a lamp's core saturates the IR-filtered sensor
  double halo = 1.6;                    // blob radius / lamp face's angular radius (IR bloom)
  double near_bloom_m = 2.5;            // lamps closer than this get a large saturated halo
  double min_radius_px = 1.5;           // smallest blob radius
  double noise_sigma = 3.0;             // grey levels
  double occlusion_probability = 0.08;  // per lamp more than 50 deg off-axis: hidden by people
  double spurious_per_image = 0.3;      // expected spurious lights (windows, reflections) per image
  void validate() const;
};

class OmniRenderer {
 public:
  OmniRenderer(const CameraDescription& camera, OmniRenderOptions options);
  Image8 render(const Pose2& robot, const CameraTilt& tilt,
                const std::vector<const graph::Lamp*>& lamps, std::mt19937_64& rng) const;
  std::optional<Eigen::Vector2d> project(const Pose2& robot, const CameraTilt& tilt,
                                         const Eigen::Vector3d& p_map) const;

 private:
  CameraDescription cam_;
  OmniRenderOptions o_;
};

}  // namespace lampnav::sim
