#include "lampnav/vision/camera_models.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "lampnav/core/error.hpp"

namespace lampnav::vision {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {
// d/dr of r * radial(r^2) = 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6: the mapping folds back where this
// first reaches zero. Scanned in r^2 up to a generous bound (normalized radius 10, 84 degrees).
double fold_radius2(const std::array<double, 5>& k) {
  const double k1 = k[0], k2 = k[1], k3 = k[4];
  auto slope = [&](double s) { return 1 + 3 * k1 * s + 5 * k2 * s * s + 7 * k3 * s * s * s; };
  const double limit = 100.0;
  double prev = 0.0;
  for (double s = 1e-3; s <= limit; s += 1e-3 * (1 + s)) {
    if (slope(s) <= 0) {
      double lo = prev, hi = s;  // refine by bisection
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (slope(mid) > 0 ? lo : hi) = mid;
      }
      return lo;
    }
    prev = s;
  }
  return limit;
}
}  // namespace

bool PinholeCamera::takes(CameraModelKind model) {
  return model == CameraModelKind::pinhole || model == CameraModelKind::kannala_brandt;
}

PinholeParameters PinholeCamera::intrinsics(const CameraDescription& d) {
  if (d.model != CameraModelKind::kannala_brandt) return d.pinhole;
  const FisheyeParameters& f = d.fisheye;
  return {f.f, f.f * f.beta, f.u0, f.v0, {}};
}

PinholeCamera::PinholeCamera(const CameraDescription& d)
    : p_(intrinsics(d)), width_(d.width), height_(d.height) {
  if (!takes(d.model))
    throw Error("camera '" + d.name + "' is " + to_string(d.model) +
                ": the ceiling camera's pipeline takes pinhole or kannala_brandt");
  if (d.model == CameraModelKind::pinhole) {
    max_r2_ = fold_radius2(p_.distortion);
    return;
  }
  equidistant_ = true;
  k_ = d.fisheye.k;
  // The view's edge: half the field of view, where theta_d stops growing, or 89 degrees (the
  // normalized plane ends at 90).
  max_theta_ = std::min(0.5 * d.fisheye.fov_deg, 89.0) * M_PI / 180.0;
  const int steps = 2000;
  for (int i = 1; i <= steps; ++i)
    if (!(theta_d_derivative(max_theta_ * i / steps) > 0)) {
      max_theta_ = max_theta_ * (i - 1) / steps;
      break;
    }
  max_r2_ = std::pow(std::tan(max_theta_), 2);
}

double PinholeCamera::theta_d(double t) const {
  const double t2 = t * t;
  return t * (1 + t2 * (k_[0] + t2 * (k_[1] + t2 * (k_[2] + t2 * k_[3]))));
}

double PinholeCamera::theta_d_derivative(double t) const {
  const double t2 = t * t;
  return 1 + t2 * (3 * k_[0] + t2 * (5 * k_[1] + t2 * (7 * k_[2] + t2 * 9 * k_[3])));
}

double PinholeCamera::theta_of(double td) const {
  // theta_d rises on [0, max_theta_]: Newton's steps from theta = theta_d, kept inside by
  // bisection's bracket, to double precision.
  if (!(td > 0)) return 0.0;
  double lo = 0, hi = max_theta_;
  if (td >= theta_d(hi)) return hi;
  double t = std::min(td, hi);
  for (int i = 0; i < 50; ++i) {
    const double e = theta_d(t) - td;
    (e < 0 ? lo : hi) = t;
    if (std::abs(e) < 1e-15) break;
    double next = t - e / theta_d_derivative(t);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    t = next;
  }
  return t;
}

Vector2d PinholeCamera::distort(const Vector2d& xy) const {
  if (equidistant_) {
    const double r = xy.norm();
    if (r < 1e-12) return xy;
    return xy * (theta_d(std::atan(r)) / r);
  }
  const auto& k = p_.distortion;
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + k[0] * r2 + k[1] * r2 * r2 + k[4] * r2 * r2 * r2;
  return {x * radial + 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x),
          y * radial + k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y};
}

