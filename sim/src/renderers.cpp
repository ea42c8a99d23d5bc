#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "lampnav/core/error.hpp"
#include "lampnav/sim/renderers.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::sim {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

CameraPose camera_pose(const Pose2& robot, const CameraTilt& tilt, const Mount& mount) {
  const Matrix3d body = (Eigen::AngleAxisd(robot.yaw(), Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(tilt.pitch, Vector3d::UnitY()) *
                         Eigen::AngleAxisd(tilt.roll, Vector3d::UnitX()))
                            .toRotationMatrix();
  CameraPose c;
  c.rotation = body * mount.rotation();
  c.origin = Vector3d(robot.x(), robot.y(), 0.0) + body * mount.xyz;
  return c;
}

namespace {
void check(double v, double lo, double hi, const char* what, const char* field) {
  if (!(v >= lo && v <= hi)) {
    throw InputError({"", what, field},
                     "must be between " + std::to_string(lo) + " and " + std::to_string(hi));
  }
}
void add_noise(Image8& img, double sigma, std::mt19937_64& rng) {
  if (sigma <= 0) return;
  std::normal_distribution<double> n(0.0, sigma);
  for (auto& p : img.pixels)
    p = static_cast<std::uint8_t>(std::clamp(std::lround(p + n(rng)), 0L, 255L));
}
}  // namespace

void CeilingRenderOptions::validate() const {
  check(background, 0, 255, "ceiling render options", "background");
  check(lamp_level, 0, 255, "ceiling render options", "lamp_level");
  check(fringe_level, 0, 255, "ceiling render options", "fringe_level");
  check(fringe_width, 0, 1, "ceiling render options", "fringe_width");
  check(noise_sigma, 0, 50, "ceiling render options", "noise_sigma");
  check(exposure, 0.05, 20, "ceiling render options", "exposure");
  check(supersample, 1, 16, "ceiling render options", "supersample");
}

void OmniRenderOptions::validate() const {
  check(background, 0, 255, "omni render options", "background");
  check(peak, 0, 255, "omni render options", "peak");
  check(halo, 0.5, 10, "omni render options", "halo");
  check(noise_sigma, 0, 50, "omni render options", "noise_sigma");
  check(occlusion_probability, 0, 1, "omni render options", "occlusion_probability");
  check(spurious_per_image, 0, 20, "omni render options", "spurious_per_image");
}

// Per pixel, the normalized image coordinates (x/z, y/z) of its centre and their derivative with
// respect to (u, v): sub-pixel samples then need no iterative undistortion.
struct CeilingRenderer::Impl {
  CameraDescription cam;
  CeilingRenderOptions o;
  vision::PinholeCamera model;
  std::vector<Vector2d> xn;
  std::vector<Eigen::Matrix2d> jac;
  Impl(const CameraDescription& c, CeilingRenderOptions opt) : cam(c), o(opt), model(c) {
    const int w = c.width, h = c.height;
    xn.resize(static_cast<std::size_t>(w) * h);
    jac.resize(xn.size());
    auto norm = [&](double u, double v) {
      const Vector3d r = model.unproject({u, v});
      return Vector2d(r.x() / r.z(), r.y() / r.z());
    };
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        xn[i] = norm(u, v);
        jac[i].col(0) = norm(u + 0.5, v) - norm(u - 0.5, v);
        jac[i].col(1) = norm(u, v + 0.5) - norm(u, v - 0.5);
      }
    }
  }
};

CeilingRenderer::CeilingRenderer(const CameraDescription& camera, CeilingRenderOptions options) {
  options.validate();
  impl_ = std::make_unique<Impl>(camera, options);
}
CeilingRenderer::~CeilingRenderer() = default;
CeilingRenderer::CeilingRenderer(CeilingRenderer&&) noexcept = default;

std::optional<Vector2d> CeilingRenderer::project(const Pose2& robot, const CameraTilt& tilt,
                                                 const Vector3d& p_map) const {
  const CameraPose cp = camera_pose(robot, tilt, impl_->cam.mount);
  return impl_->model.project(cp.to_camera(p_map));
}

