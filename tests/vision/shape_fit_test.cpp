// Completion's rectangle fit (vision/src/shape_fit.hpp, white-box): its normal equations come from
// moments kept per part of the shape (the two ends and the two sides), updated only for the points
// that change part. Here it is compared with the same Gauss-Newton fit written point by point from
// its definition, on edge points of rectangles cut by an image border, with noise and fringe.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <random>
#include <vector>

#include "shape_fit.hpp"

namespace lampnav::vision::detail {
namespace {

using Eigen::Vector2d;

// The definition: each point on the nearer of end and side, residual |q| - half size, Jacobian
// by hand, summed point by point; the same dropping and stopping rules as fit_shape.
ShapeFit by_definition(const EdgePoints& pts, double a, double b, Vector2d c, double theta,
                       double min_drop) {
  ShapeFit fit;
  std::vector<bool> use(pts.size(), true);
  double rms = 0;
  bool dropping = false;
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
    const double cs = std::cos(theta), sn = std::sin(theta);
    const double drop = dropping ? std::max(min_drop, 3.0 * rms) : HUGE_VAL;
    double sum2 = 0;
    int ends = 0, sides = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vector2d d = pts[i] - c;
      const double qx = cs * d.x() + sn * d.y(), qy = -sn * d.x() + cs * d.y();
      const double rx = std::fabs(qx) - a, ry = std::fabs(qy) - b;
      const bool end = std::fabs(rx) < std::fabs(ry);
      const double r = end ? rx : ry;
      if (!use[i] || std::fabs(r) > drop) {
        use[i] = false;
        continue;
      }
      // d|q_x|/d(c, theta) = sign(q_x) (-cos, -sin, q_y); d|q_y| = sign(q_y) (sin, -cos, -q_x).
      const double s = end ? (qx >= 0 ? 1 : -1) : (qy >= 0 ? 1 : -1);
      const Eigen::Vector3d J =
          end ? Eigen::Vector3d(-cs, -sn, qy) * s : Eigen::Vector3d(sn, -cs, -qx) * s;
      JtJ += J * J.transpose();
      Jtr += J * r;
      sum2 += r * r;
      ++(end ? ends : sides);
    }
    const int n = ends + sides;
    if (n < 12) return fit;
    rms = std::sqrt(sum2 / n);
    fit.points = n;
    fit.rms = rms;
    if (ends < 4 || sides < 8) return fit;
    // J^T J is symmetric and semi-definite: its singular values are its eigenvalues.
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(JtJ, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Vector3d sv = svd.singularValues();  // largest first
    if (sv(2) < 1e-9 * std::max(1.0, sv(0))) return fit;
    const Eigen::Vector3d delta = svd.solve(-Jtr);
    c += delta.head<2>();
    theta += delta(2);
    const bool small_step = delta.head<2>().norm() < 1e-6 && std::fabs(delta(2)) < 1e-5;
    if (dropping && small_step) break;
    if (small_step || it >= 2) dropping = true;
  }
  fit.centre = c;
  fit.orientation = theta;
  fit.ok = true;
  return fit;
}

// Edge points of a rectangle (half sizes a, b) centred at c with heading theta, a point every
// `step` along its outline, those past the cut line x = cut dropped; noise of `sigma`, and a few
// fringe points off the outline.
EdgePoints cut_rectangle(std::mt19937& rng, Vector2d c, double theta, double a, double b,
                         double cut, double step, double sigma, int fringe) {
  std::normal_distribution<double> noise(0, sigma);
  std::uniform_real_distribution<double> unit(0, 1);
  const Eigen::Rotation2Dd R(theta);
  EdgePoints pts;
  auto add = [&](const Vector2d& q) {
    const Vector2d p = c + R * q + Vector2d(noise(rng), noise(rng));
    if (p.x() < cut) pts.push_back(p);
  };
  for (double s = -a; s <= a; s += step) add({s, b}), add({s, -b});
  for (double t = -b + step; t < b; t += step) add({a, t}), add({-a, t});
  for (int k = 0; k < fringe; ++k)
    add({(2 * unit(rng) - 1) * 1.3 * a, (2 * unit(rng) - 1) * 1.6 * b});
  return pts;
}

TEST(ShapeFit, SameRectangleAsTheFitSummedPointByPoint) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  const double px = 1.0 / 300;  // one pixel in normalized units at fx = 300
  FitScratch scratch;
  int fitted = 0, refused = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const double a = (40 + 60 * unit(rng)) * px, b = a * (0.2 + 0.3 * unit(rng));
    const double theta = 3.2 * unit(rng) - 1.6;
    const Vector2d c(0.3 * unit(rng) - 0.15, 0.3 * unit(rng) - 0.15);
    // Cut anywhere from well past the centre to just inside the far end.
    const double cut = c.x() + (1.2 * unit(rng) - 0.6) * a;
    const EdgePoints pts = cut_rectangle(rng, c, theta, a, b, cut, (0.5 + unit(rng)) * px,
                                         (0.05 + 0.3 * unit(rng)) * px, trial % 4 == 0 ? 0 : 12);
    // Started a few pixels and degrees off, as completion's guesses are.
    const Vector2d start = c + Vector2d(unit(rng) - 0.5, unit(rng) - 0.5) * 8 * px;
    const double theta0 = theta + (unit(rng) - 0.5) * 0.1;
    const ShapeFit want = by_definition(pts, a, b, start, theta0, 2 * px);
    const ShapeFit got = fit_shape(pts, true, a, b, start, theta0, 2 * px, scratch);
    SCOPED_TRACE("trial " + std::to_string(trial));
    ASSERT_EQ(got.ok, want.ok);
    ASSERT_EQ(got.points, want.points);
    EXPECT_NEAR(got.rms, want.rms, 1e-9 * px + 1e-9 * want.rms);
    if (!want.ok) {
      ++refused;
      continue;
    }
    ++fitted;
    EXPECT_NEAR((got.centre - want.centre).norm(), 0, 1e-6 * px);
    EXPECT_NEAR(got.orientation, want.orientation, 1e-8);
  }
  // Both kinds of ending are exercised: fits, and cuts that leave no end or too little side.
  EXPECT_GT(fitted, 250);
  EXPECT_GT(refused, 10);
}

}  // namespace
}  // namespace lampnav::vision::detail
