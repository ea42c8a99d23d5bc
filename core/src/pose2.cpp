#include "lampnav/core/pose2.hpp"

#include <cmath>
#include <ostream>

namespace lampnav {

double wrap_angle(double a) {
  if (!std::isfinite(a)) return a;
  // remainder() gives (-pi, pi] up to the sign at exactly +-pi; fold -pi onto +pi.
  double w = std::remainder(a, 2.0 * M_PI);
  if (w <= -M_PI) w += 2.0 * M_PI;
  return w;
}

double wrap_axis_angle(double a) {
  if (!std::isfinite(a)) return a;
  double w = std::remainder(a, M_PI);
  if (w <= -M_PI / 2) w += M_PI;
  return w;
}

Pose2::Pose2(double x, double y, double yaw) : t_(x, y), yaw_(wrap_angle(yaw)) {}
Pose2::Pose2(const Eigen::Vector2d& t, double yaw) : t_(t), yaw_(wrap_angle(yaw)) {}

Eigen::Matrix2d Pose2::rotation() const {
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

Pose2 Pose2::compose(const Pose2& other) const {
  return {t_ + rotation() * other.t_, yaw_ + other.yaw_};
}

Pose2 Pose2::inverse() const {
  const Eigen::Matrix2d rt = rotation().transpose();
  return {-(rt * t_), -yaw_};
}

Pose2 Pose2::between(const Pose2& other) const { return inverse().compose(other); }

Eigen::Vector2d Pose2::transform_from(const Eigen::Vector2d& p) const {
  return t_ + rotation() * p;
}

Eigen::Vector2d Pose2::transform_to(const Eigen::Vector2d& p) const {
  return rotation().transpose() * (p - t_);
}

std::ostream& operator<<(std::ostream& os, const Pose2& p) {
  return os << "(" << p.x() << ", " << p.y() << ", " << p.yaw() << ")";
}

Pose2 interpolate(const Pose2& a, const Pose2& b, double f) {
  return Pose2(a.translation() + f * (b.translation() - a.translation()),
               wrap_angle(a.yaw() + f * wrap_angle(b.yaw() - a.yaw())));
}

}  // namespace lampnav
