// Replay of a mission the executor drove: the same estimates as live, bit for bit; the metrics
// against the truth; the outputs the spec lists; logs without truth, without a camera, cut short.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "lampnav/core/error.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/navigation/replay.hpp"
#include "lampnav/sim/simulated_robot.hpp"
#include "lampnav_test.hpp"

namespace lampnav::navigation {
namespace {

namespace fs = std::filesystem;

struct LiveEstimates : RuntimeObserver {
  std::vector<fusion::LocalizerEstimate> all;
  void on_estimate(const fusion::LocalizerEstimate& e) override { all.push_back(e); }
};

// The office mission driven once by the executor, its log kept for the tests below.
struct Driven {
  std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  graph::TopologicalMap map = graph::parse_map(geojson, "office_floor.geojson").map;
  RobotDescription robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  sim::Scenario scenario;
  std::string dir, log_path;
  LiveEstimates live;
  RunOutcome outcome;
  Driven() {
    scenario = sim::make_named_scenario("office-mission", map, geojson, robot, 1);
    dir = (fs::temp_directory_path() / ("lampnav_replay_" + std::to_string(::getpid()))).string();
    fs::create_directories(dir);
    log_path = dir + "/mission.mcap";
    sim::SimulatedRobot robot_sim(scenario, log_path);
    std::string text;
    for (const auto& c : scenario.commands) text += (text.empty() ? "" : ", ") + c;
    Runtime rt(map, robot);
    outcome = rt.run(robot_sim, scenario.start, graph::parse_route_commands(text), &live);
    robot_sim.finish();
  }
  ~Driven() { fs::remove_all(dir); }
};

const Driven& driven() {
  static const Driven d;
  return d;
}

TEST(Replay, GivesTheLiveEstimatesAndScoresThem) {
  const Driven& d = driven();
  ASSERT_EQ(d.outcome.status, ExecutorStatus::arrived) << d.outcome.reason;
  const io::MissionLog log = io::read_mission_log(d.log_path);
  ReplayOptions o;
  o.initial_pose = d.scenario.start;
  const ReplayResult r = replay(log, d.map, d.robot, o);
  // Deterministic: the live run and the replay of its log agree exactly.
  ASSERT_GE(r.estimates.size(), d.live.all.size());
  for (std::size_t k = 0; k < d.live.all.size(); ++k) {
    ASSERT_EQ(r.estimates[k].stamp, d.live.all[k].stamp) << k;
    ASSERT_EQ(r.estimates[k].pose.vector(), d.live.all[k].pose.vector()) << k;
    ASSERT_EQ(r.estimates[k].mode, d.live.all[k].mode) << k;
  }
  const Metrics& m = r.metrics;
  std::cout << metrics_json(m);
  EXPECT_TRUE(m.has_truth);
  EXPECT_LE(m.position_error_m.mean, 0.05);
  EXPECT_EQ(m.kidnaps, 1);
  EXPECT_EQ(m.recoveries, 1);
  EXPECT_LE(m.relocalization_latency_s.max, 5.0);
  EXPECT_GT(m.lost_s, 0.0);
  EXPECT_GT(m.lamps_labelled, m.lamps_seen / 2);
  EXPECT_GE(m.realtime_factor, 1.0);  // the target (50x) is measured by bench, not here
  EXPECT_FALSE(r.odometry.empty());
}

TEST(Replay, WritesTheOutputsTheSpecLists) {
  const Driven& d = driven();
  const io::MissionLog log = io::read_mission_log(d.log_path);
  ReplayOptions o;
  o.initial_pose = d.scenario.start;
  const ReplayResult r = replay(log, d.map, d.robot, o);
  const std::string out = d.dir + "/out";
  write_replay(r, log, d.map, d.geojson, *log.robot_json, out);
  for (const char* f : {"replay.mcap", "estimate.tum", "truth.tum", "metrics.json"})
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  const auto j = nlohmann::json::parse(test::slurp(out + "/metrics.json"));
  for (const char* k :
       {"frames", "duration_s", "position_error_m", "yaw_error_deg", "lost_s", "kidnaps",
        "recoveries", "relocalization_latency_s", "runtime_s", "realtime_factor"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_TRUE(j["position_error_m"].contains("rms"));
  // The TUM file: one pose per estimate, eight numbers a line.
  std::ifstream tum_in(out + "/estimate.tum");
  std::string line;
  std::size_t lines = 0;
  while (std::getline(tum_in, line)) {
    std::istringstream s(line);
    double v;
    int n = 0;
    while (s >> v) ++n;
    ASSERT_EQ(n, 8) << line;
    ++lines;
  }
  EXPECT_EQ(lines, r.estimates.size());
  // The replay log reads back with the inputs and the estimates.
  const io::MissionLog back = io::read_mission_log(out + "/replay.mcap");
  EXPECT_EQ(back.wheels.size(), log.wheels.size());
  EXPECT_EQ(back.omni_images.size(), log.omni_images.size());
  EXPECT_FALSE(back.report.truncated);
}

TEST(Replay, WithoutTruthWithoutACameraOrCutShort) {
  const Driven& d = driven();
  const io::MissionLog full = io::read_mission_log(d.log_path);
  ReplayOptions o;
  o.initial_pose = d.scenario.start;
  // No truth: works, says so, scores nothing.
  io::MissionLog no_truth = full;
  no_truth.truth.clear();
  const ReplayResult a = replay(no_truth, d.map, d.robot, o);
  EXPECT_FALSE(a.metrics.has_truth);
  EXPECT_FALSE(a.estimates.empty());
  EXPECT_TRUE(nlohmann::json::parse(metrics_json(a.metrics))["position_error_m"].is_null());
  bool said = false;
  for (const auto& n : a.notes) said = said || n.find("no truth") != std::string::npos;
  EXPECT_TRUE(said);
  // No omni camera: the ceiling camera tracks and finds the kidnap, but nothing relocalizes.
  ReplayOptions ceiling_only = o;
  ceiling_only.use_omni = false;
  const ReplayResult b = replay(full, d.map, d.robot, ceiling_only);
  EXPECT_EQ(b.metrics.omni_frames, 0u);
  EXPECT_EQ(b.metrics.kidnaps, 1);
  EXPECT_EQ(b.metrics.recoveries, 0);
  EXPECT_GT(b.metrics.lost_s, 60.0);
  EXPECT_LE(b.metrics.position_error_m.mean, 0.05);  // before the kidnap
  // No ceiling camera: the omni camera alone, 1.8 m under evenly spaced lamps, tracks the
  // first half of the mission.
  ReplayOptions omni_only = o;
  omni_only.use_ceiling = false;
  const ReplayResult e = replay(full, d.map, d.robot, omni_only);
  EXPECT_EQ(e.metrics.ceiling_frames, 0u);
  double before = 0;
  int counted = 0;
  const io::TruthTrack truth(full.truth);
  for (const auto& s : e.estimates)
    if (to_seconds(s.stamp) < 50) {
      before += (s.pose.translation() - truth.at(s.stamp).translation()).norm();
      ++counted;
    }
  std::cout << "omni only: mean error " << before / counted * 100 << " cm before the kidnap, "
            << e.metrics.position_error_m.mean << " m over the mission\n";
  EXPECT_LE(before / counted, 0.10);
  // No start and no omni camera: nothing to find the robot with.
  ReplayOptions blind;
  blind.use_omni = false;
  EXPECT_THROW(replay(full, d.map, d.robot, blind), JobFailed);
  // Cut short: the first 60 % of the file.
  const std::string bytes = test::slurp(d.log_path);
  const std::string cut = d.dir + "/cut.mcap";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() * 6 / 10);
  const io::MissionLog part = io::read_mission_log(cut);
  ASSERT_TRUE(part.report.truncated);
  const ReplayResult c = replay(part, d.map, d.robot, o);
  said = false;
  for (const auto& n : c.notes) said = said || n.find("truncated") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_LT(c.metrics.duration_s, full.wheels.back().value.stamp.time_since_epoch().count() * 1e-9);
  EXPECT_LE(c.metrics.position_error_m.mean, 0.05);
}

}  // namespace
}  // namespace lampnav::navigation
