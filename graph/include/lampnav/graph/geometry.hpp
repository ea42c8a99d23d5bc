#pragma once
// Planar geometry for map regions: simple polygons, containment, overlap area.

#include <Eigen/Core>
#include <array>
#include <vector>

namespace lampnav::graph {

struct Box2 {
  Eigen::Vector2d min{0, 0}, max{0, 0};
  bool intersects(const Box2& o, double margin = 0.0) const;
  bool contains(const Eigen::Vector2d& p, double margin = 0.0) const;
};

class Polygon {
 public:
  Polygon() = default;
  explicit Polygon(std::vector<Eigen::Vector2d> vertices);

  const std::vector<Eigen::Vector2d>& vertices() const { return v_; }
  std::size_t size() const { return v_.size(); }

  // Positive when the vertices run counter-clockwise.
  double signed_area() const;
  double area() const;
  Eigen::Vector2d centroid() const;
  Box2 bounds() const { return box_; }
  // Points on the boundary (within `tolerance`) count as inside.
  bool contains(const Eigen::Vector2d& p, double tolerance = 1e-9) const;
  double distance_to_boundary(const Eigen::Vector2d& p) const;
  // The point of the boundary nearest p (p itself for a polygon with no vertices).
  Eigen::Vector2d nearest_on_boundary(const Eigen::Vector2d& p) const;
  // True when two non-adjacent edges touch or cross, or two adjacent edges fold back on each other.
  bool self_intersects() const;
  // Triangles (counter-clockwise) covering the polygon exactly, by ear clipping.
  std::vector<std::array<Eigen::Vector2d, 3>> triangulate() const;

 private:
  std::vector<Eigen::Vector2d> v_;
  Box2 box_;
};

// Area of the intersection of two simple polygons.
double intersection_area(const Polygon& a, const Polygon& b);

// The smallest convex polygon holding every point, counter-clockwise, without collinear
// vertices (Andrew's monotone chain). Fewer than three vertices when the points are collinear.
Polygon convex_hull(std::vector<Eigen::Vector2d> points);

// The part of convex polygon `convex` left of the directed line a -> b (Sutherland-Hodgman).
Polygon clip_left_of(const Polygon& convex, const Eigen::Vector2d& a, const Eigen::Vector2d& b);

// Signed angle from direction a to direction b, in (-pi, pi]; positive is a left (CCW) turn.
double signed_angle(const Eigen::Vector2d& a, const Eigen::Vector2d& b);

// The point of segment a-b nearest p.
Eigen::Vector2d closest_on_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                   const Eigen::Vector2d& b);

// The distance between closed segments a-b and c-d (0 when they share a point).
double segment_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                        const Eigen::Vector2d& c, const Eigen::Vector2d& d);

// Whether closed segments p1-p2 and q1-q2 share a point.
bool segments_intersect(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2,
                        const Eigen::Vector2d& q1, const Eigen::Vector2d& q2);

}  // namespace lampnav::graph
