#include "lampnav/fusion/ceiling_geometry.hpp"

#include <cmath>

namespace lampnav::fusion {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

CeilingGeometry::CeilingGeometry(const CameraDescription& camera)
    : R_(camera.mount.rotation()), t_(camera.mount.xyz) {}

std::optional<Vector2d> CeilingGeometry::predict(const Pose2& pose, const Vector3d& p,
                                                 Eigen::Matrix<double, 2, 3>* d_pose) const {
  const double c = std::cos(pose.yaw()), s = std::sin(pose.yaw());
  const Vector3d d(p.x() - pose.x(), p.y() - pose.y(), p.z());
  // Map -> base: rotate by -yaw.
  const Vector3d b(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
  const Vector3d q = R_.transpose() * (b - t_);
  if (!(q.z() > 1e-9)) return std::nullopt;
  const Vector2d n(q.x() / q.z(), q.y() / q.z());
  if (d_pose) {
    Eigen::Matrix<double, 3, 3> db;  // d b / d (x, y, yaw)
    db.col(0) = Vector3d(-c, s, 0);
    db.col(1) = Vector3d(-s, -c, 0);
    db.col(2) = Vector3d(-s * d.x() + c * d.y(), -c * d.x() - s * d.y(), 0);
    Eigen::Matrix<double, 2, 3> dn;  // d n / d q
    dn << 1 / q.z(), 0, -n.x() / q.z(), 0, 1 / q.z(), -n.y() / q.z();
    *d_pose = dn * R_.transpose() * db;
  }
  return n;
}

std::optional<double> CeilingGeometry::predict_orientation(const Pose2& pose, const Vector3d& p,
                                                           double lamp_yaw) const {
  // Image of a short piece of the axis; the orientation is that of its image.
  const double h = 0.05;
  const Vector3d e(std::cos(lamp_yaw) * h, std::sin(lamp_yaw) * h, 0);
  const auto a = predict(pose, p + e), b = predict(pose, p - e);
  if (!a || !b) return std::nullopt;
  const Vector2d d = *a - *b;
  return std::atan2(d.y(), d.x());
}

std::optional<Vector2d> CeilingGeometry::base_point(const Vector2d& n, double z,
                                                    Eigen::Matrix2d* d_n) const {
  const Vector3d ray = R_ * Vector3d(n.x(), n.y(), 1.0);
  if (!(ray.z() > 1e-9)) return std::nullopt;
  const double k = (z - t_.z()) / ray.z();
  if (!(k > 0)) return std::nullopt;
  if (d_n) {
    // p = t + k(n) ray(n), k = (z - tz) / ray_z: dp/dn_i = k (R_i - ray R_zi / ray_z).
    for (int i = 0; i < 2; ++i) {
      const Vector3d dr = R_.col(i);
      const Vector3d dp = k * (dr - ray * (dr.z() / ray.z()));
      d_n->col(i) = dp.head<2>();
    }
  }
  return (t_ + k * ray).head<2>();
}

std::optional<double> CeilingGeometry::base_direction(const Vector2d& n, double orientation,
                                                      double z) const {
  const double h = 1e-3;
  const Vector2d e(std::cos(orientation) * h, std::sin(orientation) * h);
  const auto a = base_point(n + e, z), b = base_point(n - e, z);
  if (!a || !b) return std::nullopt;
  const Vector2d d = *a - *b;
  return std::atan2(d.y(), d.x());
}

Eigen::Matrix2d CeilingGeometry::tilt_jacobian(const Eigen::Vector2d& n) {
  // The point (x, y, 1) seen from a camera turned by w = (a, b, 0) is (x, y, 1) - w x (x, y, 1):
  // to first order x' = x - b (1 + x^2) + a x y, y' = y + a (1 + y^2) - b x y.
  const double x = n.x(), y = n.y();
  Eigen::Matrix2d T;
  T << x * y, -(1 + x * x), 1 + y * y, -x * y;
  return T;
}

}  // namespace lampnav::fusion
