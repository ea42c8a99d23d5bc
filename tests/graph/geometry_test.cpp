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

TEST(SignedAngle, LeftIsPositive) {
  EXPECT_NEAR(signed_angle(V(1, 0), V(0, 1)), M_PI / 2, 1e-12);
  EXPECT_NEAR(signed_angle(V(1, 0), V(0, -1)), -M_PI / 2, 1e-12);
}

}  // namespace
}  // namespace lampnav::graph
