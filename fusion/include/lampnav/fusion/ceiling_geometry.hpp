#pragma once
// Where a map point appears to the ceiling camera from a robot pose, and back: the geometry shared
// by the lamp labeller and the pose measurement. Image positions are UNDISTORTED normalized
// coordinates (X/Z, Y/Z in the camera frame), the detector's output.

#include <Eigen/Core>
#include <optional>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"

namespace lampnav::fusion {

class CeilingGeometry {
 public:
  explicit CeilingGeometry(const CameraDescription& camera);

  // Normalized coordinates of map point `p` seen from `pose` (level floor), and their Jacobian
  // with respect to (x, y, yaw). nullopt when the point is not in front of the lens.
  std::optional<Eigen::Vector2d> predict(const Pose2& pose, const Eigen::Vector3d& p,
                                         Eigen::Matrix<double, 2, 3>* d_pose = nullptr) const;
  // Orientation in the normalized plane (rad, mod pi) of a horizontal lamp axis of map yaw
  // `lamp_yaw` through `p`, seen from `pose`.
  std::optional<double> predict_orientation(const Pose2& pose, const Eigen::Vector3d& p,
                                            double lamp_yaw) const;

  // The base-frame (x, y) of the point at height `z` above the floor seen at normalized
  // coordinates `n`, and its Jacobian with respect to n. nullopt when the ray does not reach it.
  std::optional<Eigen::Vector2d> base_point(const Eigen::Vector2d& n, double z,
                                            Eigen::Matrix2d* d_n = nullptr) const;
  // The base-frame direction (rad) of an image axis of orientation `orientation` through `n`,
  // for a horizontal line at height `z`.
  std::optional<double> base_direction(const Eigen::Vector2d& n, double orientation,
                                       double z) const;

  // d n / d (a, b) at normalized coordinates n for a small turn of the camera by a about its x
  // axis and b about its y axis (a floor bump): a lamp far off the axis moves further, by up to
  // 1 + |n|^2 times what one overhead does.
  static Eigen::Matrix2d tilt_jacobian(const Eigen::Vector2d& n);

  const Eigen::Matrix3d& mount_rotation() const { return R_; }
  const Eigen::Vector3d& mount_origin() const { return t_; }

 private:
  Eigen::Matrix3d R_;  // camera -> base
  Eigen::Vector3d t_;  // camera origin in base
};

}  // namespace lampnav::fusion
