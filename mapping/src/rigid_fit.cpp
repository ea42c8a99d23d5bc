#include "lampnav/mapping/rigid_fit.hpp"

#include <cmath>

namespace lampnav::mapping {

Pose2 fit_rigid(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& pairs) {
  if (pairs.empty()) return Pose2::identity();
  Eigen::Vector2d ca = Eigen::Vector2d::Zero(), cb = Eigen::Vector2d::Zero();
  for (const auto& [a, b] : pairs) {
    ca += a;
    cb += b;
  }
  ca /= static_cast<double>(pairs.size());
  cb /= static_cast<double>(pairs.size());
  double c = 0, s = 0;
  for (const auto& [a, b] : pairs) {
    const Eigen::Vector2d u = a - ca, v = b - cb;
    c += u.dot(v);
    s += u.x() * v.y() - u.y() * v.x();
  }
  const double yaw = std::atan2(s, c);
  // b = R (a - ca) + cb = R a + (cb - R ca)
  const Pose2 rot(0, 0, yaw);
  return Pose2(cb - rot.transform_from(ca), yaw);
}

}  // namespace lampnav::mapping
