#pragma once
// A planar rigid transform: the pose (x, y, yaw) of one frame in another (conventions.md).

#include <Eigen/Core>
#include <iosfwd>

namespace lampnav {

// Wraps an angle to (-pi, pi] (conventions.md: angles are wrapped to that interval).
double wrap_angle(double a);
// Wraps the angle of an undirected axis (a lamp's long side) to (-pi/2, pi/2].
double wrap_axis_angle(double a);

class Pose2 {
 public:
  Pose2() = default;
  Pose2(double x, double y, double yaw);
  Pose2(const Eigen::Vector2d& t, double yaw);

  double x() const { return t_.x(); }
  double y() const { return t_.y(); }
  double yaw() const { return yaw_; }
  const Eigen::Vector2d& translation() const { return t_; }
  Eigen::Matrix2d rotation() const;
  Eigen::Vector3d vector() const { return {t_.x(), t_.y(), yaw_}; }

  // this * other: first this transform, then other expressed in this frame.
  Pose2 compose(const Pose2& other) const;
  Pose2 operator*(const Pose2& other) const { return compose(other); }
  Pose2 inverse() const;
  // The pose of `other` seen from this frame: inverse() * other.
  Pose2 between(const Pose2& other) const;

  // Maps a point given in this frame into the parent frame, and back.
  Eigen::Vector2d transform_from(const Eigen::Vector2d& p) const;
  Eigen::Vector2d transform_to(const Eigen::Vector2d& p) const;

  static Pose2 identity() { return {}; }

 private:
  Eigen::Vector2d t_ = Eigen::Vector2d::Zero();
  double yaw_ = 0.0;
};

// Linear interpolation between two poses, the yaw along the shorter arc: f = 0 gives a, 1 gives b.
// The one interpolation of poses (dead reckoning between readings, the truth between samples).
Pose2 interpolate(const Pose2& a, const Pose2& b, double f);

std::ostream& operator<<(std::ostream& os, const Pose2& p);

}  // namespace lampnav
