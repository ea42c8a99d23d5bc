#include "lampnav/fusion/merit.hpp"

#include <algorithm>
#include <cmath>

#include "lampnav/core/error.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::fusion {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {
constexpr int kTableSize = 4096;
constexpr double kCell = 16.0;  // px, the merit function's lookup cells
}  // namespace

CeilingMapProjection::CeilingMapProjection(const graph::TopologicalMap& map,
                                           const CameraDescription& camera)
    : mount_Rt_(camera.mount.rotation().transpose()), mount_t_(camera.mount.xyz) {
  const vision::FisheyeCamera model(camera);  // throws for another model
  const FisheyeParameters& p = model.parameters();
  u0_ = p.u0;
  v0_ = p.v0;
  beta_ = p.beta;
  width_ = model.width();
  height_ = model.height();
  for (const auto& n : map.nodes())
    for (const auto& l : n.lamps) {
      lamps_.push_back(&l);
      origin_ += l.xyz.head<2>();
    }
  if (!lamps_.empty()) origin_ /= double(lamps_.size());
  for (const graph::Lamp* l : lamps_) {
    lx_.push_back(float(l->xyz.x() - origin_.x()));
    ly_.push_back(float(l->xyz.y() - origin_.y()));
    lz_.push_back(float(l->xyz.z()));
  }
  // g(s) = r / t with t = tan(theta / 2) and s = t^2: smooth, finite on the axis, so that a
  // pixel needs one square root and one division: r / rho = g(s) / (n + z).
  t_max_ = std::tan(model.max_theta() / 2);
  s_max_ = t_max_ * t_max_;
  g_table_.resize(kTableSize + 2);
  for (int k = 0; k < kTableSize + 2; ++k) {
    const double s = s_max_ * k / kTableSize;
    const double t = std::sqrt(s);
    // On the axis, the limit: theta = 2 atan(t) ~ 2 t.
    g_table_[k] = float(k == 0 ? model.radius(2e-7) / 1e-7 : model.radius(2 * std::atan(t)) / t);
  }
  s_step_inv_ = kTableSize / s_max_;
}

void CeilingMapProjection::project(const Pose2& robot, std::vector<Vector2d>& pixels,
                                   std::vector<int>* lamp) const {
  // Sized for every lamp, then cut to those in view: no capacity check per pixel.
  pixels.resize(lamps_.size());
  if (lamp) lamp->resize(lamps_.size());
  Vector2d* out = pixels.data();
  std::size_t n = 0;
  const double c = std::cos(robot.yaw()), s = std::sin(robot.yaw());
  // World -> camera: R = mount^T Rz(-yaw), camera centre C = (x, y, 0) + Rz(yaw) mount_t.
  Eigen::Matrix3d Rz_t;
  Rz_t << c, s, 0, -s, c, 0, 0, 0, 1;
  const Eigen::Matrix3d R = mount_Rt_ * Rz_t;
  // (Relative to the lamps' mean, as they are kept.)
  const Vector3d C(robot.x() - origin_.x() + c * mount_t_.x() - s * mount_t_.y(),
                   robot.y() - origin_.y() + s * mount_t_.x() + c * mount_t_.y(), mount_t_.z());
  const Vector3d RC = R * C;
  // Single precision from here: a pixel to 1e-4 px, and twice the square roots per cycle.
  const float r00 = float(R(0, 0)), r01 = float(R(0, 1)), r02 = float(R(0, 2));
  const float r10 = float(R(1, 0)), r11 = float(R(1, 1)), r12 = float(R(1, 2));
  const float r20 = float(R(2, 0)), r21 = float(R(2, 1)), r22 = float(R(2, 2));
  const float cx = float(RC.x()), cy = float(RC.y()), cz = float(RC.z());
  const float s_max = float(s_max_), step_inv = float(s_step_inv_);
  const float u0 = float(u0_), v0 = float(v0_), beta = float(beta_);
  const float w = float(width_) - 0.5f, h = float(height_) - 0.5f;
  const std::size_t n_lamps = lamps_.size();
  for (std::size_t i = 0; i < n_lamps; ++i) {
    const float X = lx_[i], Y = ly_[i], Z = lz_[i];
    const float vx = r00 * X + r01 * Y + r02 * Z - cx;
    const float vy = r10 * X + r11 * Y + r12 * Z - cy;
    const float vz = r20 * X + r21 * Y + r22 * Z - cz;
    const float rho2 = vx * vx + vy * vy;
    const float nz = std::sqrt(rho2 + vz * vz) + vz;
    // tan(theta / 2) = rho / (n + z); beyond the field of view when it exceeds t_max.
    if (!(nz > 0) || rho2 > s_max * nz * nz) continue;
    const float inv = 1.0f / nz;
    const float q = rho2 * inv * inv * step_inv;
    const int k = static_cast<int>(q);
    const float g = (g_table_[k] + (q - k) * (g_table_[k + 1] - g_table_[k])) * inv;
    const float u = u0 + g * vx, v = v0 + beta * g * vy;
    if (u < -0.5f || v < -0.5f || u > w || v > h) continue;
    out[n] = Vector2d(u, v);
    if (lamp) (*lamp)[n] = static_cast<int>(i);
    ++n;
  }
  pixels.resize(n);
  if (lamp) lamp->resize(n);
}

