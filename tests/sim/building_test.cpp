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
}

}  // namespace
}  // namespace lampnav::sim