Image8 CeilingRenderer::render(const Pose2& robot, const CameraTilt& tilt,
                               const std::vector<const graph::Lamp*>& lamps,
                               std::mt19937_64& rng) const {
  const Impl& m = *impl_;
  const CeilingRenderOptions& o = m.o;
  const int w = m.cam.width, h = m.cam.height;
  Image8 img(w, h, static_cast<std::uint8_t>(std::lround(o.background)));
  const CameraPose cp = camera_pose(robot, tilt, m.cam.mount);
  const double half_diag = 0.5 * std::hypot(w, h);
  const Vector2d centre((w - 1) / 2.0, (h - 1) / 2.0);
  const int s = o.supersample;
  for (const graph::Lamp* lamp : lamps) {
    const double fw = o.fringe_width;
    const bool disc = lamp->shape == graph::LampShape::disc;
    const double hl = lamp->length / 2 + fw, hw = lamp->width / 2 + fw;
    // Image bounding box from points around the lamp and its fringe.
    double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
    bool any = false;
    const double c = std::cos(lamp->yaw), sn = std::sin(lamp->yaw);
    for (int k = 0; k < 16; ++k) {
      const double a = 2 * M_PI * k / 16;
      // 16 points around the outline: a circle, or four per edge of the rectangle.
      Vector2d local(hl * std::cos(a), hl * std::sin(a));
      if (!disc) {
        const double t = (k % 4) / 2.0 - 1.0;  // -1, -0.5, 0, 0.5 along each edge
        switch (k / 4) {
          case 0:
            local = {t * hl, -hw};
            break;
          case 1:
            local = {hl, t * hw};
            break;
          case 2:
            local = {-t * hl, hw};
            break;
          default:
            local = {-hl, -t * hw};
            break;
        }
      }
      const Vector3d p(lamp->xyz.x() + c * local.x() - sn * local.y(),
                       lamp->xyz.y() + sn * local.x() + c * local.y(), lamp->xyz.z());
      const auto px = m.model.project(cp.to_camera(p));
      if (!px) continue;
      any = true;
      u0 = std::min(u0, px->x());
      v0 = std::min(v0, px->y());
      u1 = std::max(u1, px->x());
      v1 = std::max(v1, px->y());
    }
    if (!any) continue;
    const int ua = std::max(0, static_cast<int>(std::floor(u0)) - 2);
    const int va = std::max(0, static_cast<int>(std::floor(v0)) - 2);
    const int ub = std::min(w - 1, static_cast<int>(std::ceil(u1)) + 2);
    const int vb = std::min(h - 1, static_cast<int>(std::ceil(v1)) + 2);
    if (ua > ub || va > vb) continue;
    for (int v = va; v <= vb; ++v) {
      for (int u = ua; u <= ub; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        const double off = std::min(1.0, (Vector2d(u, v) - centre).norm() / half_diag);
        const double fringe = o.fringe_level * (0.3 + 0.7 * off);
        double sum = 0;
        for (int sy = 0; sy < s; ++sy) {
          for (int sx = 0; sx < s; ++sx) {
            const Vector2d d((sx + 0.5) / s - 0.5, (sy + 0.5) / s - 0.5);
            const Vector2d x = m.xn[i] + m.jac[i] * d;
            const Vector3d ray = cp.rotation * Vector3d(x.x(), x.y(), 1.0);
            double level = o.background;
            if (ray.z() > 1e-9) {
              const double t = (lamp->xyz.z() - cp.origin.z()) / ray.z();
              if (t > 0) {
                const double dx = cp.origin.x() + t * ray.x() - lamp->xyz.x();
                const double dy = cp.origin.y() + t * ray.y() - lamp->xyz.y();
                const double lx = c * dx + sn * dy, ly = -sn * dx + c * dy;
                if (disc) {
                  const double r = std::hypot(lx, ly);
                  if (r <= lamp->length / 2) {
                    level = o.lamp_level * o.exposure;
                  } else if (r <= hl) {
                    level = fringe * o.exposure;
                  }
                } else if (std::fabs(lx) <= lamp->length / 2 && std::fabs(ly) <= lamp->width / 2) {
                  level = o.lamp_level * o.exposure;
                } else if (std::fabs(lx) <= hl && std::fabs(ly) <= hw) {
                  level = fringe * o.exposure;
                }
              }
            }
            sum += std::min(255.0, std::max(level, o.background));
          }
        }
        const auto value = static_cast<std::uint8_t>(std::lround(sum / (s * s)));
        img.pixels[i] = std::max(img.pixels[i], value);
      }
    }
  }
  add_noise(img, o.noise_sigma, rng);
  return img;
}

OmniRenderer::OmniRenderer(const CameraDescription& camera, OmniRenderOptions options)
    : cam_(camera), o_(options) {
  o_.validate();
  vision::FisheyeCamera check_model(camera);  // throws when not a fisheye camera
  (void)check_model;
}

