// The map oracle: the travel after which a drive's lamps fit only the true place.

#include "lampnav/sim/map_oracle.hpp"

#include <gtest/gtest.h>

#include <iostream>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav_test.hpp"

namespace lampnav::sim {
namespace {

// The grid office (3 x 3 junctions 12 m apart, lamps every 2.4 m, no rooms).
graph::TopologicalMap grid_office(int missing_corridors) {
  BuildingOptions o;
  o.nodes = 21;
  o.block_m = 12;
  o.lamp_spacing_m = 2.4;
  o.rooms = false;
  o.missing_corridors = missing_corridors;
  o.seed = 3;
  return graph::parse_map(generate_building(o).geojson, "grid office").map;
}

// A straight drive along +x from `from`, a sample every 0.25 m.
std::vector<DriveSample> straight(const Pose2& from, double length) {
  std::vector<DriveSample> d;
  for (double s = 0; s <= length; s += 0.25) d.push_back({s, from * Pose2(s, 0, 0)});
  return d;
}

// The corridor starting at the grid's origin junction, driven east.
const graph::Node& east_corridor_from_origin(const graph::TopologicalMap& map) {
  for (const auto& n : map.nodes()) {
    if (n.place != graph::Place::corridor || !n.axis) continue;
    const auto& a = *n.axis;
    if (std::abs(a.first.y()) < 1e-6 && std::abs(a.second.y()) < 1e-6 &&
        std::min(a.first.x(), a.second.x()) < 2)
      return n;
  }
  throw std::runtime_error("no corridor along y = 0 from the origin");
}

TEST(MapOracle, PerfectlySymmetricBuildingNeverDecides) {
  const graph::TopologicalMap map = grid_office(0);
  MapOracleOptions o;
  o.view_radius_m = 30;
  const MapOracle oracle(map, o);
  const graph::Node& c = east_corridor_from_origin(map);
  const OracleVerdict v = oracle.judge(straight(Pose2(c.axis->point_at(1.0), 0.0), 20));
  EXPECT_FALSE(v.distinguishing_m);  // the half-turn twin fits every view
  EXPECT_GE(v.alive_at_end, 1u);
  EXPECT_GE(v.twins, v.alive_at_end);
}

// A short view in a regular building: the first views fit many corridors; driving on, the twins
// fall away, and a longer view never decides later than a shorter one.
TEST(MapOracle, DecidesLaterWithAShorterView) {
  const graph::TopologicalMap map = grid_office(1);
  const graph::Node& c = east_corridor_from_origin(map);
  const auto drive = straight(Pose2(c.axis->point_at(1.0), 0.0), 24);
  std::optional<double> previous;
  for (double radius : {30.0, 12.0, 6.0}) {
    MapOracleOptions o;
    o.view_radius_m = radius;
    const OracleVerdict v = MapOracle(map, o).judge(drive);
    ASSERT_TRUE(v.distinguishing_m) << radius << " m: " << v.alive_at_end << " twins left";
    std::cout << "view " << radius << " m: " << v.twins << " twins, decided after "
              << *v.distinguishing_m << " m\n";
    EXPECT_GT(v.twins, 0u);
    if (previous) {
      EXPECT_GE(*v.distinguishing_m, *previous) << radius;
    }
    previous = v.distinguishing_m;
  }
  EXPECT_GT(*previous, 0.0);  // at 6 m, the first view fits other places
}

// A failed lamp is a landmark: the oracle sees the lamps that light, as the sensors do.
TEST(MapOracle, AFailedLampTellsTwinsApart) {
  const graph::TopologicalMap map = grid_office(0);
  const graph::Node& c = east_corridor_from_origin(map);
  MapOracleOptions o;
  o.view_radius_m = 30;
  o.failed_lamps = {c.lamps[2].id.value};
  const OracleVerdict v =
      MapOracle(map, o).judge(straight(Pose2(c.axis->point_at(1.0), 0.0), 10));
  ASSERT_TRUE(v.distinguishing_m);
  EXPECT_EQ(*v.distinguishing_m, 0.0);  // no twin has that gap in the same place
}

TEST(MapOracle, RefusesBadOptions) {
  const graph::TopologicalMap map = grid_office(1);
  MapOracleOptions o;
  o.view_radius_m = -1;
  EXPECT_THROW(MapOracle(map, o), InputError);
}

}  // namespace
}  // namespace lampnav::sim