Vector2d PinholeCamera::undistort(const Vector2d& xd) const {
  if (equidistant_) {
    const double td = xd.norm();
    if (td < 1e-12) return xd;
    return xd * (std::tan(theta_of(td)) / td);
  }
  // Fixed-point iteration (as OpenCV's undistortPoints), then Gauss-Newton polish.
  Vector2d xy = xd;
  for (int i = 0; i < 20; ++i) {
    const Vector2d e = distort(xy) - xd;
    if (e.squaredNorm() < 1e-24) break;
    xy -= distort_jacobian(xy).lu().solve(e);
  }
  return xy;
}

Eigen::Matrix2d PinholeCamera::distort_jacobian(const Vector2d& xy) const {
  if (equidistant_) {
    // distort(xy) = g(r) xy with g = theta_d(atan r) / r: J = g I + g'(r) / r xy xy^T.
    const double r = xy.norm();
    if (r < 1e-9) return Eigen::Matrix2d::Identity();
    const double t = std::atan(r), g = theta_d(t) / r;
    const double dg = (theta_d_derivative(t) / (1 + r * r) - g) / r;
    return g * Eigen::Matrix2d::Identity() + (dg / r) * xy * xy.transpose();
  }
  const auto& k = p_.distortion;
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + k[0] * r2 + k[1] * r2 * r2 + k[4] * r2 * r2 * r2;
  const double dradial = k[0] + 2 * k[1] * r2 + 3 * k[4] * r2 * r2;  // d radial / d r2
  Eigen::Matrix2d J;
  J(0, 0) = radial + x * dradial * 2 * x + 2 * k[2] * y + k[3] * 6 * x;
  J(0, 1) = x * dradial * 2 * y + 2 * k[2] * x + k[3] * 2 * y;
  J(1, 0) = y * dradial * 2 * x + k[2] * 2 * x + 2 * k[3] * y;
  J(1, 1) = radial + y * dradial * 2 * y + k[2] * 6 * y + 2 * k[3] * x;
  return J;
}

double PinholeCamera::corner_radius() const {
  double out = 0;
  for (const Vector2d& px : {Vector2d(0, 0), Vector2d(width_ - 1, 0), Vector2d(0, height_ - 1),
                             Vector2d(width_ - 1, height_ - 1)})
    out = std::max(out, normalized_of_pixel(px).norm());
  return out;
}

Eigen::Matrix2d PinholeCamera::normalized_covariance(const Vector2d& xy, double pixel_sigma) const {
  const Eigen::Matrix2d J =
      Eigen::Vector2d(p_.fx, p_.fy).asDiagonal() * distort_jacobian(xy);  // d pixel / d xy
  const Eigen::Matrix2d Ji = J.inverse();
  return pixel_sigma * pixel_sigma * Ji * Ji.transpose();
}

Vector2d PinholeCamera::normalized_of_pixel(const Vector2d& px) const {
  return undistort(Vector2d((px.x() - p_.cx) / p_.fx, (px.y() - p_.cy) / p_.fy));
}

Vector2d PinholeCamera::pixel_of_normalized(const Vector2d& xy) const {
  const Vector2d d = distort(xy);
  return {p_.fx * d.x() + p_.cx, p_.fy * d.y() + p_.cy};
}

Eigen::Matrix<double, 2, 3> PinholeCamera::project_jacobian(const Vector3d& p) const {
  const double iz = 1.0 / p.z();
  const Vector2d xy(p.x() * iz, p.y() * iz);
  Eigen::Matrix<double, 2, 3> dxy;  // d (x, y) / d (X, Y, Z)
  dxy << iz, 0, -xy.x() * iz, 0, iz, -xy.y() * iz;
  const Eigen::Matrix2d K = Eigen::Vector2d(p_.fx, p_.fy).asDiagonal();
  return K * distort_jacobian(xy) * dxy;
}

