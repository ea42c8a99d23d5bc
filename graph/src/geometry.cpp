#include "lampnav/graph/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace lampnav::graph {

using Eigen::Vector2d;

namespace {
double cross(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
double orient(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  return cross(b - a, c - a);
}
bool on_segment(const Vector2d& a, const Vector2d& b, const Vector2d& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= p.y() && p.y() <= std::max(a.y(), b.y());
}
// The part of the convex polygon `v` left of the directed line a -> b (Sutherland-Hodgman, one
// edge): the vertices on or left of it, and where its edges cross it.
std::vector<Vector2d> clip_left(const std::vector<Vector2d>& v, const Vector2d& a,
                                const Vector2d& b) {
  std::vector<Vector2d> out;
  out.reserve(v.size() + 2);
  for (std::size_t j = 0; j < v.size(); ++j) {
    const Vector2d& p = v[j];
    const Vector2d& q = v[(j + 1) % v.size()];
    const double dp = orient(a, b, p), dq = orient(a, b, q);
    if (dp >= 0) out.push_back(p);
    if ((dp > 0 && dq < 0) || (dp < 0 && dq > 0)) out.push_back(p + (q - p) * (dp / (dp - dq)));
  }
  return out;
}

// Clips convex polygon `subject` by the convex counter-clockwise polygon `clip`, returning the
// area of what is left.
double convex_intersection_area(std::vector<Vector2d> subject,
                                const std::array<Vector2d, 3>& clip) {
  for (std::size_t i = 0; i < 3 && !subject.empty(); ++i)
    subject = clip_left(subject, clip[i], clip[(i + 1) % 3]);
  if (subject.size() < 3) return 0.0;
  double a2 = 0;
  for (std::size_t j = 0; j < subject.size(); ++j)
    a2 += cross(subject[j], subject[(j + 1) % subject.size()]);
  return std::fabs(a2) * 0.5;
}
}  // namespace

bool Box2::intersects(const Box2& o, double margin) const {
  return min.x() <= o.max.x() + margin && o.min.x() <= max.x() + margin &&
         min.y() <= o.max.y() + margin && o.min.y() <= max.y() + margin;
}

bool Box2::contains(const Vector2d& p, double margin) const {
  return p.x() >= min.x() - margin && p.x() <= max.x() + margin && p.y() >= min.y() - margin &&
         p.y() <= max.y() + margin;
}

Polygon::Polygon(std::vector<Vector2d> vertices) : v_(std::move(vertices)) {
  if (v_.empty()) return;
  box_.min = box_.max = v_.front();
  for (const auto& p : v_) {
    box_.min = box_.min.cwiseMin(p);
    box_.max = box_.max.cwiseMax(p);
  }
}

double Polygon::signed_area() const {
  double a2 = 0;
  for (std::size_t i = 0; i < v_.size(); ++i) a2 += cross(v_[i], v_[(i + 1) % v_.size()]);
  return 0.5 * a2;
}

double Polygon::area() const { return std::fabs(signed_area()); }

Vector2d Polygon::centroid() const {
  const double a = signed_area();
  if (std::fabs(a) < 1e-12) {
    Vector2d m = Vector2d::Zero();
    for (const auto& p : v_) m += p;
    return v_.empty() ? m : Vector2d(m / static_cast<double>(v_.size()));
  }
  Vector2d c = Vector2d::Zero();
  for (std::size_t i = 0; i < v_.size(); ++i) {
    const auto& p = v_[i];
    const auto& q = v_[(i + 1) % v_.size()];
    c += (p + q) * cross(p, q);
  }
  return c / (6.0 * a);
}

Vector2d Polygon::nearest_on_boundary(const Vector2d& p) const {
  Vector2d best = v_.empty() ? p : v_.front();
  for (std::size_t i = 0; i < v_.size(); ++i) {
    const Vector2d q = closest_on_segment(p, v_[i], v_[(i + 1) % v_.size()]);
    if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
  }
  return best;
}

double Polygon::distance_to_boundary(const Vector2d& p) const {
  return v_.empty() ? INFINITY : (nearest_on_boundary(p) - p).norm();
}

Vector2d closest_on_segment(const Vector2d& p, const Vector2d& a, const Vector2d& b) {
  const Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return a + t * ab;
}

double segment_distance(const Vector2d& a, const Vector2d& b, const Vector2d& c,
                        const Vector2d& d) {
  if (segments_intersect(a, b, c, d)) return 0;
  return std::min(
      {(closest_on_segment(a, c, d) - a).norm(), (closest_on_segment(b, c, d) - b).norm(),
       (closest_on_segment(c, a, b) - c).norm(), (closest_on_segment(d, a, b) - d).norm()});
}

bool Polygon::contains(const Vector2d& p, double tolerance) const {
  if (v_.size() < 3 || !box_.contains(p, tolerance)) return false;
  bool inside = false;
  for (std::size_t i = 0, j = v_.size() - 1; i < v_.size(); j = i++) {
    const Vector2d& a = v_[i];
    const Vector2d& b = v_[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside || distance_to_boundary(p) <= tolerance;
}

bool segments_intersect(const Vector2d& p1, const Vector2d& p2, const Vector2d& q1,
                        const Vector2d& q2) {
  const double d1 = orient(q1, q2, p1), d2 = orient(q1, q2, p2);
  const double d3 = orient(p1, p2, q1), d4 = orient(p1, p2, q2);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) {
    return true;
  }
  return (d1 == 0 && on_segment(q1, q2, p1)) || (d2 == 0 && on_segment(q1, q2, p2)) ||
         (d3 == 0 && on_segment(p1, p2, q1)) || (d4 == 0 && on_segment(p1, p2, q2));
}

bool Polygon::self_intersects() const {
  const std::size_t n = v_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vector2d& a1 = v_[i];
    const Vector2d& a2 = v_[(i + 1) % n];
    if ((a2 - a1).squaredNorm() == 0.0) return true;  // repeated vertex
    // Adjacent edge folding back onto this one (a spike of zero width).
    const Vector2d& a3 = v_[(i + 2) % n];
    if (n > 3 && orient(a1, a2, a3) == 0.0 && (a3 - a2).dot(a1 - a2) > 0) return true;
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (segments_intersect(a1, a2, v_[j], v_[(j + 1) % n])) return true;
    }
  }
  return false;
}