MeritFunction::MeritFunction(std::vector<Vector2d> detected, double threshold, int width,
                             int height)
    : detected_(std::move(detected)), threshold_(threshold) {
  if (!(threshold > 0)) throw Error("the merit threshold must be positive");
  cols_ = std::max(1, static_cast<int>(std::ceil((width + 1) / kCell)));
  rows_ = std::max(1, static_cast<int>(std::ceil((height + 1) / kCell)));
  // Each detection is listed in every cell with a point closer to it than the threshold.
  // Compressed rows, in two passes over the cells each detection covers (no list per cell: this
  // runs for every image and every refined hypothesis).
  const double t2 = threshold * threshold;
  auto covered = [&](std::size_t j, auto&& visit) {
    const Vector2d q = detected_[j] + Vector2d(0.5, 0.5);  // cell coordinates start at -0.5 px
    const int x0 = std::max(0, static_cast<int>(std::floor((q.x() - threshold) / kCell)));
    const int x1 = std::min(cols_ - 1, static_cast<int>(std::floor((q.x() + threshold) / kCell)));
    const int y0 = std::max(0, static_cast<int>(std::floor((q.y() - threshold) / kCell)));
    const int y1 = std::min(rows_ - 1, static_cast<int>(std::floor((q.y() + threshold) / kCell)));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        // Distance from the detection to the cell's rectangle.
        const double dx = std::max({0.0, x * kCell - q.x(), q.x() - (x + 1) * kCell});
        const double dy = std::max({0.0, y * kCell - q.y(), q.y() - (y + 1) * kCell});
        if (dx * dx + dy * dy < t2) visit(y * cols_ + x);
      }
  };
  cell_start_.assign(static_cast<std::size_t>(cols_) * rows_ + 1, 0);
  for (std::size_t j = 0; j < detected_.size(); ++j)
    covered(j, [&](int cell) { ++cell_start_[cell + 1]; });
  for (std::size_t k = 1; k < cell_start_.size(); ++k) cell_start_[k] += cell_start_[k - 1];
  cell_items_.resize(cell_start_.back());
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t j = 0; j < detected_.size(); ++j)
    covered(j, [&](int cell) { cell_items_[fill[cell]++] = static_cast<int>(j); });
  claim_d2_.resize(detected_.size());
  claim_by_.resize(detected_.size());
}

void MeritFunction::claim(double x, double y, int i) const {
  const int cx = static_cast<int>((x + 0.5) * (1.0 / kCell));
  const int cy = static_cast<int>((y + 0.5) * (1.0 / kCell));
  if (cx < 0 || cy < 0 || cx >= cols_ || cy >= rows_) return;
  const int cell = cy * cols_ + cx;
  int best = -1;
  double best_d2 = threshold_ * threshold_;
  for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
    const int j = cell_items_[k];
    const double dx = detected_[j].x() - x, dy = detected_[j].y() - y;
    const double d2 = dx * dx + dy * dy;
    if (d2 < best_d2) {
      best_d2 = d2;
      best = j;
    }
  }
  // (1) within the threshold and (2) the nearest detection; (3) the closest claim wins.
  if (best < 0) return;
  if (claim_by_[best] < 0 || best_d2 < claim_d2_[best]) {
    claim_by_[best] = i;
    claim_d2_[best] = best_d2;
  }
}

Merit MeritFunction::tally(std::vector<std::pair<int, int>>* matches) const {
  Merit m;
  if (matches) matches->clear();
  for (std::size_t j = 0; j < detected_.size(); ++j) {
    if (claim_by_[j] < 0) {
      m.error_px += threshold_;
      continue;
    }
    ++m.matched;
    m.error_px += std::sqrt(claim_d2_[j]);
    if (matches) matches->emplace_back(claim_by_[j], static_cast<int>(j));
  }
  if (m.matched > 0) m.value = m.error_px / m.matched;
  return m;
}

Merit MeritFunction::operator()(const std::vector<Vector2d>& projected,
                                std::vector<std::pair<int, int>>* matches) const {
  std::fill(claim_by_.begin(), claim_by_.end(), -1);
  for (std::size_t i = 0; i < projected.size(); ++i)
    claim(projected[i].x(), projected[i].y(), static_cast<int>(i));
  return tally(matches);
}

}  // namespace lampnav::fusion
