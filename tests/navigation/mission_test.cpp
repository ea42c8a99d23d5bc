// Whole missions in the simulated world, closed loop: the executor drives the simulated robot by
// route commands on the localizer's estimate; the robot is kidnapped on the way.

#include <unistd.h>

#include <filesystem>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/navigation/runtime.hpp"
#include "lampnav/sim/simulated_robot.hpp"
#include "lampnav_test.hpp"

namespace lampnav::navigation {
namespace {

struct Office {
  std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  graph::TopologicalMap map = graph::parse_map(geojson, "office_floor.geojson").map;
  RobotDescription robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
};

// Scores each estimate against the simulated truth at the same instant.
struct Scorer : RuntimeObserver {
  const sim::SimulatedRobot* robot;
  int scored = 0, lost_steps = 0;
  double sum = 0, max = 0;
  bool after_kidnap = false;
  std::vector<fusion::LocalizerMode> modes;
  void on_estimate(const fusion::LocalizerEstimate& e) override {
    if (modes.empty() || modes.back() != e.mode) modes.push_back(e.mode);
    if (e.mode != fusion::LocalizerMode::tracking) {
      ++lost_steps;
      return;
    }
    const double err = (e.pose.translation() - robot->truth().translation()).norm();
    // Between the kidnap and its detection the estimate is wrong by design: not scored.
    if (err > 0.5 && !after_kidnap) {
      after_kidnap = true;
      return;
    }
    if (err > 0.5) return;
    ++scored;
    sum += err;
    max = std::max(max, err);
  }
};

TEST(Mission, OfficeMissionArrivesThroughAKidnap) {
  const Office o;
  const sim::Scenario s = sim::make_named_scenario("office-mission", o.map, o.geojson, o.robot, 1);
  const std::string log = (std::filesystem::temp_directory_path() /
                           ("lampnav_mission_" + std::to_string(::getpid()) + ".mcap"))
                              .string();
  sim::SimulatedRobot robot(s, log);
  std::string text;
  for (const auto& c : s.commands) text += (text.empty() ? "" : ", ") + c;
  Runtime rt(o.map, o.robot);
  Scorer score;
  score.robot = &robot;
  const RunOutcome r = rt.run(robot, s.start, graph::parse_route_commands(text), &score);
  const sim::RecordStats stats = robot.finish();
  std::filesystem::remove(log);
  std::cout << "status " << to_string(r.status) << " after " << r.duration_s() << " s, "
            << stats.kidnaps << " kidnap(s); mean error " << score.sum / score.scored * 100
            << " cm (max " << score.max * 100 << ") over " << score.scored << " steps\n";
  for (const auto& ev : rt.executor().events())
    std::cout << "  " << to_seconds(ev.stamp) << " s: " << ev.text << "\n";
  EXPECT_EQ(r.status, ExecutorStatus::arrived) << r.reason;
  EXPECT_EQ(stats.kidnaps, 1u);
  EXPECT_EQ(rt.executor().replans(), 1);
  const graph::Node& goal = *o.map.find_node(s.goal);
  EXPECT_EQ(o.map.node_containing(robot.truth().translation()), &goal);
  EXPECT_LE(score.sum / score.scored, 0.05);
  // Lost, then relocalized, then tracking again.
  EXPECT_GE(score.modes.size(), 4u);
}

}  // namespace
}  // namespace lampnav::navigation
