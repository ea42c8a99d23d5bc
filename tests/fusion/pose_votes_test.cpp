// Votes for poses counted in eight shifted grids (fusion/src/pose_votes.hpp): poses that agree
// are one place whatever their place against the cells' borders, and a place is counted once.

#include "pose_votes.hpp"

#include <cmath>
#include <random>

#include "lampnav_test.hpp"

namespace lampnav::fusion::detail {
namespace {

constexpr double kDeg = M_PI / 180;

// Three poses within 4 cm and 1 degree of (0.5, 1.0, 30 deg), that point lying on a corner of
// the 0.25 m x 3 degree cells (30 deg + 180 deg is a multiple of 3): one grid gives each of them
// a cell of its own.
TEST(PoseVotes, PosesAcrossACellsCornerAreOnePlace) {
  PoseVotes v;
  v.add(Pose2(0.49, 1.02, 29.6 * kDeg));
  v.add(Pose2(0.52, 0.98, 30.4 * kDeg));
  v.add(Pose2(0.51, 1.01, 29.8 * kDeg));
  // Look-alikes: two poses agreeing inside one cell, twice.
  v.add(Pose2(10.10, 3.10, 91 * kDeg));
  v.add(Pose2(10.12, 3.11, 91.5 * kDeg));
  v.add(Pose2(20.10, 3.10, 91 * kDeg));
  v.add(Pose2(20.12, 3.11, 91.5 * kDeg));
  const auto best = v.best(10);
  ASSERT_EQ(best.size(), 3u);
  EXPECT_EQ(best[0].votes, 3);
  EXPECT_NEAR(best[0].pose.x(), (0.49 + 0.52 + 0.51) / 3, 1e-9);
  EXPECT_NEAR(best[0].pose.y(), (1.02 + 0.98 + 1.01) / 3, 1e-9);
  EXPECT_NEAR(best[0].pose.yaw(), 29.933 * kDeg, 0.01 * kDeg);
  EXPECT_EQ(best[1].votes, 2);
  EXPECT_EQ(best[2].votes, 2);
  EXPECT_EQ(v.places_with_at_least(3, 100), 1u);
  EXPECT_EQ(v.places_with_at_least(2, 100), 3u);
  EXPECT_EQ(v.places_with_at_least(1, 100), 3u);
}

// Headings either side of the half turn are one place: the yaw cells go round.
TEST(PoseVotes, HeadingsAcrossTheHalfTurnAreOnePlace) {
  PoseVotes v;
  v.add(Pose2(4.1, 4.1, M_PI - 0.2 * kDeg));
  v.add(Pose2(4.1, 4.1, -M_PI + 0.2 * kDeg));
  v.add(Pose2(9.1, 4.1, 0));
  const auto best = v.best(10);
  ASSERT_EQ(best.size(), 2u);
  EXPECT_EQ(best[0].votes, 2);
  EXPECT_NEAR(std::abs(best[0].pose.yaw()), M_PI, 1e-9);
}

// Poses that do not agree are places of their own, each counted once although eight grids hold
// it; the count stops past its limit.
TEST(PoseVotes, EachPlaceOnceAndCountsStopPastTheirLimit) {
  PoseVotes v;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 200; ++i)  // a lattice 1 m and 20 degrees apart, jittered by 5 cm and 1 deg
    v.add(Pose2((i % 10) + 0.05 * u(rng), (i / 10) + 0.05 * u(rng),
                (i % 7) * 20 * kDeg + u(rng) * kDeg));
  EXPECT_EQ(v.best(500).size(), 200u);
  EXPECT_EQ(v.places_with_at_least(1, 1000), 200u);
  EXPECT_EQ(v.places_with_at_least(1, 48), 49u);
  EXPECT_EQ(v.places_with_at_least(2, 1000), 0u);
  EXPECT_EQ(v.places_with_at_least(0, 1000), 200u);
  // The best n: the first n of the full order.
  const auto all = v.best(500);
  const auto ten = v.best(10);
  ASSERT_EQ(ten.size(), 10u);
  for (std::size_t k = 0; k < ten.size(); ++k) EXPECT_EQ(ten[k].pose.x(), all[k].pose.x());
}

// Poses absurdly far away (a map in the wrong units) are still places, without overflow.
TEST(PoseVotes, FarPosesAreCountedToo) {
  PoseVotes v;
  v.add(Pose2(3e11, -4e11, 0.1));
  v.add(Pose2(3e11, -4e11, 0.1));
  v.add(Pose2(1e300, 2.5, 0.1));
  v.add(Pose2(1.0, 2.5, 0.1));
  const auto best = v.best(10);
  ASSERT_EQ(best.size(), 3u);
  EXPECT_EQ(best[0].votes, 2);
  EXPECT_EQ(best[0].pose.x(), 3e11);
}

TEST(PoseVotes, NoVotesNoPlaces) {
  PoseVotes v;
  EXPECT_TRUE(v.best(10).empty());
  EXPECT_EQ(v.places_with_at_least(1, 10), 0u);
}

}  // namespace
}  // namespace lampnav::fusion::detail
