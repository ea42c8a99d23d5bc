#include "lampnav/sim/lamp_sensors.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>

#include "lampnav/core/error.hpp"
#include "lampnav/sim/renderers.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::sim {

namespace {
constexpr double kDeg = M_PI / 180.0;
using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

// A unit vector turned by small random angles (sigma rad) about two axes across it.
Vector3d jitter(const Vector3d& ray, double sigma, std::mt19937_64& rng) {
  if (sigma <= 0) return ray;
  std::normal_distribution<double> n(0.0, sigma);
  const Vector3d a = ray.unitOrthogonal(), b = ray.cross(a);
  return (ray + n(rng) * a + n(rng) * b).normalized();
}

// The base tilted by a floor bump: roll then pitch, small angles.
Matrix3d bump(double sigma, std::mt19937_64& rng) {
  if (sigma <= 0) return Matrix3d::Identity();
  std::normal_distribution<double> n(0.0, sigma);
  const double r = n(rng), p = n(rng);
  Matrix3d Rx, Ry;
  Rx << 1, 0, 0, 0, std::cos(r), -std::sin(r), 0, std::sin(r), std::cos(r);
  Ry << std::cos(p), 0, std::sin(p), 0, 1, 0, -std::sin(p), 0, std::cos(p);
  return Rx * Ry;
}
}  // namespace

void LampSensorOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what = "must not be negative") {
    if (!ok) throw InputError({"", "lamp sensors", field}, what);
  };
  check(omni_sigma_deg >= 0, "omni_sigma_deg");
  check(omni_halo > 0, "omni_halo", "must be positive");
  check(omni_max_theta_deg > 0 && omni_max_theta_deg < 180, "omni_max_theta_deg",
        "must be between 0 and 180 degrees");
  check(ceiling_sigma_px >= 0, "ceiling_sigma_px");
  check(ceiling_orientation_sigma >= 0, "ceiling_orientation_sigma");
  check(bump_sigma_deg >= 0, "bump_sigma_deg");
}

struct LampSensors::Impl {
  const graph::TopologicalMap* map;
  LampSensorOptions o;
  std::optional<vision::FisheyeCamera> omni;
  Matrix3d omni_R;  // camera -> base
  Vector3d omni_t;
  std::optional<vision::PinholeCamera> ceiling;
  Matrix3d ceiling_R;
  Vector3d ceiling_t;
  double omni_reach = 0;  // m, lamps further away are below the omni's horizon limit
  double omni_top = 0;    // m, the highest lamp above the omni camera

  bool works(const graph::Lamp& l) const { return !o.failed_lamps.count(l.id.value); }

