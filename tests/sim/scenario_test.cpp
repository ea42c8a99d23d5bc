#include <filesystem>
#include <fstream>
#include <sstream>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav_test.hpp"

namespace lampnav::sim {
namespace {

using test::slurp;

struct Office {
  std::string text = slurp(test::source_path("maps/office_floor.geojson"));
  graph::LoadedMap map = graph::parse_map(text, "office");
  RobotDescription robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
};

std::string temp(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("lampnav_sim_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

// A short mission: door D1 to door D2 along corridor C1 (8 m).
Scenario short_mission(const Office& o, std::uint64_t seed) {
  Scenario s = make_route_scenario(o.map.map, o.text, o.robot, "D1", "D2", seed);
  s.omni_rate = 0.5;
  return s;
}

TEST(Scenario, SameSeedSameBytes) {
  const Office o;
  const std::string a = temp("a.mcap"), b = temp("b.mcap"), c = temp("c.mcap");
  record_mission(short_mission(o, 42), a);
  record_mission(short_mission(o, 42), b);
  record_mission(short_mission(o, 43), c);
  const std::string ba = slurp(a), bb = slurp(b), bc = slurp(c);
  EXPECT_GT(ba.size(), 10000u);
  EXPECT_EQ(ba, bb);
  EXPECT_NE(ba, bc);
  for (const auto& p : {a, b, c}) std::filesystem::remove(p);
}

TEST(Scenario, MissionLogHoldsWhatTheSpecLists) {
  const Office o;
  const std::string path = temp("log.mcap");
  Scenario s = short_mission(o, 5);
  s.failed_lamps = {"C1-L3"};
  const RecordStats st = record_mission(s, path);
  EXPECT_TRUE(st.arrived);
  const io::MissionLog log = io::read_mission_log(path);
  EXPECT_FALSE(log.report.truncated);
  EXPECT_EQ(log.skipped_messages, 0u);
  ASSERT_TRUE(log.robot_json && log.map_geojson);
  EXPECT_EQ(*log.map_geojson, o.text);
  EXPECT_EQ(log.wheels.size(), st.wheel_messages);
  EXPECT_EQ(log.truth.size(), st.wheel_messages);
  EXPECT_EQ(log.ceiling_images.size(), st.ceiling_frames);
  EXPECT_EQ(log.omni_images.size(), st.omni_frames);
  ASSERT_FALSE(log.commands.empty());
  EXPECT_EQ(log.commands.front().value.text, "follow corridor C1");
  bool failure_event = false;
  for (const auto& e : log.events)
    failure_event = failure_event ||
                    (e.value.type() == io::EventKind::lamp_failure && e.value.detail == "C1-L3");
  EXPECT_TRUE(failure_event);
  // Camera frames become available a second after they were captured (paper 2), and the log is
  // in availability order.
  for (const auto& f : log.ceiling_images) {
    EXPECT_EQ(to_nanoseconds(f.log_time) - to_nanoseconds(f.value.stamp), 1'000'000'000LL);
  }
  const Image8 img = io::decode_image(log.ceiling_images.front().value.data, "frame");
  EXPECT_EQ(img.width, 352);
  EXPECT_EQ(img.height, 288);
  // The truth ends at door D2.
  const Eigen::Vector2d end = log.truth.back().value.pose.translation();
  EXPECT_LT((end - o.map.map.find_node("D2")->point).norm(), 0.15);
  std::filesystem::remove(path);
}

TEST(Scenario, KidnapPutsTheRobotElsewhereWithoutOdometry) {
  const Office o;
  Scenario s = make_named_scenario("office-mission", o.map.map, o.text, o.robot, 3);
  s.ceiling_rate = 0;  // keep the test quick: wheels and truth only
  s.omni_rate = 0;
  const std::string path = temp("kidnap.mcap");
  const RecordStats st = record_mission(s, path);
  EXPECT_TRUE(st.arrived);
  EXPECT_EQ(st.kidnaps, 1u);
  const io::MissionLog log = io::read_mission_log(path);
  // At the kidnap the truth jumps by metres while the wheels move by millimetres.
  double biggest_jump = 0, wheels_then = 1;
  for (std::size_t i = 1; i < log.truth.size(); ++i) {
    const double jump =
        (log.truth[i].value.pose.translation() - log.truth[i - 1].value.pose.translation()).norm();
    if (jump > biggest_jump) {
      biggest_jump = jump;
      wheels_then = std::fabs(log.wheels[i].value.left - log.wheels[i - 1].value.left);
    }
  }
  EXPECT_GT(biggest_jump, 3.0);
  EXPECT_LT(wheels_then, 0.05);
  std::filesystem::remove(path);
}

TEST(Scenario, NamedScenariosBuildAndRefuseTheWrongMap) {
  const Office o;
  for (const char* n : {"corridor", "office-mission"})
    EXPECT_NO_THROW(make_named_scenario(n, o.map.map, o.text, o.robot, 1));
  EXPECT_THROW(make_named_scenario("domus-global", o.map.map, o.text, o.robot, 1), InputError);
  EXPECT_THROW(make_named_scenario("nowhere", o.map.map, o.text, o.robot, 1), InputError);
  const std::string museum_text = slurp(test::source_path("maps/domus_museum.geojson"));
  const auto museum = graph::parse_map(museum_text, "museum");
  const Scenario g = make_named_scenario("domus-global", museum.map, museum_text, o.robot, 1);
  double len = 0;
  for (std::size_t i = 1; i < g.waypoints.size(); ++i)
    len += (g.waypoints[i] - g.waypoints[i - 1]).norm();
  EXPECT_NEAR(len, 24.0, 0.5);  // paper 1: a 24 m path
  for (const auto& p : g.waypoints) EXPECT_NE(museum.map.node_containing(p), nullptr);
  const Scenario k = make_named_scenario("domus-kidnap", museum.map, museum_text, o.robot, 1);
  len = 0;
  for (std::size_t i = 1; i < k.waypoints.size(); ++i)
    len += (k.waypoints[i] - k.waypoints[i - 1]).norm();
  EXPECT_GT(len, 40.0);  // paper 1: more than 40 m
  for (const auto& p : k.waypoints) EXPECT_NE(museum.map.node_containing(p), nullptr);
}

}  // namespace
}  // namespace lampnav::sim