std::optional<Vector2d> PinholeCamera::project(const Vector3d& p) const {
  if (!(p.z() > 0)) return std::nullopt;
  const Vector2d xy(p.x() / p.z(), p.y() / p.z());
  if (xy.squaredNorm() > max_r2_) return std::nullopt;
  const Vector2d d = distort(xy);
  return Vector2d(p_.fx * d.x() + p_.cx, p_.fy * d.y() + p_.cy);
}

Vector3d PinholeCamera::unproject(const Vector2d& px) const {
  const Vector2d xd((px.x() - p_.cx) / p_.fx, (px.y() - p_.cy) / p_.fy);
  const Vector2d xy = undistort(xd);
  return Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

FisheyeCamera::FisheyeCamera(const CameraDescription& d)
    : p_(d.fisheye), width_(d.width), height_(d.height) {
  if (!is_fisheye(d.model)) {
    throw Error("camera '" + d.name +
                "' is not a fisheye (pajdla_bakstein or kannala_brandt) camera");
  }
  kb_ = d.model == CameraModelKind::kannala_brandt;
  max_theta_ = 0.5 * p_.fov_deg * M_PI / 180.0;
  // Beyond the angle where the radius stops growing the model folds back: that is the edge of
  // its field of view.
  const int steps = 2000;
  for (int i = 1; i <= steps; ++i) {
    const double t = max_theta_ * i / steps;
    if (!(radius_derivative(t) > 0)) {
      max_theta_ = max_theta_ * (i - 1) / steps;
      break;
    }
  }
}

double FisheyeCamera::radius(double theta) const {
  if (kb_) {
    const double t2 = theta * theta;
    return p_.f * theta * (1 + t2 * (p_.k[0] + t2 * (p_.k[1] + t2 * (p_.k[2] + t2 * p_.k[3]))));
  }
  return p_.a * std::tan(theta / p_.b) + p_.c * std::sin(theta / p_.d);
}

double FisheyeCamera::radius_derivative(double theta) const {
  if (kb_) {
    const double t2 = theta * theta;
    return p_.f *
           (1 + t2 * (3 * p_.k[0] + t2 * (5 * p_.k[1] + t2 * (7 * p_.k[2] + t2 * 9 * p_.k[3]))));
  }
  const double sec = 1.0 / std::cos(theta / p_.b);
  return p_.a / p_.b * sec * sec + p_.c / p_.d * std::cos(theta / p_.d);
}

std::optional<double> FisheyeCamera::theta_of_radius(double r) const {
  if (r < 0 || r > radius(max_theta_)) return std::nullopt;
  // r(theta) rises monotonically on [0, max_theta] for physical parameters: bisection is exact
  // to double precision in 60 steps and cannot diverge.
  double lo = 0, hi = max_theta_;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (radius(mid) < r ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::optional<Vector2d> FisheyeCamera::project(const Vector3d& p) const {
  const double rho = std::hypot(p.x(), p.y());
  const double theta = std::atan2(rho, p.z());
  if (theta > max_theta_ || p.norm() == 0) return std::nullopt;
  const double phi = std::atan2(p.y(), p.x());
  const double r = radius(theta);
  return Vector2d(p_.u0 + r * std::cos(phi), p_.v0 + p_.beta * r * std::sin(phi));
}

Eigen::Matrix<double, 2, 3> FisheyeCamera::project_jacobian(const Vector3d& p) const {
  // u = u0 + r(theta) cos(phi), v = v0 + beta r(theta) sin(phi); chain rule through theta, phi.
  const double rho2 = p.x() * p.x() + p.y() * p.y();
  const double rho = std::sqrt(rho2);
  const double n2 = rho2 + p.z() * p.z();
  const double theta = std::atan2(rho, p.z());
  const double cphi = p.x() / rho, sphi = p.y() / rho;
  const double dr = radius_derivative(theta);
  const double r = radius(theta);
  // d theta / d (X, Y, Z) and d phi / d (X, Y, Z).
  const Eigen::RowVector3d dtheta(p.x() * p.z() / (rho * n2), p.y() * p.z() / (rho * n2),
                                  -rho / n2);
  const Eigen::RowVector3d dphi(-p.y() / rho2, p.x() / rho2, 0.0);
  Eigen::Matrix<double, 2, 3> J;
  J.row(0) = dr * cphi * dtheta - r * sphi * dphi;
  J.row(1) = p_.beta * (dr * sphi * dtheta + r * cphi * dphi);
  return J;
}

std::optional<Vector3d> FisheyeCamera::unproject(const Vector2d& px) const {
  const double dx = px.x() - p_.u0;
  const double dy = (px.y() - p_.v0) / p_.beta;
  const auto theta = theta_of_radius(std::hypot(dx, dy));
  if (!theta) return std::nullopt;
  const double phi = std::atan2(dy, dx);
  return Vector3d(std::sin(*theta) * std::cos(phi), std::sin(*theta) * std::sin(phi),
                  std::cos(*theta));
}

namespace {

// Either model, from ray to pixel and back: pinhole cameras by PinholeCamera, fisheyes
// (Kannala-Brandt too, whose rays may pass 90 degrees) by FisheyeCamera.
struct AnyCamera {
  std::optional<PinholeCamera> pinhole;
  std::optional<FisheyeCamera> fisheye;
  explicit AnyCamera(const CameraDescription& c) {
    if (c.model == CameraModelKind::pinhole)
      pinhole.emplace(c);
    else
      fisheye.emplace(c);
  }
  std::optional<Vector3d> ray(const Eigen::Vector2d& px) const {
    if (pinhole) return pinhole->unproject(px);
    return fisheye->unproject(px);
  }
  std::optional<Eigen::Vector2d> pixel(const Vector3d& ray) const {
    return pinhole ? pinhole->project(ray) : fisheye->project(ray);
  }
};

}  // namespace

double ceiling_view_length(const CameraDescription& camera, double height) {
  const Eigen::Matrix3d R = camera.mount.rotation();
  const Vector3d origin = camera.mount.xyz;
  if (!(height > origin.z())) return 0.0;
  const AnyCamera model(camera);
  auto visible = [&](double s) {
    const Vector3d p_base(origin.x() + s, origin.y(), height);
    const auto px = model.pixel(R.transpose() * (p_base - origin));
    return px && vision::in_image(*px, camera.width, camera.height);
  };
  if (!visible(0.0)) return 0.0;
  // Walk out each way to the edge of the view, then bisect the edge.
  auto reach = [&](double dir) {
    double lo = 0, hi = 0.05;
    const double far = 1e3 * (height - origin.z());
    while (visible(dir * hi) && hi < far) {
      lo = hi;
      hi *= 1.5;
    }
    for (int i = 0; i < 50; ++i) {
      const double mid = 0.5 * (lo + hi);
      (visible(dir * mid) ? lo : hi) = mid;
    }
    return lo;
  };
  return reach(+1.0) + reach(-1.0);
}

double projection_difference_px(const CameraDescription& a, const CameraDescription& b) {
  if (a.width != b.width || a.height != b.height) return std::numeric_limits<double>::infinity();
  const AnyCamera ma(a), mb(b);
  constexpr int kSteps = 16;
  double worst = 0;
  for (int i = 0; i <= kSteps; ++i)
    for (int j = 0; j <= kSteps; ++j) {
      const Eigen::Vector2d px((a.width - 1) * double(i) / kSteps,
                               (a.height - 1) * double(j) / kSteps);
      const auto ray = ma.ray(px);
      if (!ray) continue;
      const auto there = mb.pixel(*ray);
      if (!there) return std::numeric_limits<double>::infinity();
      worst = std::max(worst, (*there - px).norm());
    }
  return worst;
}

}  // namespace lampnav::vision
