#pragma once
// The rigid motion (rotation and translation, no scale) that best maps one set of 2-D points
// onto another in the least-squares sense, for comparing a built map with the truth.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <utility>
#include <vector>

namespace lampnav::test {

struct RigidFit {
  Eigen::Matrix2d rotation = Eigen::Matrix2d::Identity();
  Eigen::Vector2d from_centre = Eigen::Vector2d::Zero(), to_centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d apply(const Eigen::Vector2d& p) const {
    return rotation * (p - from_centre) + to_centre;
  }
};

// pairs: (point, its counterpart).
inline RigidFit fit_rigid(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& pairs) {
  RigidFit f;
  if (pairs.empty()) return f;
  for (const auto& [a, b] : pairs) {
    f.from_centre += a;
    f.to_centre += b;
  }
  f.from_centre /= static_cast<double>(pairs.size());
  f.to_centre /= static_cast<double>(pairs.size());
  double c = 0, s = 0;
  for (const auto& [a, b] : pairs) {
    const Eigen::Vector2d u = a - f.from_centre, v = b - f.to_centre;
    c += u.dot(v);
    s += u.x() * v.y() - u.y() * v.x();
  }
  f.rotation = Eigen::Rotation2Dd(std::atan2(s, c)).toRotationMatrix();
  return f;
}

}  // namespace lampnav::test
