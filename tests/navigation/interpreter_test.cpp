// Route commands walked on the office floor: a planned route's own commands lead back to it, text
// commands find their places, and commands that cannot be carried out say which and why.

#include "lampnav/navigation/interpreter.hpp"

#include "lampnav/graph/corridor_geometry.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav_test.hpp"

namespace lampnav::navigation {
namespace {

const graph::TopologicalMap& office() {
  static const graph::TopologicalMap map =
      graph::read_map(test::source_path("maps/office_floor.geojson")).map;
  return map;
}

std::vector<std::string> names(const graph::TopologicalMap& map, const graph::Route& r) {
  std::vector<std::string> out;
  for (const auto& id : r.nodes) out.push_back(map.node(id).name);
  return out;
}

// Where a robot starting a route stands: the first node's point, facing the way out.
Pose2 start_of(const graph::TopologicalMap& map, const graph::Route& r) {
  const auto pts = graph::route_waypoints(map, r);
  const Eigen::Vector2d d =
      pts.size() > 1 ? Eigen::Vector2d(pts[1] - pts[0]) : Eigen::Vector2d(1, 0);
  return Pose2(pts[0], std::atan2(d.y(), d.x()));
}

TEST(Interpreter, EveryPlannedRouteComesBackFromItsCommands) {
  const auto& map = office();
  int routes = 0, same = 0;
  std::vector<std::string> differ;
  for (const auto& a : map.nodes())
    for (const auto& b : map.nodes()) {
      if (a.id == b.id) continue;
      const auto r = graph::plan_route(map, a.id, b.id);
      if (!r || r->nodes.size() < 2) continue;
      ++routes;
      const auto commands = graph::route_to_commands(map, *r);
      const Interpretation i = interpret_commands(map, start_of(map, *r), commands);
      if (i.plan && names(map, i.plan->route) == names(map, *r)) {
        ++same;
        EXPECT_EQ(i.plan->completes_at.size(), commands.size());
        EXPECT_EQ(i.plan->completes_at.back(), r->nodes.size() - 1);
      } else if (differ.size() < 5) {
        differ.push_back(a.name + " -> " + b.name + ": " + (i.plan ? "other route" : i.why));
      }
    }
  std::cout << same << " of " << routes << " routes walked back from their commands\n";
  for (const auto& d : differ) std::cout << "  " << d << "\n";
  EXPECT_GT(routes, 500);
  EXPECT_EQ(same, routes);
}

TEST(Interpreter, TextCommandsFindTheirPlaces) {
  const auto& map = office();
  const graph::Node& c1 = *map.find_node("C1");
  const Pose2 start(c1.axis->point_at(1.0),
                    std::atan2(c1.axis->direction().y(), c1.axis->direction().x()));
  const auto cmds = graph::parse_route_commands(
      "follow corridor C1, turn right at the first corner, follow corridor C3, stop at door D6");
  const Interpretation i = interpret_commands(map, start, cmds);
  ASSERT_TRUE(i.plan) << i.why;
  const auto n = names(map, i.plan->route);
  EXPECT_EQ(n.front(), "C1");
  EXPECT_EQ(n.back(), "D6");
  ASSERT_EQ(i.plan->completes_at.size(), 4u);
  EXPECT_EQ(n[i.plan->completes_at[1]], "C3");  // the turn ends in the corridor turned into
  // The waypoints start where the robot stands.
  EXPECT_LT((i.plan->waypoints.front() - start.translation()).norm(), 1e-9);
}

TEST(Interpreter, CommandsThatCannotBeCarriedOutSayWhichAndWhy) {
  const auto& map = office();
  const graph::Node& c1 = *map.find_node("C1");
  const Pose2 start(c1.axis->point_at(1.0),
                    std::atan2(c1.axis->direction().y(), c1.axis->direction().x()));
  const Interpretation far = interpret_commands(
      map, start, graph::parse_route_commands("turn left at the fifth junction"));
  EXPECT_FALSE(far.plan);
  EXPECT_EQ(far.failed, 0);
  EXPECT_NE(far.why.find("no fifth junction ahead"), std::string::npos) << far.why;
  const Interpretation doors = interpret_commands(
      map, start,
      graph::parse_route_commands("follow corridor C1, stop at the ninth door on the left"));
  EXPECT_FALSE(doors.plan);
  EXPECT_EQ(doors.failed, 1);
  EXPECT_NE(doors.why.find("no ninth door on the left ahead in C1"), std::string::npos)
      << doors.why;
  const Interpretation nowhere =
      interpret_commands(map, Pose2(500, 500, 0), graph::parse_route_commands("go to C1"));
  EXPECT_FALSE(nowhere.plan);
  EXPECT_NE(nowhere.why.find("in no place"), std::string::npos);
}

}  // namespace
}  // namespace lampnav::navigation
