#include "shape_fit.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

namespace lampnav::vision::detail {

using Eigen::Vector2d;

namespace {

// A rectangle's edge points fall in four classes: on an end (|q_x| = a) with q_x >= 0 or < 0, or
// on a side (|q_y| = b) with q_y >= 0 or < 0, q = R^T (p - c) in the lamp's frame. Within a class
// the normal equations are polynomials of degree two in the points, so each class keeps the
// moments of its points (about a fixed origin), and an iteration only has to find which points
// changed class: after the first, few do.
enum Class : char { end_pos = 0, end_neg, side_pos, side_neg, dropped, kClasses = dropped };

struct PointMoments {
  double n = 0, x = 0, y = 0, xx = 0, xy = 0, yy = 0;
  void add(const Vector2d& p, double k) {
    n += k, x += k * p.x(), y += k * p.y();
    xx += k * p.x() * p.x(), xy += k * p.x() * p.y(), yy += k * p.y() * p.y();
  }
};

// The class of a point: the nearer of end and side, and the sign of that coordinate; `r` its
// distance to the shape (signed: outside > 0). Without branches: ends and sides alternate along
// the edge points, and a mispredicted branch would cost more than the arithmetic.
Class classify(double qx, double qy, double a, double b, double& r) {
  const double rx = std::fabs(qx) - a, ry = std::fabs(qy) - b;
  const int end = std::fabs(rx) < std::fabs(ry);
  r = end ? rx : ry;
  return static_cast<Class>(end ? int(qx < 0) : 2 + int(qy < 0));
}

// One Gauss-Newton step on the centre and heading, iteration `it`. Points are dropped from the
// iteration after the fit first settles on all of them (a step below the tolerance, or after
// three iterations), and the fit is done when it settles again with the points it keeps.
enum class Step { singular, again, done };
Step gauss_newton_step(const Eigen::Matrix3d& JtJ, const Eigen::Vector3d& Jtr, int it, Vector2d& c,
                       double& theta, bool& dropping) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(JtJ, Eigen::EigenvaluesOnly);
  if (eig.eigenvalues()(0) < 1e-9 * std::max(1.0, eig.eigenvalues()(2))) return Step::singular;
  const Eigen::Vector3d step = -JtJ.ldlt().solve(Jtr);
  c += step.head<2>();
  theta += step(2);
  const bool settled = step.head<2>().norm() < 1e-6 && std::fabs(step(2)) < 1e-5;
  if (settled && dropping) return Step::done;
  dropping = dropping || settled || it >= 2;
  return Step::again;
}

ShapeFit fitted(ShapeFit fit, const Vector2d& c, double theta) {
  fit.centre = c;
  fit.orientation = theta;
  fit.ok = true;
  return fit;
}

ShapeFit fit_rectangle(const EdgePoints& pts, double a, double b, Vector2d c, double theta,
                       double min_drop, FitScratch& scratch) {
  ShapeFit fit;
  // Moments about the first centre, where the points are: small numbers, no cancellation.
  const Vector2d origin = c;
  std::array<PointMoments, kClasses> m{};
  std::vector<char>& cls = scratch.part;
  cls.assign(pts.size(), dropped);
  double rms = 0;
  bool dropping = false;  // gauss_newton_step's
  // A point's part (and whether it is dropped: |r| > max(min_drop, 3 rms) >= min_drop) depends on
  // the signs of q_x, q_y, |r_x| - |r_y| and min_drop - |r|. Moving the shape from (c0, theta0) to
  // (c, theta) moves q = R^T (p - c) by at most |c - c0| + |theta - theta0| |p - c0|, which
  // changes q_x, q_y and min_drop - |r| by at most that, and |r_x| - |r_y| by at most twice that.
  // So after a pass over every point at (c0, theta0), a point whose margin there (the least of
  // |q_x| or |q_y|, ||r_x| - |r_y|| / 2 and min_drop - |r|) is at least `far` keeps its part
  // until the shape has moved by `far`: only the others (`near`: by a corner, or near being
  // dropped) are looked at until then.
  const double far = 0.5 * min_drop;
  std::vector<int>& near = scratch.near;
  Vector2d c0 = c;
  double theta0 = theta, reach = 0;  // reach: max |p - c0| over the points in the fit
  for (int it = 0; it < 20; ++it) {
    const bool first = it == 0;  // every point is classed; after, only changes are moved
    const double cs = std::cos(theta), sn = std::sin(theta);
    const double drop = dropping ? std::max(min_drop, 3.0 * rms) : HUGE_VAL;
    // A little short of `far`, for rounding.
    const bool all =
        first || (c - c0).norm() + std::fabs(theta - theta0) * reach >= far * (1 - 1e-6);
    // Through local pointers: the classes are bytes, and a byte store could alias anything, so
    // the compiler would read the vectors' bounds again after each one.
    const Vector2d* const pt = pts.data();
    char* const cl = cls.data();
    const double cx = c.x(), cy = c.y();
    // Point i, of part `was` before: its part now, moved between the moments; its margin.
    const auto look = [&](std::size_t i, Class was, double& margin) {
      const double dx = pt[i].x() - cx, dy = pt[i].y() - cy;
      const double qx = cs * dx + sn * dy, qy = -sn * dx + cs * dy;
      double r;
      Class k = classify(qx, qy, a, b, r);
      margin =
          std::min({k < side_pos ? std::fabs(qx) : std::fabs(qy),
                    0.5 * std::fabs(std::fabs(std::fabs(qx) - a) - std::fabs(std::fabs(qy) - b)),
                    min_drop - std::fabs(r)});
      if (std::fabs(r) > drop) k = dropped;
      if (!first && k == was) return k;
      const Vector2d p = pt[i] - origin;
      if (!first) m[was].add(p, -1.0);
      if (k != dropped) m[k].add(p, 1.0);
      cl[i] = k;
      return k;
    };
    double margin;
    if (all) {
      c0 = c;
      theta0 = theta;
      near.clear();
      double reach2 = 0;
      const std::size_t count = pts.size();
      for (std::size_t i = 0; i < count; ++i) {
        const Class was = static_cast<Class>(cl[i]);
        if (!first && was == dropped) continue;  // once dropped, a point stays dropped
        if (look(i, was, margin) == dropped) continue;
        if (margin < far) near.push_back(static_cast<int>(i));
        reach2 = std::max(reach2, (pt[i] - c0).squaredNorm());
      }
      reach = std::sqrt(reach2);
    } else {
      for (const int i : near)
        if (cl[i] != dropped) look(static_cast<std::size_t>(i), static_cast<Class>(cl[i]), margin);
    }
    // Per class: T = sum (p - d) and P = sum (p - d)(p - d)^T, d = c - origin; then the sums of
    // q_x, q_y and their products follow from e = (cos, sin) and f = (-sin, cos).
    const Vector2d d = c - origin;
    const Vector2d e(cs, sn), f(-sn, cs);
    double n_end = 0, q_end = 0, qq_end = 0, sr_end = 0, srq_end = 0;
    double n_side = 0, q_side = 0, qq_side = 0, sr_side = 0, srq_side = 0, sum2 = 0;
    for (int k = 0; k < kClasses; ++k) {
      const PointMoments& s = m[k];
      if (s.n <= 0) continue;
      const Vector2d t(s.x - s.n * d.x(), s.y - s.n * d.y());
      Eigen::Matrix2d pp;
      pp(0, 0) = s.xx - 2 * s.x * d.x() + s.n * d.x() * d.x();
      pp(1, 1) = s.yy - 2 * s.y * d.y() + s.n * d.y() * d.y();
      pp(0, 1) = pp(1, 0) = s.xy - s.x * d.y() - s.y * d.x() + s.n * d.x() * d.y();
      const double sx = e.dot(t), sy = f.dot(t);  // sums of q_x and q_y
      const double sxx = e.dot(pp * e), syy = f.dot(pp * f), sxy = e.dot(pp * f);
      const double sign = (k == end_pos || k == side_pos) ? 1.0 : -1.0;
      if (k == end_pos || k == end_neg) {
        // r = sign q_x - a; the gradient's signed residual sign r = q_x - sign a.
        n_end += s.n, q_end += sy, qq_end += syy;
        sr_end += sx - sign * a * s.n, srq_end += sxy - sign * a * sy;
        sum2 += sxx - 2 * sign * a * sx + a * a * s.n;
      } else {
        n_side += s.n, q_side += sx, qq_side += sxx;
        sr_side += sy - sign * b * s.n, srq_side += sxy - sign * b * sx;
        sum2 += syy - 2 * sign * b * sy + b * b * s.n;
      }
    }
    const int ends = static_cast<int>(std::lround(n_end));
    const int sides = static_cast<int>(std::lround(n_side));
    const int n = ends + sides;
    if (n < 12) return fit;
    rms = std::sqrt(std::max(sum2, 0.0) / n);
    fit.points = n;
    fit.rms = rms;
    // The fit must see an end and a long side, or its position along the lamp (or across it) is
    // not determined.
    if (ends < 4 || sides < 8) return fit;
    // An end's Jacobian row is sign (-cos, -sin, q_y), a side's sign (sin, -cos, -q_x): each class
    // adds to J^T J a fixed part times its count plus its sums of q and q^2.
    Eigen::Matrix3d JtJ;
    JtJ(0, 0) = n_end * cs * cs + n_side * sn * sn;
    JtJ(0, 1) = JtJ(1, 0) = (n_end - n_side) * cs * sn;
    JtJ(1, 1) = n_end * sn * sn + n_side * cs * cs;
    JtJ(0, 2) = JtJ(2, 0) = -cs * q_end - sn * q_side;
    JtJ(1, 2) = JtJ(2, 1) = -sn * q_end + cs * q_side;
    JtJ(2, 2) = qq_end + qq_side;
    const Eigen::Vector3d Jtr(-cs * sr_end + sn * sr_side, -sn * sr_end - cs * sr_side,
                              srq_end - srq_side);
    const Step step = gauss_newton_step(JtJ, Jtr, it, c, theta, dropping);
    if (step == Step::singular) return fit;
    if (step == Step::done) break;
  }
  return fitted(fit, c, theta);
}

}  // namespace

