#include <random>

#include "lampnav/core/pose2.hpp"
#include "lampnav_test.hpp"

namespace lampnav {
namespace {

using test::IsNearPose;

TEST(WrapAngle, WrapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrap_angle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(wrap_angle(M_PI), M_PI);
  EXPECT_DOUBLE_EQ(wrap_angle(-M_PI), M_PI);  // (-pi, pi]: -pi maps to +pi
  EXPECT_NEAR(wrap_angle(3 * M_PI / 2), -M_PI / 2, 1e-12);
  EXPECT_NEAR(wrap_angle(-5 * M_PI / 2), -M_PI / 2, 1e-12);
  EXPECT_NEAR(wrap_angle(100.0), std::remainder(100.0, 2 * M_PI), 1e-12);
}

TEST(Pose2, ComposeKnownValues) {
  const Pose2 a(1, 2, M_PI / 2);
  const Pose2 b(3, 0, 0);
  EXPECT_THAT(a * b, IsNearPose(Pose2(1, 5, M_PI / 2), 1e-12, 1e-12));
  EXPECT_THAT(a.transform_from(Eigen::Vector2d(1, 0)).eval(),
              ::testing::Truly([](const Eigen::Vector2d& p) {
                return (p - Eigen::Vector2d(1, 3)).norm() < 1e-12;
              }));
}

// Property battery: compose/inverse round trips over random poses (manif's style).
TEST(Pose2, RoundTripProperties) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> pos(-50, 50), ang(-M_PI, M_PI);
  for (int i = 0; i < 2000; ++i) {
    const Pose2 a(pos(rng), pos(rng), ang(rng));
    const Pose2 b(pos(rng), pos(rng), ang(rng));
    const Pose2 c(pos(rng), pos(rng), ang(rng));
    EXPECT_THAT(a * a.inverse(), IsNearPose(Pose2::identity(), 1e-9, 1e-12));
    EXPECT_THAT(a.inverse() * a, IsNearPose(Pose2::identity(), 1e-9, 1e-12));
    EXPECT_THAT((a * b) * c, IsNearPose(a * (b * c), 1e-9, 1e-12));
    EXPECT_THAT(a * a.between(b), IsNearPose(b, 1e-9, 1e-12));
    const Eigen::Vector2d p(pos(rng), pos(rng));
    EXPECT_LT((a.transform_to(a.transform_from(p)) - p).norm(), 1e-9);
    EXPECT_LT(((a * b).transform_from(p) - a.transform_from(b.transform_from(p))).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace lampnav
