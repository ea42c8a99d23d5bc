#include "shape_fit.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace lampnav::vision::detail {

using Eigen::Vector2d;

ShapeFit fit_shape(const EdgePoints& pts, bool rectangle, double a, double b, Vector2d c,
                   double theta, double min_drop, std::vector<char>& use) {
  ShapeFit fit;
  use.assign(pts.size(), 1);
  double rms = 0;
  // Points are dropped once the fit has settled on all of them (a step below the tolerance, or
  // after three iterations), and the fit ends when it settles again with the points it keeps.
  bool dropping = false;
  for (int it = 0; it < 20; ++it) {
    // The normal equations J^T J (symmetric: six sums) and J^T r.
    double h00 = 0, h01 = 0, h02 = 0, h11 = 0, h12 = 0, h22 = 0, g0 = 0, g1 = 0, g2 = 0;
    const double cs = std::cos(theta), sn = std::sin(theta);
    double sum2 = 0;
    int n = 0, ends = 0, sides = 0;
    const double drop = dropping ? std::max(min_drop, 3.0 * rms) : HUGE_VAL;
    if (rectangle) {
      // In the lamp's frame q = R^T (p - c), a point is on an end (|q_x| = a) or a side
      // (|q_y| = b), whichever is nearer; s is the sign of that coordinate. dq/dc = -R^T and
      // dq/dtheta = (q_y, -q_x), so an end's Jacobian row is s (-cos, -sin, q_y) and a side's
      // s (sin, -cos, -q_x): each class adds to J^T J a fixed part times its count plus its sums
      // of q and q^2, and to J^T r its sums of s r and s r q. Without branches, point by point.
      double n_end = 0, q_end = 0, qq_end = 0, sr_end = 0, srq_end = 0;
      double n_side = 0, q_side = 0, qq_side = 0, sr_side = 0, srq_side = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        const double dx = pts[i].x() - c.x(), dy = pts[i].y() - c.y();
        const double qx = cs * dx + sn * dy, qy = -sn * dx + cs * dy;
        const double rx = std::fabs(qx) - a, ry = std::fabs(qy) - b;
        const bool end = std::fabs(rx) < std::fabs(ry);
        const double r = end ? rx : ry;
        // Once dropped, a point stays dropped.
        const bool kept = use[i] && std::fabs(r) <= drop;
        use[i] = kept;
        const double we = kept && end ? 1.0 : 0.0, ws = kept && !end ? 1.0 : 0.0;
        const double srx = qx >= 0 ? rx : -rx, sry = qy >= 0 ? ry : -ry;
        n_end += we, q_end += we * qy, qq_end += we * qy * qy;
        sr_end += we * srx, srq_end += we * srx * qy;
        n_side += ws, q_side += ws * qx, qq_side += ws * qx * qx;
        sr_side += ws * sry, srq_side += ws * sry * qx;
        sum2 += (we + ws) * r * r;
      }
      ends = static_cast<int>(n_end);
      sides = static_cast<int>(n_side);
      n = ends + sides;
      h00 = n_end * cs * cs + n_side * sn * sn;
      h01 = (n_end - n_side) * cs * sn;
      h11 = n_end * sn * sn + n_side * cs * cs;
      h02 = -cs * q_end - sn * q_side;
      h12 = -sn * q_end + cs * q_side;
      h22 = qq_end + qq_side;
      g0 = -cs * sr_end + sn * sr_side;
      g1 = -sn * sr_end - cs * sr_side;
      g2 = srq_end - srq_side;
    } else {
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
    }
    if (n < 12) return fit;
    rms = std::sqrt(sum2 / n);
    fit.points = n;
    fit.rms = rms;
    // The fit must see an end and a long side of a rectangle, or its position along the lamp
    // (or across it) is not determined.
    if (rectangle && (ends < 4 || sides < 8)) return fit;
    Eigen::Matrix3d JtJ;
    JtJ << h00, h01, h02, h01, h11, h12, h02, h12, h22;
    const Eigen::Vector3d Jtr(g0, g1, g2);
    // A disc has no heading: pin it (unit information, zero gradient) and solve the same 3x3.
    if (!rectangle) JtJ(2, 2) = 1.0;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(JtJ, Eigen::EigenvaluesOnly);
    if (eig.eigenvalues()(0) < 1e-9 * std::max(1.0, eig.eigenvalues()(2))) return fit;
    const Eigen::Vector3d step = -JtJ.ldlt().solve(Jtr);
    c += step.head<2>();
    theta += step(2);
    const bool settled = step.head<2>().norm() < 1e-6 && std::fabs(step(2)) < 1e-5;
    if (settled && dropping) break;
    dropping = dropping || settled || it >= 2;
  }
  fit.centre = c;
  fit.orientation = theta;
  fit.ok = true;
  return fit;
}

}  // namespace lampnav::vision::detail
