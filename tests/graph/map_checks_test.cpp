#include "lampnav/graph/map_checks.hpp"
#include "lampnav_test.hpp"
#include "map_sketch.hpp"

namespace lampnav::graph {
namespace {

using ::testing::HasSubstr;

TEST(MaxSpeed, FromViewLampAndSpacing) {
  // 2.8 m of view, a 1.2 m lamp: 1.6 m of travel per frame sees it whole; 2.4 m spacing limits
  // the travel per frame to 1.2 m so consecutive lamps are not confused.
  EXPECT_DOUBLE_EQ(max_speed_every_lamp_seen(2.8, 1.2, 2.4, 1.0), 1.2);
  EXPECT_DOUBLE_EQ(max_speed_every_lamp_seen(2.8, 1.2, 10.0, 1.0), 1.6);
  EXPECT_DOUBLE_EQ(max_speed_every_lamp_seen(2.8, 1.2, 10.0, 5.0), 8.0);
  EXPECT_DOUBLE_EQ(max_speed_every_lamp_seen(1.0, 1.2, 10.0, 5.0), 0.0);  // lamp never fits
}

TEST(MapChecks, CoverageWarnsAtTheLimitingLamp) {
  test::MapSketch s;
  s.corridor("C", {0, 0}, {10, 0}, {}, 1.0);  // lamps 1 m apart
  s.corridor("D", {0, 5}, {10, 5}, {}, 3.0);
  s.connect("C", "D");
  MapCheckOptions opts;
  CeilingCoverage cov;
  cov.view_length = [](double) { return 2.8; };
  cov.speed = 0.8;
  cov.frame_rate = 1.0;
  opts.coverage = cov;
  const auto warnings = check_map(s.map(), opts, "m.geojson");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].where.place, "node 'C' (id 1)");
  EXPECT_THAT(warnings[0].message, HasSubstr("highest safe speed here is 0.50 m/s"));
  cov.speed = 0.4;
  opts.coverage = cov;
  EXPECT_TRUE(check_map(s.map(), opts).empty());
}

TEST(MapChecks, OneWayDeadEndIsNotMutuallyReachable) {
  test::MapSketch s;
  s.place("A", Place::hall, {0, 0})
      .place("B", Place::hall, {5, 0})
      .place("C", Place::hall, {10, 0});
  s.connect("A", "B").connect("B", "C", /*one_way=*/true);
  const auto warnings = check_map(s.map());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].where.place, "node 'C' (id 3)");
  EXPECT_THAT(warnings[0].message, HasSubstr("not mutually reachable"));
}

}  // namespace
}  // namespace lampnav::graph
