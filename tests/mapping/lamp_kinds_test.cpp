// The kinds of lamp learnt from the lamps a drive saw whole (mapping/lamp_kinds.hpp).

#include "lampnav/mapping/lamp_kinds.hpp"

#include <gtest/gtest.h>

#include <random>

#include "lampnav/core/error.hpp"

namespace lampnav::mapping {
namespace {

// `n` looks of a lamp `length` x `width` seen from unit distance, a few percent apart (heights,
// the floor's bumps, the detector).
void add(std::vector<LampLook>& looks, int n, double length, double width, std::mt19937& rng) {
  std::normal_distribution<double> spread(1.0, 0.02);
  for (int k = 0; k < n; ++k) looks.push_back({length * spread(rng), width * spread(rng)});
}

// An office: strip lights down the corridors (1.2 x 0.3 m, 2.4 m above the camera) and round
// lamps in the rooms (0.6 m). A museum: large discs 11 m up beside small ones 3 m up.
TEST(LampKinds, TheBuildingsKindsAreFoundMostCommonFirst) {
  std::mt19937 rng(3);
  std::vector<LampLook> office;
  add(office, 400, 1.2 / 2.4, 0.3 / 2.4, rng);
  add(office, 30, 0.6 / 2.4, 0.6 / 2.4, rng);
  const auto kinds = lamp_kinds(office);
  ASSERT_EQ(kinds.size(), 2u);
  EXPECT_TRUE(kinds[0].rectangle);
  EXPECT_NEAR(kinds[0].length, 0.5, 0.01);
  EXPECT_NEAR(kinds[0].width, 0.125, 0.005);
  EXPECT_FALSE(kinds[1].rectangle);
  EXPECT_NEAR(kinds[1].length, 0.25, 0.005);
  EXPECT_EQ(nearest_kind(kinds, 0.52, 0.12), 0);
  EXPECT_EQ(nearest_kind(kinds, 0.24, 0.25), 1);

  std::vector<LampLook> museum;
  add(museum, 300, 0.5 / 11.1, 0.5 / 11.1, rng);
  add(museum, 60, 0.25 / 2.95, 0.25 / 2.95, rng);
  const auto round = lamp_kinds(museum);
  ASSERT_EQ(round.size(), 2u);
  EXPECT_NEAR(round[0].length, 0.045, 0.002);
  EXPECT_NEAR(round[1].length, 0.085, 0.003);
  // Between the two, the nearer in the logarithm: 0.06 is 0.29 from 0.045 and 0.35 from 0.085.
  EXPECT_EQ(nearest_kind(round, 0.06, 0.06), 0);
  EXPECT_EQ(nearest_kind(round, 0.07, 0.07), 1);
  // A long blob where the building has only round lamps is of the nearest round kind.
  EXPECT_EQ(nearest_kind(round, 0.2, 0.05), 1);
  EXPECT_EQ(nearest_kind({}, 0.2, 0.05), -1);
}

// One kind at a few heights (a ceiling with steps of 5 %) stays one kind; a few glints (a
// reflection, a person's white shirt) are none, however unlike the lamps they are.
TEST(LampKinds, OneKindAtSeveralHeightsAndAFewGlintsAreOneKind) {
  std::mt19937 rng(5);
  std::vector<LampLook> looks;
  for (const double h : {2.3, 2.4, 2.5, 2.6}) add(looks, 125, 1.2 / h, 0.3 / h, rng);
  add(looks, 7, 0.9, 0.9, rng);    // fewer than min_sightings
  add(looks, 9, 0.05, 0.05, rng);  // more, but under 2 % of 519
  add(looks, 3, 0.3, 0.03, rng);   // a long glint
  const auto kinds = lamp_kinds(looks);
  ASSERT_EQ(kinds.size(), 1u);
  EXPECT_TRUE(kinds[0].rectangle);
  EXPECT_NEAR(kinds[0].length, 1.2 / 2.45, 0.02);

  LampKindOptions strict;
  strict.min_share = 0;
  EXPECT_EQ(lamp_kinds(looks, strict).size(), 2u);  // the 9 small discs, then
  EXPECT_TRUE(lamp_kinds({}).empty());
  LampKindOptions bad;
  bad.split_log_gap = 0;
  EXPECT_THROW(lamp_kinds(looks, bad), InputError);
}

}  // namespace
}  // namespace lampnav::mapping