std::vector<std::array<Vector2d, 3>> Polygon::triangulate() const {
  std::vector<Vector2d> ring = v_;
  if (signed_area() < 0) std::reverse(ring.begin(), ring.end());
  std::vector<std::array<Vector2d, 3>> tris;
  if (ring.size() < 3) return tris;
  tris.reserve(ring.size() - 2);
  std::size_t guard = 0;
  while (ring.size() > 3 && guard < 4 * v_.size() * v_.size()) {
    bool clipped = false;
    const std::size_t n = ring.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vector2d& a = ring[(i + n - 1) % n];
      const Vector2d& b = ring[i];
      const Vector2d& c = ring[(i + 1) % n];
      if (orient(a, b, c) <= 0) continue;  // reflex or collinear: not an ear
      bool empty = true;
      for (std::size_t k = 0; k < n && empty; ++k) {
        const Vector2d& p = ring[k];
        if (p == a || p == b || p == c) continue;
        empty = !(orient(a, b, p) >= 0 && orient(b, c, p) >= 0 && orient(c, a, p) >= 0);
      }
      if (!empty) continue;
      tris.push_back({a, b, c});
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
      break;
    }
    if (!clipped) {
      // Only collinear vertices left to remove (zero-area slivers): drop one and go on.
      for (std::size_t i = 0; i < ring.size(); ++i) {
        const std::size_t m = ring.size();
        if (orient(ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]) == 0) {
          ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
          clipped = true;
          break;
        }
      }
      if (!clipped) break;
    }
    ++guard;
  }
  if (ring.size() == 3 && orient(ring[0], ring[1], ring[2]) > 0)
    tris.push_back({ring[0], ring[1], ring[2]});
  return tris;
}

double intersection_area(const Polygon& a, const Polygon& b) {
  if (!a.bounds().intersects(b.bounds())) return 0.0;
  const auto ta = a.triangulate();
  const auto tb = b.triangulate();
  double area = 0;
  for (const auto& t : ta) {
    Box2 bt{t[0].cwiseMin(t[1]).cwiseMin(t[2]), t[0].cwiseMax(t[1]).cwiseMax(t[2])};
    if (!bt.intersects(b.bounds())) continue;
    for (const auto& u : tb) {
      Box2 bu{u[0].cwiseMin(u[1]).cwiseMin(u[2]), u[0].cwiseMax(u[1]).cwiseMax(u[2])};
      if (!bt.intersects(bu)) continue;
      area += convex_intersection_area({t[0], t[1], t[2]}, u);
    }
  }
  return area;
}

Polygon convex_hull(std::vector<Vector2d> pts) {
  std::sort(pts.begin(), pts.end(), [](const Vector2d& a, const Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return Polygon(pts);
  std::vector<Vector2d> hull(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {  // lower chain
    while (k >= 2 && orient(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && orient(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);  // the last point is the first
  return Polygon(std::move(hull));
}

Polygon clip_left_of(const Polygon& convex, const Vector2d& a, const Vector2d& b) {
  return Polygon(clip_left(convex.vertices(), a, b));
}

double signed_angle(const Vector2d& a, const Vector2d& b) {
  return std::atan2(cross(a, b), a.dot(b));
}

}  // namespace lampnav::graph