ShapeFit fit_shape(const EdgePoints& pts, bool rectangle, double a, double b, Vector2d c,
                   double theta, double min_drop, FitScratch& scratch) {
  if (rectangle) return fit_rectangle(pts, a, b, c, theta, min_drop, scratch);
  std::vector<char>& use = scratch.part;  // 1 while a point is in the fit
  // A disc: its distance to a point needs the point's own square root, so it is summed point by
  // point. Its heading is pinned (unit information, zero gradient) and the same 3x3 solved.
  ShapeFit fit;
  use.assign(pts.size(), 1);
  double rms = 0;
  bool dropping = false;
  for (int it = 0; it < 20; ++it) {
    double h00 = 0, h01 = 0, h11 = 0, g0 = 0, g1 = 0, sum2 = 0;
    int n = 0;
    const double drop = dropping ? std::max(min_drop, 3.0 * rms) : HUGE_VAL;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (!use[i]) continue;  // once dropped, a point stays dropped
      const double dx = pts[i].x() - c.x(), dy = pts[i].y() - c.y();
      const double dn = std::sqrt(dx * dx + dy * dy);
      if (dn < 1e-12) continue;
      const double r = dn - a;
      if (std::fabs(r) > drop) {
        use[i] = 0;
        continue;
      }
      const double j0 = -dx / dn, j1 = -dy / dn;
      h00 += j0 * j0, h01 += j0 * j1, h11 += j1 * j1;
      g0 += j0 * r, g1 += j1 * r;
      sum2 += r * r;
      ++n;
    }
    if (n < 12) return fit;
    rms = std::sqrt(sum2 / n);
    fit.points = n;
    fit.rms = rms;
    Eigen::Matrix3d JtJ;
    JtJ << h00, h01, 0, h01, h11, 0, 0, 0, 1.0;
    const Step step = gauss_newton_step(JtJ, Eigen::Vector3d(g0, g1, 0), it, c, theta, dropping);
    if (step == Step::singular) return fit;
    if (step == Step::done) break;
  }
  return fitted(fit, c, theta);
}

}  // namespace lampnav::vision::detail