std::optional<Vector2d> OmniRenderer::project(const Pose2& robot, const CameraTilt& tilt,
                                              const Vector3d& p_map) const {
  const vision::FisheyeCamera model(cam_);
  return model.project(camera_pose(robot, tilt, cam_.mount).to_camera(p_map));
}

double lamp_face_radius(const graph::Lamp& lamp) {
  return lamp.shape == graph::LampShape::disc ? lamp.length / 2
                                              : std::sqrt(lamp.length * lamp.width / M_PI);
}

Image8 OmniRenderer::render(const Pose2& robot, const CameraTilt& tilt,
                            const std::vector<const graph::Lamp*>& lamps,
                            std::mt19937_64& rng) const {
  const vision::FisheyeCamera model(cam_);
  const int w = cam_.width, h = cam_.height;
  Image8 img(w, h, static_cast<std::uint8_t>(std::lround(o_.background)));
  const CameraPose cp = camera_pose(robot, tilt, cam_.mount);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  // A blob: a saturated core, for near lamps a bloom halo, and a soft one-pixel edge.
  auto blob = [&](const Vector2d& c, double core, double halo_r, double halo_level) {
    const double outer = std::max(core, halo_r) + 1.5;
    const int ua = std::max(0, static_cast<int>(c.x() - outer)),
              ub = std::min(w - 1, static_cast<int>(c.x() + outer) + 1);
    const int va = std::max(0, static_cast<int>(c.y() - outer)),
              vb = std::min(h - 1, static_cast<int>(c.y() + outer) + 1);
    for (int v = va; v <= vb; ++v) {
      for (int u = ua; u <= ub; ++u) {
        const double d = std::hypot(u - c.x(), v - c.y());
        double level = o_.background;
        if (d <= core) {
          level = o_.peak;
        } else if (d <= core + 1.0) {
          level = o_.peak +
                  (std::max(o_.background, halo_r > core ? halo_level : o_.background) - o_.peak) *
                      (d - core);
        } else if (d <= halo_r) {
          level = halo_level;
        } else if (d <= halo_r + 1.0) {
          level = halo_level + (o_.background - halo_level) * (d - halo_r);
        }
        auto& p = img.at(u, v);
        p = std::max(p, static_cast<std::uint8_t>(std::lround(std::clamp(level, 0.0, 255.0))));
      }
    }
  };
  // Pixels per radian off-axis at theta (the derivative of r(theta)), of the camera's own model:
  // Pajdla-Bakstein's a, b, c, d are zero on a Kannala-Brandt camera, whose lamps were drawn as
  // dots of min_radius_px, too small for the detector to take for lamps.
  auto px_per_rad = [&](double theta) { return model.radius_derivative(theta); };
  for (const graph::Lamp* lamp : lamps) {
    const Vector3d pc = cp.to_camera(lamp->xyz);
    const auto px = model.project(pc);
    if (!px || !model.in_image(*px)) continue;
    const double dist = pc.norm();
    const double theta = std::atan2(std::hypot(pc.x(), pc.y()), pc.z());
    if (theta > 50.0 * M_PI / 180.0 && uni(rng) < o_.occlusion_probability) continue;  // a person
    const double ang = std::atan(lamp_face_radius(*lamp) / dist);
    const double core = std::max(o_.min_radius_px, o_.halo * ang * px_per_rad(theta));
    double halo_r = core, halo_level = o_.background;
    if (dist < o_.near_bloom_m) {
      // A light right above the camera floods the sensor: a big saturated-looking blob that
      // only a higher threshold splits into its lamps (paper 1, Fig. 9).
      halo_r = core * (1.0 + 2.0 * (o_.near_bloom_m - dist) / o_.near_bloom_m);
      halo_level = 200.0;
    }
    blob(*px, core, halo_r, halo_level);
  }
  // Spurious lights: windows and reflections low over the horizon.
  std::poisson_distribution<int> spurious(o_.spurious_per_image);
  const int n = o_.spurious_per_image > 0 ? spurious(rng) : 0;
  for (int k = 0; k < n; ++k) {
    const double theta = (60.0 + 30.0 * uni(rng)) * M_PI / 180.0;
    const double phi = 2 * M_PI * uni(rng);
    const Vector3d ray(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                       std::cos(theta));
    if (const auto p = model.project(ray)) blob(*p, 3.0 + 8.0 * uni(rng), 0.0, o_.background);
  }
  add_noise(img, o_.noise_sigma, rng);
  return img;
}

}  // namespace lampnav::sim
