// Generated buildings: valid maps of the size asked for, with lamps to match, routes across them
// that their own commands walk back, and the same map for the same seed.

#include "lampnav/sim/building.hpp"

#include "lampnav/core/error.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/planner.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav_test.hpp"

namespace lampnav::sim {
namespace {

TEST(Building, ValidMapsOfTheSizeAskedFor) {
  for (int n : {10, 100, 1000}) {
    BuildingOptions o;
    o.nodes = n;
    const Building b = generate_building(o);
    const graph::LoadedMap m = graph::parse_map(b.geojson, "generated");
    std::cout << n << " nodes asked: " << b.nodes << " nodes (grid " << b.grid << "), " << b.edges
              << " edges, " << b.lamps << " lamps, " << m.warnings.size() << " warnings\n";
    for (std::size_t k = 0; k < std::min<std::size_t>(3, m.warnings.size()); ++k)
      std::cout << "  " << m.warnings[k].text() << "\n";
    EXPECT_EQ(b.nodes, n);
    EXPECT_EQ(static_cast<int>(m.map.node_count()), b.nodes);
    EXPECT_EQ(m.warnings.size(), 0u);
    // Corner to corner: a route, and the commands that describe it.
    const std::string far = "J" + std::to_string(b.grid - 1) + "_" + std::to_string(b.grid - 1);
    const auto r = graph::plan_route(m.map, m.map.find_node("J0_0")->id, m.map.find_node(far)->id);
    ASSERT_TRUE(r);
    EXPECT_FALSE(graph::route_to_commands(m.map, *r).empty());
    // Every lamp's position is inside the region of the node that holds it.
    for (const auto& node : m.map.nodes())
      for (const auto& l : node.lamps)
        ASSERT_EQ(m.map.node_containing(l.xyz.head<2>()), &node) << l.id.value;
  }
  BuildingOptions o;
  o.nodes = 1000;
  EXPECT_GE(generate_building(o).lamps, 5000);
}

TEST(Building, SameSeedSameMapAndBadOptionsRefused) {
  BuildingOptions o;
  o.nodes = 300;
  EXPECT_EQ(generate_building(o).geojson, generate_building(o).geojson);
  o.seed = 2;
  BuildingOptions p = o;
  p.seed = 3;
  EXPECT_NE(generate_building(o).geojson, generate_building(p).geojson);
  BuildingOptions bad;
  bad.nodes = 3;
  EXPECT_THROW(generate_building(bad), InputError);
  bad = {};
  bad.lamp_spacing_m = 0;
  EXPECT_THROW(generate_building(bad), InputError);
  bad = {};
  bad.rows = 3;
  EXPECT_THROW(generate_building(bad), InputError);
  bad = {};
  bad.rows = 2;
  bad.row_spacing_m = 2.5;  // outside the corridor
  EXPECT_THROW(generate_building(bad), InputError);
}

// Two rows: each corridor and junction lamp becomes a pair `row_spacing_m` apart across the
// corridor, about where the one lamp hung, inside the node's region; rooms keep theirs.
TEST(Building, TwoRowsHangEachLampAsAPairAcrossTheCorridor) {
  BuildingOptions one;
  one.nodes = 30;
  BuildingOptions two = one;
  two.rows = 2;
  two.row_spacing_m = 1.4;
  const graph::LoadedMap a = graph::parse_map(generate_building(one).geojson, "one");
  const graph::LoadedMap b = graph::parse_map(generate_building(two).geojson, "two");
  EXPECT_EQ(b.warnings.size(), 0u);
  ASSERT_EQ(a.map.node_count(), b.map.node_count());
  for (const auto& n : a.map.nodes()) {
    const graph::Node& m = *b.map.find_node(n.name);
    if (n.place == graph::Place::room) {
      EXPECT_EQ(m.lamps.size(), n.lamps.size()) << n.name;
      continue;
    }
    ASSERT_EQ(m.lamps.size(), 2 * n.lamps.size()) << n.name;
    for (std::size_t k = 0; k < n.lamps.size(); ++k) {
      const auto& l = n.lamps[k];
      const auto& p = m.lamps[2 * k];
      const auto& q = m.lamps[2 * k + 1];
      EXPECT_EQ(p.id.value, l.id.value + "a");
      EXPECT_NEAR((p.xyz - q.xyz).norm(), 1.4, 1e-9) << l.id.value;
      EXPECT_LT(((p.xyz + q.xyz) / 2 - l.xyz).norm(), 1e-9) << l.id.value;
      // Across the lamp's axis (the corridor's), not along it.
      EXPECT_NEAR(
          std::abs(std::cos(l.yaw) * (p.xyz - q.xyz).x() + std::sin(l.yaw) * (p.xyz - q.xyz).y()),
          0, 1e-9);
      EXPECT_EQ(b.map.node_containing(p.xyz.head<2>()), &m) << p.id.value;
      EXPECT_EQ(b.map.node_containing(q.xyz.head<2>()), &m) << q.id.value;
    }
  }
}

}  // namespace
}  // namespace lampnav::sim
