#pragma once
// Two pieces of geometry the hypothesis set uses: whether a rigid motion maps the map onto itself
// (look-alike places no motion can tell apart), and the Kalman update of a pose hypothesis.
// Private to the hypothesis set (hypothesis_set.cpp, hypothesis_weighing.cpp).

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>

#include "lampnav/core/pose2.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::fusion::detail {

// Whether the rigid motion T maps every lamp of the map onto a lamp of the same shape and size
// (within 0.15 m, 5 cm of size and height; a rectangle's axis within 3 degrees, modulo a half
// turn).
inline bool maps_onto_itself(const graph::TopologicalMap& map, const Pose2& T) {
  constexpr double kDeg = M_PI / 180.0;
  const double c = std::cos(T.yaw()), s = std::sin(T.yaw());
  for (const auto& n : map.nodes()) {
    for (const auto& l : n.lamps) {
      const Eigen::Vector2d p = T.translation() + Eigen::Vector2d(c * l.xyz.x() - s * l.xyz.y(),
                                                                  s * l.xyz.x() + c * l.xyz.y());
      bool found = false;
      for (const graph::Lamp* m : map.lamps_within(p, 0.15)) {
        if (m->shape != l.shape || std::abs(m->length - l.length) > 0.05 ||
            std::abs(m->width - l.width) > 0.05 || std::abs(m->xyz.z() - l.xyz.z()) > 0.05)
          continue;
        const bool round = l.shape == graph::LampShape::disc || l.length <= l.width;
        const double d = wrap_angle(m->yaw - (l.yaw + T.yaw()));
        if (round || std::abs(std::sin(d)) < std::sin(3 * kDeg)) found = true;
      }
      if (!found) return false;
    }
  }
  return true;
}

// Kalman update of a pose (x, y, yaw) and its covariance P with a pose measurement z of
// covariance R; P's diagonal kept at least floor_m^2, floor_m^2, floor_yaw^2 (a hypothesis is
// never surer than odometry between frames allows). Returns the normalized innovation squared
// less its expectation (3): about 0 for a right hypothesis, comparable between hypotheses
// whatever their covariance.
inline double update_pose(Pose2& pose, Eigen::Matrix3d& P, const Pose2& z, const Eigen::Matrix3d& R,
                          double floor_m, double floor_yaw) {
  const Eigen::Matrix3d S = P + R;
  const Eigen::Vector3d nu(z.x() - pose.x(), z.y() - pose.y(), wrap_angle(z.yaw() - pose.yaw()));
  const Eigen::Matrix3d Si = S.inverse();
  const Eigen::Matrix3d K = P * Si;
  const Eigen::Vector3d dx = K * nu;
  pose = Pose2(pose.x() + dx.x(), pose.y() + dx.y(), wrap_angle(pose.yaw() + dx.z()));
  const Eigen::Matrix3d I_K = Eigen::Matrix3d::Identity() - K;
  P = I_K * P * I_K.transpose() + K * R * K.transpose();
  P = 0.5 * (P + P.transpose());
  const double fp = floor_m * floor_m, fy = floor_yaw * floor_yaw;
  if (P(0, 0) < fp) P(0, 0) = fp;
  if (P(1, 1) < fp) P(1, 1) = fp;
  if (P(2, 2) < fy) P(2, 2) = fy;
  return nu.dot(Si * nu) - 3.0;
}

}  // namespace lampnav::fusion::detail
