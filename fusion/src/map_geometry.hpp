#pragma once
// Geometry of the map and of pose hypotheses: whether a rigid motion carries a lamp, or the whole
// map, onto lamps alike (look-alike places), and the Kalman update of a pose hypothesis. Private
// to fusion (the hypothesis set, the audits).

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>

#include "lampnav/core/pose2.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::fusion::detail {

// Whether lamp m is of the same shape and size as lamp l, at the same height (within 5 cm).
inline bool alike(const graph::Lamp& m, const graph::Lamp& l) {
  return m.shape == l.shape && std::abs(m.length - l.length) <= 0.05 &&
         std::abs(m.width - l.width) <= 0.05 && std::abs(m.xyz.z() - l.xyz.z()) <= 0.05;
}

// Whether lamp m is alike to lamp l turned by `yaw`: a rectangle's axis within 3 degrees of l's
// turned, modulo a half turn.
inline bool alike_turned(const graph::Lamp& m, const graph::Lamp& l, double yaw) {
  constexpr double kDeg = M_PI / 180.0;
  if (!alike(m, l)) return false;
  const bool round = l.shape == graph::LampShape::disc || l.length <= l.width;
  return round || std::abs(std::sin(wrap_angle(m.yaw - (l.yaw + yaw)))) < std::sin(3 * kDeg);
}

// Whether the rigid motion T carries lamp `l` within 0.15 m of a lamp alike to it turned.
inline bool lands_on_alike(const graph::TopologicalMap& map, const Pose2& T, const graph::Lamp& l) {
  for (const graph::Lamp* m : map.lamps_within(T.transform_from(l.xyz.head<2>()), 0.15))
    if (alike_turned(*m, l, T.yaw())) return true;
  return false;
}

// Whether the rigid motion T maps every lamp of the map onto a lamp alike (lands_on_alike).
inline bool maps_onto_itself(const graph::TopologicalMap& map, const Pose2& T) {
  for (const auto& n : map.nodes())
    for (const auto& l : n.lamps)
      if (!lands_on_alike(map, T, l)) return false;
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
