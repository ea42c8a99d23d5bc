// Every map lampnav writes loads with Nav2's own GeoJSON route graph loader (navigation2's
// geojson_graph_file_loader.cpp, compiled here unchanged; README.md), and routes cost the same in
// Nav2 as in lampnav. A format-1 map, which the Route Server refused, is refused here too: the
// test can tell.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <queue>

#include "drive.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/planner.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"
#include "lampnav/mapping/topology.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav_test.hpp"
#include "nav2_route/plugins/graph_file_loaders/geojson_graph_file_loader.hpp"

namespace lampnav {
namespace {

namespace fs = std::filesystem;

struct Nav2Load {
  bool loaded = false;
  std::string error;  // an exception the loader let out (the Route Server fails to configure)
  nav2_route::Graph graph;
  nav2_route::GraphToIDMap ids;
};

Nav2Load load_with_nav2(const std::string& path) {
  nav2_route::GeoJsonGraphFileLoader loader;
  loader.configure(std::make_shared<nav2::LifecycleNode>("route_server"));
  rclcpp::stand_in_log().clear();
  Nav2Load out;
  try {
    out.loaded = loader.loadGraphFromFile(out.graph, out.ids, path);
  } catch (const std::exception& e) {
    out.error = e.what();
  }
  if (!out.loaded) out.error += "\n" + rclcpp::stand_in_log();
  return out;
}

// Nav2's route search cost from one node to every other (RoutePlanner with the default
// DistanceScorer): an edge that may not be overridden costs its written cost, which must be
// positive or Nav2 throws; any other costs the straight line between its nodes' coordinates.
std::vector<float> nav2_costs_from(nav2_route::Graph& g, unsigned int start) {
  std::vector<float> dist(g.size(), std::numeric_limits<float>::infinity());
  using Item = std::pair<float, unsigned int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  dist[start] = 0;
  open.push({0, start});
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > dist[i]) continue;
    for (auto& e : g[i].neighbors) {
      float c;
      if (!e.edge_cost.overridable) {
        EXPECT_GT(e.edge_cost.cost, 0.0f) << "Nav2 throws on edge " << e.edgeid;
        c = e.edge_cost.cost;
      } else {
        c = std::hypot(e.end->coords.x - e.start->coords.x, e.end->coords.y - e.start->coords.y);
      }
      const auto j = static_cast<unsigned int>(e.end - g.data());
      if (d + c < dist[j]) {
        dist[j] = d + c;
        open.push({dist[j], j});
      }
    }
  }
  return dist;
}

std::string write_temp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("lampnav_nav2_" + name + ".geojson");
  std::ofstream(p) << text;
  return p.string();
}

// Loads a file lampnav wrote with Nav2's loader, and checks that it holds the same graph and that
// shortest routes cost the same in both.
void expect_nav2_loads_alike(const std::string& path) {
  SCOPED_TRACE(path);
  const graph::TopologicalMap map = graph::read_map(path).map;
  Nav2Load nav2 = load_with_nav2(path);
  ASSERT_TRUE(nav2.loaded) << nav2.error;
  ASSERT_EQ(nav2.graph.size(), map.node_count());
  std::size_t edges = 0;
  for (const auto& n : nav2.graph) edges += n.neighbors.size();
  EXPECT_EQ(edges, map.edge_count());
  // Routes from a handful of nodes to every node.
  const std::size_t n = map.node_count();
  for (std::size_t k = 0; k < std::min<std::size_t>(n, 6); ++k) {
    const graph::Node& from = map.node_at_index(k * n / std::min<std::size_t>(n, 6));
    const auto nav2_cost = nav2_costs_from(nav2.graph, nav2.ids.at(from.id.value));
    for (const graph::Node& to : map.nodes()) {
      const auto route = graph::plan_route(map, from.id, to.id);
      const float theirs = nav2_cost[nav2.ids.at(to.id.value)];
      if (!route) {
        EXPECT_TRUE(std::isinf(theirs)) << from.name << " -> " << to.name;
        continue;
      }
      EXPECT_NEAR(route->cost, theirs, 1e-4 * std::max(1.0, route->cost))
          << from.name << " -> " << to.name;
    }
  }
}

TEST(Nav2Loader, LoadsTheBundledMaps) {
  for (const char* m : {"maps/office_floor.geojson", "maps/domus_museum.geojson"})
    expect_nav2_loads_alike(test::source_path(m));
}

TEST(Nav2Loader, LoadsWhatTheWriterWrites) {
  for (const char* m : {"maps/office_floor.geojson", "maps/domus_museum.geojson",
                        "tests/fixtures/maps/valid_tiny.geojson"}) {
    const auto lm = graph::read_map(test::source_path(m));
    expect_nav2_loads_alike(write_temp(fs::path(m).stem().string(), graph::write_map(lm.map)));
  }
}

TEST(Nav2Loader, LoadsAMapWrittenBackFromFormat1) {
  const std::string format1 = test::fixture("maps/format1_tiny.geojson");
  // Format 1 is what the Route Server refused: the loader throws on `lamps` in metadata.
  const Nav2Load refused = load_with_nav2(format1);
  EXPECT_FALSE(refused.loaded);
  EXPECT_NE(refused.error.find("Failed to convert the key: "), std::string::npos) << refused.error;
  const auto lm = graph::read_map(format1);
  expect_nav2_loads_alike(write_temp("format1_tiny", graph::write_map(lm.map)));
}

TEST(Nav2Loader, LoadsGeneratedBuildings) {
  for (int nodes : {10, 100}) {
    sim::BuildingOptions o;
    o.nodes = nodes;
    o.missing_corridors = 1;
    o.lobby = true;
    o.wing_lamp_spacing_m = 3.0;
    const std::string raw = sim::generate_building(o).geojson;
    expect_nav2_loads_alike(write_temp("generated_" + std::to_string(nodes), raw));
    const auto lm = graph::parse_map(raw, "generated");
    expect_nav2_loads_alike(
        write_temp("generated_written_" + std::to_string(nodes), graph::write_map(lm.map)));
  }
}

// A map built from a drive down every corridor of the office (mapping/), as `map build` writes it.
TEST(Nav2Loader, LoadsABuiltMap) {
  const test::Office office;
  const test::DriveRecord drive = office.drive(test::office_every_corridor());
  const graph::TopologicalMap built =
      mapping::build_topology(test::map_drive(drive, office.robot), {}, {}, nullptr);
  ASSERT_GT(built.edge_count(), 0u);
  expect_nav2_loads_alike(write_temp("built", graph::write_map(built)));
}

// Nav2's own graphs, read by lampnav and written back, still load in Nav2 the same.
TEST(Nav2Loader, LoadsNav2GraphsWrittenBackByLampnav) {
  for (const char* g : {"sample_graph", "aws_graph", "turtlebot3_graph", "turtlebot4_graph"}) {
    const std::string original = test::fixture(std::string("nav2/") + g + ".geojson");
    ASSERT_TRUE(load_with_nav2(original).loaded) << g;
    const auto lm = graph::read_map(original);
    const std::string back = write_temp(std::string("back_") + g, graph::write_map(lm.map));
    // Repeated edge ids (turtlebot4) make id lookups ambiguous; counts and costs still agree.
    expect_nav2_loads_alike(back);
  }
}

}  // namespace
}  // namespace lampnav
