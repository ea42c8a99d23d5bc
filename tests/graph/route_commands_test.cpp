// Table-driven route-command tests in the style of OSRM's guidance tests: a small map in, the
// exact command list out.

#include "lampnav/graph/route_commands.hpp"
#include "lampnav_test.hpp"
#include "map_sketch.hpp"

namespace lampnav::graph {
namespace {

using test::MapSketch;
using V = Eigen::Vector2d;

// A cross: corridors W, E, N, S meet at junction J; each ends in an end node.
MapSketch cross() {
  MapSketch s;
  s.corridor(
       "W", V(0, 0), V(10, 0),
       {{"A", Side::left, 2}, {"B", Side::right, 4}, {"C", Side::left, 6}, {"D", Side::left, 8}})
      .place("J", Place::junction, V(11, 0))
      .corridor("E", V(12, 0), V(22, 0))
      .corridor("N", V(11, 1), V(11, 11))
      .corridor("S", V(11, -1), V(11, -11))
      .place("EW", Place::end, V(-1, 0))
      .place("EE", Place::end, V(23, 0))
      .place("EN", Place::end, V(11, 12))
      .place("ES", Place::end, V(11, -12))
      .place("A", Place::door, V(2, 1.15), 0.3)
      .place("C", Place::door, V(6, 1.15), 0.3)
      .place("R", Place::room, V(6, 4), 4.0);
  s.connect("EW", "W").connect("W", "J").connect("J", "E").connect("J", "N").connect("J", "S");
  s.connect("E", "EE").connect("N", "EN").connect("S", "ES");
  s.connect("W", "A").connect("W", "C").connect("C", "R");
  return s;
}

// An L: corridor W then a corner K then corridor N (left turn), or corridor S (right turn).
MapSketch ell(bool left) {
  MapSketch s;
  const double sign = left ? 1 : -1;
  s.corridor("W", V(0, 0), V(10, 0))
      .place("K", Place::corner, V(11, 0))
      .corridor("N", V(11, sign), V(11, 11 * sign))
      .place("EW", Place::end, V(-1, 0))
      .place("EN", Place::end, V(11, 12 * sign));
  s.connect("EW", "W").connect("W", "K").connect("K", "N").connect("N", "EN");
  return s;
}

// A long corridor crossing two junctions, with a branch south at each and a corner at the end.
MapSketch two_junctions() {
  MapSketch s;
  s.corridor("W", V(0, 0), V(10, 0))
      .place("J1", Place::junction, V(11, 0))
      .corridor("M", V(12, 0), V(22, 0))
      .place("J2", Place::junction, V(23, 0))
      .corridor("E", V(24, 0), V(34, 0))
      .place("K", Place::corner, V(35, 0))
      .corridor("KN", V(35, 1), V(35, 11))
      .corridor("S1", V(11, -1), V(11, -11))
      .corridor("S2", V(23, -1), V(23, -11))
      .place("EW", Place::end, V(-1, 0))
      .place("ES2", Place::end, V(23, -12))
      .place("EKN", Place::end, V(35, 12));
  s.connect("EW", "W").connect("W", "J1").connect("J1", "M").connect("M", "J2").connect("J2", "E");
  s.connect("E", "K").connect("K", "KN").connect("KN", "EKN");
  s.connect("J1", "S1").connect("J2", "S2").connect("S2", "ES2");
  return s;
}

MapSketch halls() {
  MapSketch s;
  s.place("H1", Place::hall, V(0, 0), 10).place("H2", Place::hall, V(10, 0), 10);
  s.place("H3", Place::hall, V(10, 10), 10);
  s.connect("H1", "H2").connect("H2", "H3");
  return s;
}

struct Case {
  const char* name;
  MapSketch (*map)();
  const char* from;
  const char* to;
  std::vector<std::string> expected;
};

const Case kCases[] = {
    {"t_junction_left",
     cross,
     "EW",
     "EN",
     {"follow corridor W", "turn left at the first junction", "follow corridor N",
      "stop at end EN"}},
    {"t_junction_right",
     cross,
     "EW",
     "ES",
     {"follow corridor W", "turn right at the first junction", "follow corridor S",
      "stop at end ES"}},
    {"junction_straight_on", cross, "EW", "EE", {"follow corridor W", "stop at end EE"}},
    {"corner_left",
     [] { return ell(true); },
     "EW",
     "EN",
     {"follow corridor W", "turn left at the first corner", "follow corridor N", "stop at end EN"}},
    {"corner_right",
     [] { return ell(false); },
     "EW",
     "EN",
     {"follow corridor W", "turn right at the first corner", "follow corridor N",
      "stop at end EN"}},
    {"second_junction",
     two_junctions,
     "EW",
     "ES2",
     {"follow corridor W", "turn right at the second junction", "follow corridor S2",
      "stop at end ES2"}},
    {"corner_after_junctions",
     two_junctions,
     "EW",
     "EKN",
     {"follow corridor W", "turn left at the first corner", "follow corridor KN",
      "stop at end EKN"}},
    {"door_left_forward",
     cross,
     "EW",
     "C",
     {"follow corridor W", "stop at door C (second door on the left)"}},
    {"door_sides_flip_backward",
     cross,
     "EN",
     "A",
     {"follow corridor N", "turn right at the first junction", "follow corridor W",
      "stop at door A (third door on the right)"}},
    {"same_corridor",
     cross,
     "C",
     "A",
     {"follow corridor W", "stop at door A (first door on the right)"}},
    {"through_door_into_room",
     cross,
     "EW",
     "R",
     {"follow corridor W", "go through door C", "enter room R"}},
    {"out_of_room", cross, "R", "EE", {"go through door C", "follow corridor W", "stop at end EE"}},
    {"halls", halls, "H1", "H3", {"enter hall H2", "enter hall H3"}},
    {"start_at_junction", cross, "J", "EN", {"follow corridor N", "stop at end EN"}},
    {"goal_is_junction", cross, "EW", "J", {"follow corridor W", "stop at junction J"}},
    {"start_is_goal", cross, "W", "W", {"follow corridor W", "stop at corridor W"}},
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name << ": " << c.from << " -> " << c.to; }

class RouteCommandsTest : public ::testing::TestWithParam<Case> {};

TEST_P(RouteCommandsTest, ExactCommands) {
  const Case& c = GetParam();
  const MapSketch s = c.map();
  const auto route = plan_route(s.map(), s.id(c.from), s.id(c.to));
  ASSERT_TRUE(route) << "no route";
  std::vector<std::string> got;
  for (const auto& cmd : route_to_commands(s.map(), *route)) got.push_back(cmd.text());
  EXPECT_EQ(got, c.expected);
}

TEST_P(RouteCommandsTest, TextParsesBackToTheSameCommands) {
  const Case& c = GetParam();
  const MapSketch s = c.map();
  const auto route = plan_route(s.map(), s.id(c.from), s.id(c.to));
  ASSERT_TRUE(route);
  const auto cmds = route_to_commands(s.map(), *route);
  std::string text;
  for (const auto& cmd : cmds) text += cmd.text() + "\n";
  EXPECT_EQ(parse_route_commands(text), cmds);
  EXPECT_NO_THROW(check_commands(s.map(), cmds));
}

INSTANTIATE_TEST_SUITE_P(Guidance, RouteCommandsTest, ::testing::ValuesIn(kCases),
                         [](const auto& p) { return std::string(p.param.name); });

TEST(RouteCommands, NoRouteAgainstOneWayEdges) {
  MapSketch s;
  s.corridor("A", V(0, 0), V(10, 0)).place("X", Place::end, V(11, 0));
  s.connect("X", "A", /*one_way=*/true);
  EXPECT_FALSE(plan_route(s.map(), s.id("A"), s.id("X")));
  EXPECT_TRUE(plan_route(s.map(), s.id("X"), s.id("A")));
}

TEST(RouteCommands, OrdinalWords) {
  EXPECT_EQ(ordinal_word(1), "first");
  EXPECT_EQ(ordinal_word(10), "tenth");
  EXPECT_EQ(ordinal_word(11), "11th");
  EXPECT_EQ(ordinal_word(22), "22nd");
  EXPECT_EQ(ordinal_word(103), "103rd");
  EXPECT_EQ(ordinal_word(112), "112th");
}

}  // namespace
}  // namespace lampnav::graph
