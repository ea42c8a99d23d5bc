#include "lampnav/mapping/rigid_fit.hpp"

#include <cmath>

namespace lampnav::mapping {
namespace {

Similarity fit(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& pairs, bool scaled) {
  if (pairs.empty()) return {Pose2::identity(), 1};
  Eigen::Vector2d ca = Eigen::Vector2d::Zero(), cb = Eigen::Vector2d::Zero();
  for (const auto& [a, b] : pairs) {
    ca += a;
    cb += b;
  }
  ca /= static_cast<double>(pairs.size());
  cb /= static_cast<double>(pairs.size());
  double c = 0, s = 0, uu = 0;
  for (const auto& [a, b] : pairs) {
    const Eigen::Vector2d u = a - ca, v = b - cb;
    c += u.dot(v);
    s += u.x() * v.y() - u.y() * v.x();
    uu += u.squaredNorm();
  }
  const double yaw = std::atan2(s, c);
  // b = k R (a - ca) + cb = R (k a) + (cb - k R ca); k = |(c, s)| / sum |u|^2 minimizes the rest
  const double k = scaled && uu > 0 ? std::hypot(c, s) / uu : 1.0;
  const Pose2 rot(0, 0, yaw);
  return {Pose2(cb - rot.transform_from(k * ca), yaw), k};
}

}  // namespace

Pose2 fit_rigid(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& pairs) {
  return fit(pairs, false).motion;
}

Similarity fit_similarity(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& pairs) {
  return fit(pairs, true);
}

}  // namespace lampnav::mapping
