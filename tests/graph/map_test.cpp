#include <map>
#include "lampnav/core/error.hpp"
#include "lampnav/graph/geojson.hpp"

#include "lampnav_test.hpp"
#include "map_sketch.hpp"

namespace lampnav::graph {
namespace {

using V = Eigen::Vector2d;

std::vector<std::string> ids(const std::vector<const Lamp*>& lamps) {
  std::vector<std::string> out;
  for (const Lamp* l : lamps) out.push_back(l->id.value);
  return out;
}

TEST(TopologicalMap, RefusesDuplicatesAndDanglingEdges) {
  TopologicalMap m("t");
  Node a;
  a.id = NodeId(1);
  a.name = "A";
  a.region = Polygon({{0, 0}, {1, 0}, {1, 1}});
  m.add_node(a);
  Node b = a;
  EXPECT_THROW(m.add_node(b), Error);  // same id
  b.id = NodeId(2);
  EXPECT_THROW(m.add_node(b), Error);  // same name
  b.name = "B";
  m.add_node(b);
  Edge e;
  e.id = EdgeId(2);  // taken by node B
  e.start = NodeId(1);
  e.end = NodeId(2);
  EXPECT_THROW(m.add_edge(e), Error);
  e.id = EdgeId(3);
  e.end = NodeId(9);
  EXPECT_THROW(m.add_edge(e), Error);
  e.end = NodeId(2);
  m.add_edge(e);
  EXPECT_EQ(m.edge_count(), 1u);
  EXPECT_EQ(m.out_edges(NodeId(1)).size(), 1u);
  EXPECT_EQ(m.in_edges(NodeId(2)).size(), 1u);
  EXPECT_EQ(m.edge_between(NodeId(1), NodeId(2))->id, EdgeId(3));
  EXPECT_EQ(m.edge_between(NodeId(2), NodeId(1)), nullptr);
}

TEST(TopologicalMap, NodeContainingUsesRegionsNotNearestPoint) {
  test::MapSketch s;
  // A wide hall whose node point is far to the left, and a small room beside it whose point is
  // closer to the query: the region decides.
  s.place("Room", Place::room, V(12, 0), 2);
  s.place("Hall", Place::hall, V(5, 0), 10);
  const auto& m = s.map();
  EXPECT_EQ(m.node_containing(V(9.5, 0))->name, "Hall");
  EXPECT_EQ(m.node_containing(V(11.5, 0.5))->name, "Room");
  EXPECT_EQ(m.node_containing(V(50, 50)), nullptr);
}

// Near a region: inside it, else the nearest region within the margin (a robot in the sliver
// between two places, or a pose estimate centimetres off), else none.
TEST(TopologicalMap, NodeNearTakesTheNearestRegionWithinTheMargin) {
  TopologicalMap m("t");
  Node a;
  a.id = NodeId(1);
  a.name = "A";
  a.region = Polygon({{0, 0}, {2, 0}, {2, 1}, {0, 1}});
  m.add_node(a);
  Node b = a;
  b.id = NodeId(2);
  b.name = "B";
  b.region = Polygon({{2.1, 0}, {4, 0}, {4, 1}, {2.1, 1}});  // 10 cm past A
  m.add_node(b);
  EXPECT_EQ(m.node_near({1, 0.5}, 0.2)->name, "A");
  EXPECT_EQ(m.node_containing({2.03, 0.5}), nullptr);
  EXPECT_EQ(m.node_near({2.03, 0.5}, 0.2)->name, "A");
  EXPECT_EQ(m.node_near({2.08, 0.5}, 0.2)->name, "B");
  EXPECT_EQ(m.node_near({2.03, 0.5}, 0.0), nullptr);
  EXPECT_EQ(m.node_near({1, 1.25}, 0.2), nullptr);
  EXPECT_EQ(m.node_near({1, 1.15}, 0.2)->name, "A");
}

TEST(TopologicalMap, LampsInWalkingOrderFollowTravel) {
  test::MapSketch s;
  s.corridor("C", V(0, 0), V(10, 0), {}, 2.5);
  const auto& m = s.map();
  const NodeId c = s.id("C");
  EXPECT_EQ(ids(m.lamps_in_walking_order(c, Travel::forward)),
            (std::vector<std::string>{"C-L1", "C-L2", "C-L3", "C-L4"}));
  EXPECT_EQ(ids(m.lamps_in_walking_order(c, Travel::backward)),
            (std::vector<std::string>{"C-L4", "C-L3", "C-L2", "C-L1"}));
  EXPECT_EQ(m.travel_for_heading(c, 0.1), Travel::forward);
  EXPECT_EQ(m.travel_for_heading(c, M_PI - 0.1), Travel::backward);
}

TEST(TopologicalMap, LampsAheadAndWithin) {
  test::MapSketch s;
  s.corridor("C", V(0, 0), V(10, 0), {}, 2.0)  // lamps at x = 1, 3, 5, 7, 9
      .corridor("D", V(0, 5), V(10, 5), {}, 2.0);
  const auto& m = s.map();
  EXPECT_EQ(ids(m.lamps_ahead(Pose2(3.5, 0, 0), 4.0, 1.0)),
            (std::vector<std::string>{"C-L3", "C-L4"}));
  EXPECT_EQ(ids(m.lamps_ahead(Pose2(3.5, 0, M_PI), 10.0, 1.0)),
            (std::vector<std::string>{"C-L2", "C-L1"}));
  EXPECT_EQ(ids(m.lamps_within(V(5.2, 0), 1.0)), (std::vector<std::string>{"C-L3"}));
  EXPECT_EQ(ids(m.lamps_within(V(5, 2.5), 2.6)), (std::vector<std::string>{"C-L3", "D-L3"}));
  EXPECT_EQ(m.lamps_within(V(50, 0), 3.0).size(), 0u);
  ASSERT_NE(m.find_lamp(LampId("D-L2")), nullptr);
  EXPECT_EQ(m.find_lamp(LampId("D-L2"))->node, s.id("D"));
}

TEST(TopologicalMap, CopiesAreIndependent) {
  test::MapSketch s;
  s.corridor("C", V(0, 0), V(10, 0));
  TopologicalMap copy = s.map();
  copy.set_name("other");
  EXPECT_EQ(s.map().name(), "sketch");
  EXPECT_EQ(copy.node_count(), 1u);
  EXPECT_EQ(copy.node_containing(V(5, 0))->name, "C");
}

TEST(BundledMaps, OfficeFloorHasWhatTheIssueAsks) {
  const LoadedMap lm = read_map(test::source_path("maps/office_floor.geojson"));
  EXPECT_TRUE(lm.warnings.empty());
  std::map<Place, int> count;
  std::size_t doors = 0;
  for (const Node& n : lm.map.nodes()) {
    ++count[n.place];
    doors += n.doors.size();
    for (const Lamp& l : n.lamps) {
      EXPECT_TRUE(n.region.contains(l.xyz.head<2>())) << l.id;
      if (n.place == Place::corridor) {
        EXPECT_EQ(l.shape, LampShape::rectangle);
        EXPECT_DOUBLE_EQ(l.length, 1.2);
        EXPECT_DOUBLE_EQ(l.width, 0.3);
        EXPECT_DOUBLE_EQ(l.xyz.z(), 2.7);
      }
    }
    if (n.place == Place::corridor) {
      for (std::size_t i = 1; i < n.lamps.size(); ++i) {
        EXPECT_NEAR((n.lamps[i].xyz - n.lamps[i - 1].xyz).norm(), 2.4, 0.3) << n.name;
      }
    }
  }
  EXPECT_GE(count[Place::corridor], 4);
  EXPECT_GE(count[Place::junction], 2);
  EXPECT_GE(count[Place::corner], 2);
  EXPECT_GE(count[Place::end], 2);
  EXPECT_GE(count[Place::door], 8);
  // Every T-junction joins three corridors.
  for (const Node& n : lm.map.nodes()) {
    if (n.place == Place::junction) {
      EXPECT_EQ(lm.map.out_edges(n.id).size(), 3u) << n.name;
    }
  }
}

TEST(BundledMaps, DomusMuseumHasAllThirtyLightsAtTheirHeights) {
  const LoadedMap lm = read_map(test::source_path("maps/domus_museum.geojson"));
  EXPECT_TRUE(lm.warnings.empty());
  EXPECT_EQ(lm.map.lamp_count(), 30u);
  EXPECT_EQ(lm.map.node_count(), 3u);
  const Lamp* e1 = lm.map.find_lamp(LampId("E1"));
  ASSERT_NE(e1, nullptr);
  EXPECT_DOUBLE_EQ(e1->xyz.z(), 11.39);
  const Lamp* r65 = lm.map.find_lamp(LampId("R65"));
  ASSERT_NE(r65, nullptr);
  EXPECT_DOUBLE_EQ(r65->xyz.x(), 27.50);
  EXPECT_EQ(lm.map.node(r65->node).name, "B");
  for (const Node& n : lm.map.nodes()) EXPECT_EQ(n.place, Place::hall);
}

}  // namespace
}  // namespace lampnav::graph
