#include <algorithm>
#include <cmath>
#include <random>

#include "lampnav/graph/geometry.hpp"
#include "lampnav_test.hpp"

namespace lampnav::graph {
namespace {

using V = Eigen::Vector2d;

Polygon square(double x0, double y0, double side) {
  return Polygon({{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}});
}

TEST(Polygon, AreaCentroidContainment) {
  const Polygon p = square(0, 0, 2);
  EXPECT_DOUBLE_EQ(p.area(), 4.0);
  EXPECT_GT(p.signed_area(), 0);
  EXPECT_LT((p.centroid() - V(1, 1)).norm(), 1e-12);
  EXPECT_TRUE(p.contains(V(1, 1)));
  EXPECT_TRUE(p.contains(V(2, 1)));  // boundary counts
  EXPECT_FALSE(p.contains(V(2.01, 1)));
  // An L shape: the notch is outside.
  const Polygon l({{0, 0}, {4, 0}, {4, 1}, {1, 1}, {1, 4}, {0, 4}});
  EXPECT_DOUBLE_EQ(l.area(), 7.0);
  EXPECT_TRUE(l.contains(V(0.5, 3)));
  EXPECT_FALSE(l.contains(V(3, 3)));
}

TEST(Polygon, SelfIntersection) {
  EXPECT_FALSE(square(0, 0, 1).self_intersects());
  EXPECT_TRUE(Polygon({{0, 0}, {1, 1}, {1, 0}, {0, 1}}).self_intersects());  // bow tie
  EXPECT_TRUE(
      Polygon({{0, 0}, {2, 0}, {2, 2}, {2, 2}, {0, 2}}).self_intersects());  // repeated vertex
  EXPECT_FALSE(Polygon({{0, 0}, {4, 0}, {4, 1}, {1, 1}, {1, 4}, {0, 4}}).self_intersects());
}

TEST(Polygon, TriangulationCoversTheArea) {
  const Polygon l({{0, 0}, {4, 0}, {4, 1}, {1, 1}, {1, 4}, {0, 4}});
  double sum = 0;
  for (const auto& t : l.triangulate()) sum += Polygon({t[0], t[1], t[2]}).area();
  EXPECT_NEAR(sum, l.area(), 1e-12);
}

TEST(IntersectionArea, KnownOverlaps) {
  EXPECT_NEAR(intersection_area(square(0, 0, 2), square(1, 1, 2)), 1.0, 1e-12);
  EXPECT_NEAR(intersection_area(square(0, 0, 2), square(2, 0, 2)), 0.0, 1e-12);  // touching
  EXPECT_NEAR(intersection_area(square(0, 0, 2), square(5, 5, 2)), 0.0, 1e-12);
  const Polygon l({{0, 0}, {4, 0}, {4, 1}, {1, 1}, {1, 4}, {0, 4}});
  EXPECT_NEAR(intersection_area(l, square(2, 2, 2)), 0.0, 1e-12);  // in the notch
  EXPECT_NEAR(intersection_area(l, square(0, 0, 4)), 7.0, 1e-9);
}

TEST(IntersectionArea, MatchesMonteCarloOnRandomSquares) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 3);
  for (int i = 0; i < 50; ++i) {
    const Polygon a = square(u(rng), u(rng), 1 + u(rng));
    const Polygon b({{u(rng), u(rng)}, {u(rng) + 3, u(rng)}, {u(rng) + 3, u(rng) + 3}});
    int hits = 0;
    const int n = 20000;
    std::uniform_real_distribution<double> s(0, 7);
    for (int k = 0; k < n; ++k) {
      const V p(s(rng), s(rng));
      hits += a.contains(p, 0) && b.contains(p, 0);
    }
    EXPECT_NEAR(intersection_area(a, b), 49.0 * hits / n, 0.35);
  }
}

// The hull of random points holds every one of them, is convex and counter-clockwise, and each
// vertex is one of the points; points on a line have no hull.
TEST(ConvexHull, HoldsEveryPointAndIsConvex) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<V> pts(3 + trial);
    for (auto& p : pts) p = V(u(rng), u(rng));
    const Polygon h = convex_hull(pts);
    ASSERT_GE(h.size(), 3u);
    EXPECT_GT(h.signed_area(), 0);
    EXPECT_FALSE(h.self_intersects());
    for (const auto& p : pts) EXPECT_TRUE(h.contains(p, 1e-9));
    const auto& v = h.vertices();
    for (std::size_t i = 0; i < v.size(); ++i) {
      EXPECT_NE(std::find(pts.begin(), pts.end(), v[i]), pts.end());
      const V a = v[(i + 1) % v.size()] - v[i], b = v[(i + 2) % v.size()] - v[(i + 1) % v.size()];
      EXPECT_GT(a.x() * b.y() - a.y() * b.x(), 0) << "vertex " << i;  // a left turn at each
    }
  }
  EXPECT_EQ(convex_hull({{0, 0}, {1, 1}, {2, 2}, {1, 1}}).size(), 2u);
  const Polygon sq = convex_hull({{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 0}});
  EXPECT_EQ(sq.size(), 4u);
  EXPECT_DOUBLE_EQ(sq.area(), 4.0);
}

TEST(Segments, NearestPointsAndDistance) {
  EXPECT_LT((closest_on_segment(V(1, 1), V(0, 0), V(2, 0)) - V(1, 0)).norm(), 1e-12);
  EXPECT_LT((closest_on_segment(V(5, 1), V(0, 0), V(2, 0)) - V(2, 0)).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(segment_distance(V(0, 0), V(2, 0), V(1, -1), V(1, 1)), 0.0);  // crossing
  EXPECT_DOUBLE_EQ(segment_distance(V(0, 0), V(2, 0), V(0, 3), V(2, 3)), 3.0);   // parallel
  EXPECT_DOUBLE_EQ(segment_distance(V(0, 0), V(2, 0), V(3, 1), V(5, 1)), std::sqrt(2.0));
  const Polygon sq = square(0, 0, 2);
  EXPECT_LT((sq.nearest_on_boundary(V(1, 1.5)) - V(1, 2)).norm(), 1e-12);
  EXPECT_LT((sq.nearest_on_boundary(V(3, 3)) - V(2, 2)).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(sq.distance_to_boundary(V(1, 1.5)), 0.5);
}

TEST(ClipLeftOf, KeepsTheLeftSide) {
  const Polygon sq = square(0, 0, 2);
  const Polygon left = clip_left_of(sq, V(0.5, 0), V(0.5, 1));  // x <= 0.5 is left going up
  EXPECT_NEAR(left.area(), 1.0, 1e-12);
  EXPECT_TRUE(left.contains(V(0.25, 1)));
  EXPECT_FALSE(left.contains(V(1, 1)));
  EXPECT_NEAR(clip_left_of(sq, V(5, 0), V(5, 1)).area(), 4.0, 1e-12);  // all of it
  EXPECT_LT(clip_left_of(sq, V(-1, 0), V(-1, 1)).size(), 3u);          // none of it
  EXPECT_NEAR(clip_left_of(sq, V(0, 0), V(2, 2)).area(), 2.0, 1e-12);  // the diagonal
}

TEST(SignedAngle, LeftIsPositive) {
  EXPECT_NEAR(signed_angle(V(1, 0), V(0, 1)), M_PI / 2, 1e-12);
  EXPECT_NEAR(signed_angle(V(1, 0), V(0, -1)), -M_PI / 2, 1e-12);
}

}  // namespace
}  // namespace lampnav::graph
