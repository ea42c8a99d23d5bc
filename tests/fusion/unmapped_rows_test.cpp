// A row of lamps the map does not hold beside a row it holds (fusion/src/unmapped_rows.hpp): the
// wide corridor of tests/fixtures/maps/wide_corridor_row_beside.geojson (two rows 1.8 m apart,
// lamps 2.25 m apart along C1) with its second row taken out, as a drive under the first maps it.

#include "unmapped_rows.hpp"

#include "edited_map.hpp"
#include "lampnav/fusion/hypothesis_set.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

graph::TopologicalMap one_row() {
  const graph::TopologicalMap both =
      graph::read_map(test::source_path("tests/fixtures/maps/wide_corridor_row_beside.geojson"))
          .map;
  return test::edited(both, [](graph::Node& n) {
    std::vector<graph::Lamp> kept;
    for (const auto& l : n.lamps)
      if (l.id.value.back() != 'b') kept.push_back(l);
    n.lamps = kept;
  });
}

// Strays at (x, y) for each x, placed within `reach`.
std::vector<StraySighting> strays(std::initializer_list<double> xs, double y, double reach = 0.3) {
  std::vector<StraySighting> out;
  for (double x : xs) out.push_back({Eigen::Vector2d(x, y), reach});
  return out;
}

const Pose2 kInC1(14.0, 0.0, 0.0);

TEST(UnmappedRows, TheSecondRowOfAWideCorridorIsFoundBesideTheFirst) {
  const graph::TopologicalMap map = one_row();
  const auto row = detail::unmapped_row_beside(map, kInC1, strays({11.725, 13.975, 16.225}, 1.8),
                                               detail::UnmappedRowOptions{});
  ASSERT_TRUE(row.has_value());
  EXPECT_EQ(row->lamps, 3);
  EXPECT_NEAR(row->offset_m, 1.8, 0.01);
  EXPECT_NEAR(row->length_m, 4.5, 0.01);
  // Seen a few centimetres off, and with a stray elsewhere, it is the same row.
  auto seen = strays({11.7, 14.0, 16.25, 18.5}, 1.76);
  seen.push_back({Eigen::Vector2d(20.0, -3.0), 0.2});
  const auto again = detail::unmapped_row_beside(map, kInC1, seen, detail::UnmappedRowOptions{});
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->lamps, 4);
}

TEST(UnmappedRows, WhatIsNoRowBesideIsNotOne) {
  const graph::TopologicalMap map = one_row();
  const detail::UnmappedRowOptions o;
  // Too few lamps.
  EXPECT_FALSE(detail::unmapped_row_beside(map, kInC1, strays({11.725, 13.975}, 1.8), o));
  // Spaced as a room's grid (4.5 m apart, beside lamps 2.25 m apart).
  EXPECT_FALSE(detail::unmapped_row_beside(map, kInC1, strays({9.475, 13.975, 18.475}, 1.8), o));
  // Farther beside than row_beside_m (3.5 m).
  EXPECT_FALSE(detail::unmapped_row_beside(map, kInC1, strays({11.725, 13.975, 16.225}, 3.5), o));
  // The mapped row's own lamps seen a little off (0.3 m): no row beside.
  EXPECT_FALSE(detail::unmapped_row_beside(map, kInC1, strays({11.725, 13.975, 16.225}, 0.3), o));
  // Placed too loosely to tell where (the far blobs of the omni view).
  EXPECT_FALSE(
      detail::unmapped_row_beside(map, kInC1, strays({11.725, 13.975, 16.225}, 1.8, 2.0), o));
  // Out of view (beyond view_m of the pose).
  EXPECT_FALSE(
      detail::unmapped_row_beside(map, Pose2(0, 0, 0), strays({11.725, 13.975, 16.225}, 1.8), o));
  // A row across the corridor (a side corridor beyond a junction the map does not hold).
  std::vector<StraySighting> across;
  for (double y : {2.5, 4.75, 7.0}) across.push_back({Eigen::Vector2d(14.0, y), 0.3});
  EXPECT_FALSE(detail::unmapped_row_beside(map, kInC1, across, o));
}

// The strays of a hypothesis's last images are looked at together, and one lamp seen in several
// of them is one lamp.
TEST(UnmappedRows, ALampSeenInSeveralImagesIsOneLamp) {
  const graph::TopologicalMap map = one_row();
  const detail::UnmappedRowOptions o;
  Hypothesis h;
  h.keep_strays(strays({11.725, 13.975}, 1.8), 4);
  h.keep_strays(strays({11.75, 14.0}, 1.82), 4);
  h.keep_strays(strays({11.7}, 1.79), 4);
  EXPECT_EQ(h.strays.size(), 5u);
  EXPECT_FALSE(detail::unmapped_row_beside(map, kInC1, h.strays, o));  // two lamps
  h.keep_strays(strays({16.2}, 1.8), 4);
  const auto row = detail::unmapped_row_beside(map, kInC1, h.strays, o);
  ASSERT_TRUE(row.has_value());
  EXPECT_EQ(row->lamps, 3);
  // Four images without strays on, all are forgotten.
  for (int k = 0; k < 4; ++k) h.keep_strays({}, 4);
  EXPECT_TRUE(h.strays.empty());
  EXPECT_EQ(h.stray_age.size(), h.strays.size());
}

}  // namespace
}  // namespace lampnav::fusion