  // A lamp point in a camera's frame from the robot's pose, the base tilted by `tilt`.
  static Vector3d in_camera(const Pose2& pose, const Vector3d& p, const Matrix3d& tilt,
                            const Matrix3d& R, const Vector3d& t) {
    const double c = std::cos(pose.yaw()), s = std::sin(pose.yaw());
    const Vector3d d(p.x() - pose.x(), p.y() - pose.y(), p.z());
    const Vector3d base(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
    return R.transpose() * (tilt.transpose() * base - t);
  }
};

LampSensors::LampSensors(const graph::TopologicalMap& map, const RobotDescription& robot,
                         const LampSensorOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.map = &map;
  m.o = options;
  m.o.validate();
  if (const CameraDescription* c = robot.find_camera("omni_camera")) {
    m.omni.emplace(*c);
    m.omni_R = c->mount.rotation();
    m.omni_t = c->mount.xyz;
    double top = 0;
    for (const auto& n : map.nodes())
      for (const auto& l : n.lamps) top = std::max(top, l.xyz.z() - m.omni_t.z());
    m.omni_top = top;
    m.omni_reach = top * std::tan(std::min(89.0, m.o.omni_max_theta_deg) * kDeg) + 2.0;
  }
  if (const CameraDescription* c = robot.find_camera("ceiling_camera")) {
    m.ceiling.emplace(*c);
    m.ceiling_R = c->mount.rotation();
    m.ceiling_t = c->mount.xyz;
  }
}
LampSensors::~LampSensors() = default;
double LampSensors::omni_resolving_radius_m(double tolerance_m) const {
  const Impl& m = *impl_;
  if (!m.omni || !(m.omni_top > 0) || !(tolerance_m > 0)) return 0.0;
  const double cos2 = 3 * m.o.omni_sigma_deg * kDeg * m.omni_top / tolerance_m;
  if (cos2 >= 1) return 0.0;
  const double theta = std::min(std::acos(std::sqrt(cos2)), m.o.omni_max_theta_deg * kDeg);
  return m.omni_top * std::tan(theta);
}
LampSensors::LampSensors(LampSensors&&) noexcept = default;

vision::OmniDetection LampSensors::omni(const Pose2& pose, std::mt19937_64& rng) const {
  const Impl& m = *impl_;
  vision::OmniDetection out;
  if (!m.omni) return out;
  const Matrix3d tilt = bump(m.o.bump_sigma_deg * kDeg, rng);
  struct Seen {
    Vector3d ray;
    double radius;  // rad, half the blob's angular size
  };
  std::vector<Seen> seen;
  for (const graph::Lamp* l : m.map->lamps_within(pose.translation(), m.omni_reach)) {
    if (!m.works(*l)) continue;
    const Vector3d c = Impl::in_camera(pose, l->xyz, tilt, m.omni_R, m.omni_t);
    const double range = c.norm();
    if (!(range > 0.1)) continue;
    const Vector3d ray = c / range;
    if (std::acos(std::clamp(ray.z(), -1.0, 1.0)) > m.o.omni_max_theta_deg * kDeg) continue;
    // The IR bloom makes a blob omni_halo times the lamp's face (a disc of its area), seen
    // from its range: the rendered blob's core (OmniRenderOptions::halo).
    seen.push_back({ray, m.o.omni_halo * std::atan(std::max(0.025, lamp_face_radius(*l)) / range)});
  }
  // One blob per lamp: the detector's second threshold splits lamps whose blooms touch.
  for (const Seen& sn : seen) {
    const Vector3d ray = jitter(sn.ray, m.o.omni_sigma_deg * kDeg, rng);
    const auto px = m.omni->project(ray);
    if (!px) continue;
    vision::OmniBlob blob;
    blob.ray = ray;
    blob.theta = std::acos(std::clamp(ray.z(), -1.0, 1.0));
    blob.centroid_px = *px;
    const Vector2d d = *px - Vector2d(m.omni->parameters().u0, m.omni->parameters().v0);
    blob.radius_px = d.norm();
    blob.azimuth = std::atan2(d.y(), d.x());
    blob.angular_radius = sn.radius;
    blob.pixels = std::max(3, static_cast<int>(std::lround(400 * sn.radius * sn.radius / 0.0025)));
    blob.perimeter = std::max(3, static_cast<int>(std::lround(std::sqrt(blob.pixels) * 3.5)));
    out.blobs.push_back(blob);
  }
  out.raw_blobs = static_cast<int>(out.blobs.size());
  return out;
}

std::vector<vision::LampDetection> LampSensors::ceiling(const Pose2& pose,
                                                        std::mt19937_64& rng) const {
  const Impl& m = *impl_;
  std::vector<vision::LampDetection> out;
  if (!m.ceiling) return out;
  const vision::PinholeCamera& cam = *m.ceiling;
  const Matrix3d tilt = bump(m.o.bump_sigma_deg * kDeg, rng);
  std::normal_distribution<double> px_noise(0.0, m.o.ceiling_sigma_px);
  std::normal_distribution<double> axis_noise(0.0, m.o.ceiling_orientation_sigma);
  for (const graph::Lamp* l : m.map->lamps_within(pose.translation(), 6.0)) {
    if (!m.works(*l)) continue;
    const Vector3d c = Impl::in_camera(pose, l->xyz, tilt, m.ceiling_R, m.ceiling_t);
    if (!(c.z() > 0.2)) continue;
    // Wholly in view: the lamp's outline (its corners, or a disc's rim) inside the image.
    const double half_l = 0.5 * l->length, half_w = 0.5 * (l->width > 0 ? l->width : l->length);
    const Vector2d ax(std::cos(l->yaw), std::sin(l->yaw)), across(-ax.y(), ax.x());
    bool inside = true;
    for (int k = 0; k < 4 && inside; ++k) {
      const Vector2d corner =
          l->xyz.head<2>() + (k & 1 ? half_l : -half_l) * ax + (k & 2 ? half_w : -half_w) * across;
      const Vector3d cc = Impl::in_camera(pose, Vector3d(corner.x(), corner.y(), l->xyz.z()), tilt,
                                          m.ceiling_R, m.ceiling_t);
      const auto p = cc.z() > 0 ? cam.project(cc) : std::nullopt;
      inside = p && p->x() >= 1 && p->y() >= 1 && p->x() <= cam.width() - 2 &&
               p->y() <= cam.height() - 2;
    }
    if (!inside) continue;
    vision::LampDetection d;
    d.view = vision::LampView::full;
    const Vector2d n(c.x() / c.z(), c.y() / c.z());
    d.centre_px = cam.pixel_of_normalized(n) + Vector2d(px_noise(rng), px_noise(rng));
    d.centre = cam.normalized_of_pixel(d.centre_px);
    const Vector3d tip = Impl::in_camera(pose, l->xyz + Vector3d(ax.x(), ax.y(), 0) * half_l, tilt,
                                         m.ceiling_R, m.ceiling_t);
    const Vector2d axis = Vector2d(tip.x() / tip.z(), tip.y() / tip.z()) - n;
    double o = std::atan2(axis.y(), axis.x()) + axis_noise(rng);
    while (o > M_PI / 2) o -= M_PI;
    while (o <= -M_PI / 2) o += M_PI;
    d.orientation = o;
    d.length = l->length / c.z();
    d.width = (l->width > 0 ? l->width : l->length) / c.z();
    d.area = d.length * d.width * (l->shape == graph::LampShape::disc ? M_PI / 4 : 1.0);
    d.visible_fraction = 1.0;
    d.pixels = static_cast<int>(d.area * cam.parameters().fx * cam.parameters().fy);
    out.push_back(d);
  }
  return out;
}

}  // namespace lampnav::sim
