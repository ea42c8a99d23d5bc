// Nav2's own route graphs (tests/fixtures/nav2, from navigation2's nav2_route/graphs): lampnav
// reads them as plain topological maps, routes on them as Nav2 scores them, and writes them back
// with every Nav2 key as it came.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/planner.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav_test.hpp"

namespace lampnav::graph {
namespace {

using ::testing::HasSubstr;

class Nav2Graph : public ::testing::TestWithParam<const char*> {
 protected:
  std::string path() const { return test::fixture(std::string("nav2/") + GetParam() + ".geojson"); }
};

TEST_P(Nav2Graph, ReadsAsWaypointsAndWritesBackTheSameJson) {
  const LoadedMap lm = read_map(path());
  const nlohmann::json original = nlohmann::json::parse(test::slurp(path()));
  EXPECT_TRUE(lm.map.plain_nav2());
  EXPECT_EQ(lm.map.lamp_count(), 0u);
  std::size_t points = 0;
  for (const auto& f : original["features"]) points += f["geometry"]["type"] == "Point" ? 1 : 0;
  EXPECT_EQ(lm.map.node_count(), points);
  EXPECT_EQ(lm.map.edge_count(), original["features"].size() - points);
  for (const Node& n : lm.map.nodes()) EXPECT_EQ(n.place, Place::waypoint);
  // Every key (crs, date_generated, operations, metadata, LineString geometry) comes back.
  const nlohmann::json written = nlohmann::json::parse(write_map(lm.map));
  EXPECT_EQ(written, original);
}

// Edges cost what Nav2's planner (with its default distance scorer) makes them cost: the written
// cost where "overridable" is false, else the straight line between the nodes.
TEST_P(Nav2Graph, CostsEdgesAsNav2Does) {
  const LoadedMap lm = read_map(path());
  const nlohmann::json original = nlohmann::json::parse(test::slurp(path()));
  for (const auto& f : original["features"]) {
    const auto& p = f["properties"];
    if (!p.contains("startid")) continue;
    const Edge* e = lm.map.find_edge(EdgeId(p["id"].get<std::int64_t>()));
    ASSERT_NE(e, nullptr);
    if (e->start.value != p["startid"].get<std::int64_t>()) continue;  // a repeated id
    const double line = (lm.map.node(e->end).point - lm.map.node(e->start).point).norm();
    if (p.value("overridable", true) == false)
      EXPECT_DOUBLE_EQ(e->cost, p["cost"].get<double>());
    else
      EXPECT_DOUBLE_EQ(e->cost, line);
  }
}

TEST_P(Nav2Graph, RoutesBetweenEveryReachablePair) {
  const LoadedMap lm = read_map(path());
  std::size_t routed = 0;
  for (const Node& a : lm.map.nodes()) {
    for (const Node& b : lm.map.nodes()) {
      if (a.id == b.id) continue;
      const auto route = plan_route(lm.map, a.id, b.id);
      if (!route) continue;
      ++routed;
      const auto cmds = route_to_commands(lm.map, *route);
      ASSERT_FALSE(cmds.empty());
      EXPECT_EQ(cmds.back().kind, CommandKind::go_to);
      EXPECT_EQ(cmds.back().target, b.name);
    }
  }
  EXPECT_GT(routed, lm.map.node_count());
}

INSTANTIATE_TEST_SUITE_P(Shipped, Nav2Graph,
                         ::testing::Values("sample_graph", "aws_graph", "turtlebot3_graph",
                                           "turtlebot4_graph"));

TEST(Nav2Graph, RepeatedEdgeIdsAreWarnedNotRefused) {
  const LoadedMap lm = read_map(test::fixture("nav2/turtlebot4_graph.geojson"));
  std::size_t repeated = 0;
  for (const auto& w : lm.warnings) {
    if (w.message.find("duplicate edge id") != std::string::npos) ++repeated;
  }
  EXPECT_EQ(repeated, 6u);  // ids 10006, 10007, 10012, 10013, 10020 and 10021 come twice
}

TEST(Nav2Graph, SampleKeepsOperationsAndMetadata) {
  const LoadedMap lm = read_map(test::fixture("nav2/sample_graph.geojson"));
  const Node& n0 = lm.map.node(NodeId(0));
  EXPECT_THAT(n0.nav2_keys, HasSubstr("\"operations\""));
  EXPECT_THAT(n0.nav2_keys, HasSubstr("living_room"));
  EXPECT_EQ(n0.name, "0");  // no metadata.name: named by its id
  EXPECT_THAT(lm.map.nav2_keys(), HasSubstr("date_generated"));
}

// What a plain Nav2 graph may not hold: what Nav2's own loader would throw on.
TEST(Nav2Graph, RefusesWhatNav2WouldThrowOn) {
  nlohmann::json doc =
      nlohmann::json::parse(test::slurp(test::fixture("nav2/sample_graph.geojson")));
  doc["features"][1]["properties"]["metadata"] = {{"lamps", {{{"id", "L1"}}}}};
  try {
    parse_map(doc.dump(), "g.geojson");
    FAIL() << "accepted";
  } catch (const InputErrors& e) {
    ASSERT_EQ(e.problems().size(), 1u) << e.what();
    EXPECT_EQ(e.problems()[0].where().place, "features[1] (id 1)");
    EXPECT_EQ(e.problems()[0].where().field, "properties.metadata.lamps[0]");
    EXPECT_THAT(e.problems()[0].message(), HasSubstr("cannot convert an array of objects"));
  }
}

// Routing needs no names: a waypoint is named by metadata.name when Nav2's author gave one.
TEST(Nav2Graph, NamedByMetadataName) {
  nlohmann::json doc =
      nlohmann::json::parse(test::slurp(test::fixture("nav2/sample_graph.geojson")));
  doc["features"][2]["properties"]["metadata"] = {{"name", "dock"}};
  const LoadedMap lm = parse_map(doc.dump(), "g.geojson");
  ASSERT_NE(lm.map.find_node("dock"), nullptr);
  EXPECT_EQ(lm.map.find_node("dock")->id, NodeId(2));
}

}  // namespace
}  // namespace lampnav::graph
