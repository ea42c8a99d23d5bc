#include "lampnav/graph/planner.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav_test.hpp"
#include "map_sketch.hpp"

namespace lampnav::graph {
namespace {

using V = Eigen::Vector2d;

std::vector<std::string> names(const TopologicalMap& m, const Route& r) {
  std::vector<std::string> out;
  for (NodeId id : r.nodes) out.push_back(m.node(id).name);
  return out;
}

TEST(Planner, CheapestNotFewestHops) {
  test::MapSketch s;
  s.place("A", Place::hall, V(0, 0))
      .place("B", Place::hall, V(10, 0))
      .place("C", Place::hall, V(5, 5));
  s.connect("A", "B", false, 20.0).connect("A", "C", false, 4.0).connect("C", "B", false, 4.0);
  const auto r = plan_route(s.map(), s.id("A"), s.id("B"));
  ASSERT_TRUE(r);
  EXPECT_EQ(names(s.map(), *r), (std::vector<std::string>{"A", "C", "B"}));
  EXPECT_DOUBLE_EQ(r->cost, 8.0);
  ASSERT_EQ(r->edges.size(), 2u);
  EXPECT_EQ(s.map().find_edge(r->edges[0])->start, s.id("A"));
  EXPECT_EQ(s.map().find_edge(r->edges[1])->end, s.id("B"));
}

TEST(Planner, ParallelEdgesTakeTheCheaper) {
  test::MapSketch s;
  s.place("A", Place::hall, V(0, 0)).place("B", Place::hall, V(10, 0));
  s.connect("A", "B", true, 9.0).connect("A", "B", true, 3.0);
  const auto r = plan_route(s.map(), s.id("A"), s.id("B"));
  ASSERT_TRUE(r);
  EXPECT_DOUBLE_EQ(r->cost, 3.0);
  EXPECT_DOUBLE_EQ(s.map().find_edge(r->edges[0])->cost, 3.0);
}

TEST(Planner, StartIsGoalAndUnreachable) {
  test::MapSketch s;
  s.place("A", Place::hall, V(0, 0)).place("B", Place::hall, V(10, 0));
  const auto same = plan_route(s.map(), s.id("A"), s.id("A"));
  ASSERT_TRUE(same);
  EXPECT_EQ(same->nodes.size(), 1u);
  EXPECT_EQ(same->cost, 0.0);
  EXPECT_FALSE(plan_route(s.map(), s.id("A"), s.id("B")));
  EXPECT_THROW(plan_route(s.map(), NodeId(999), s.id("B")), Error);
}

TEST(Planner, FromAPose) {
  const LoadedMap lm = read_map(test::source_path("maps/office_floor.geojson"));
  const auto r = plan_route(lm.map, Pose2(30.0, 10.2, 0.0), lm.map.find_node("D6")->id);
  ASSERT_TRUE(r);
  EXPECT_EQ(names(lm.map, *r), (std::vector<std::string>{"C2", "K1", "C3", "D6"}));
  EXPECT_THROW(plan_route(lm.map, Pose2(-50, -50, 0), lm.map.find_node("D6")->id), Error);
}

}  // namespace
}  // namespace lampnav::graph
