// A whole mission in the simulated world, closed loop: the executor drives the simulated robot by
// route commands on the localizer's estimate through a kidnap; then the replay of its log (the
// live estimates exactly, the metrics, the outputs the spec lists, and logs without truth, without
// a camera, cut short). One mission per test process: it takes 20 s to drive.

#include <unistd.h>
#include <algorithm>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "lampnav/core/error.hpp"
#include "lampnav/evaluation/replay.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/navigation/runtime.hpp"
#include "lampnav/sim/simulated_robot.hpp"
#include "lampnav_test.hpp"

namespace lampnav::navigation {
namespace {

using namespace lampnav::evaluation;  // replay, its results and outputs

namespace fs = std::filesystem;

// Scores each estimate against the simulated truth at the same instant, and keeps them all.
struct Scorer : RuntimeObserver {
  const sim::SimulatedRobot* robot;
  std::vector<fusion::LocalizerEstimate> all;
  int scored = 0;
  double sum = 0, max = 0;
  bool after_kidnap = false;
  std::vector<fusion::LocalizerMode> modes;
  void on_estimate(const fusion::LocalizerEstimate& e) override {
    all.push_back(e);
    if (modes.empty() || modes.back() != e.mode) modes.push_back(e.mode);
    if (e.mode != fusion::LocalizerMode::tracking) return;
    const double err = (e.pose.translation() - robot->truth().translation()).norm();
    // Between the kidnap and its detection the estimate is wrong by design: not scored.
    if (err > 0.5) {
      after_kidnap = true;
      return;
    }
    ++scored;
    sum += err;
    max = std::max(max, err);
  }
};

struct Driven {
  std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  graph::TopologicalMap map = graph::parse_map(geojson, "office_floor.geojson").map;
  RobotDescription robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  sim::Scenario scenario = sim::make_named_scenario("office-mission", map, geojson, robot, 1);
  std::string dir =
      (fs::temp_directory_path() / ("lampnav_mission_" + std::to_string(::getpid()))).string();
  std::string log_path = dir + "/mission.mcap";
  ~Driven() { fs::remove_all(dir); }
};

void replay_gives_the_live_estimates(const Driven& d, const Scorer& live) {
  const io::MissionLog log = io::read_mission_log(d.log_path);
  ReplayOptions o;
  o.initial_pose = d.scenario.start;
  const ReplayResult r = replay(log, d.map, d.robot, o);
  // Deterministic: the live run and the replay of its log agree exactly.
  ASSERT_GE(r.estimates.size(), live.all.size());
  for (std::size_t k = 0; k < live.all.size(); ++k) {
    ASSERT_EQ(r.estimates[k].stamp, live.all[k].stamp) << k;
    ASSERT_EQ(r.estimates[k].pose.vector(), live.all[k].pose.vector()) << k;
    ASSERT_EQ(r.estimates[k].mode, live.all[k].mode) << k;
  }
  const Metrics& m = r.metrics;
  std::cout << metrics_json(m);
  EXPECT_TRUE(m.has_truth);
  EXPECT_LE(m.position_error_m.mean, 0.05);
  EXPECT_EQ(m.kidnaps, 1);
  EXPECT_EQ(m.recoveries, 1);
  // 3.3 s until 11-28, when the omni images' far blobs no lamp explains were charged anew in
  // every image, and the far view told the twin corridor apart within a second. Such blobs now
  // share one bounded account (far_stray_cost_max): the robot drives on along the corridor to
  // where the twins' near views differ, and relocalized 11.3 s after the kidnap until 12-07,
  // on images that fitted the truth and its twin corridor within 2 of each other, each way in
  // turn. Such an image is a tie now (omni_tie_cost 2, from 1: the same small differences
  // published twins on the sweeps): the truth leads by 6.6 from 61 s, short of the 6.9 to
  // publish, until the image that tells them apart (2.3 against 13.0) 21 s after the kidnap.
  EXPECT_LE(m.relocalization_latency_s.max, 25.0);
  EXPECT_GT(m.lost_s + m.ambiguous_s, 0.0);
  EXPECT_EQ(m.wrong_fixes, 0);
  EXPECT_GT(m.lamps_labelled, m.lamps_seen / 2);
  EXPECT_GE(m.realtime_factor, 1.0);  // the target (50x) is measured by bench, not here
  EXPECT_FALSE(r.odometry.empty());
}

void replay_writes_the_outputs(const Driven& d) {
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
  // The TUM file: one pose per estimate published as tracking, eight numbers a line.
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
  EXPECT_EQ(lines, static_cast<std::size_t>(std::count_if(
                       r.estimates.begin(), r.estimates.end(), [](const EstimateSample& e) {
                         return e.mode == fusion::LocalizerMode::tracking;
                       })));
  EXPECT_LT(lines, r.estimates.size());  // not while lost or ambiguous
  // Every topic parses as Foxglove parses it (no topic dropped), the foxglove.* ones carry the
  // official schemas, and each channel's first message validates (tests/interop).
  ASSERT_TRUE(fs::exists(test::source_path("tests/interop/node_modules/@foxglove/schemas")))
      << "@foxglove/schemas is not installed: run `make test`, which installs it";
  int status = -1;
  const std::string checked =
      test::run_command("cd '" + test::source_path("tests/interop") +
                            "' && node check_schemas.mjs '" + out + "/replay.mcap' 2>&1",
                        &status);
  EXPECT_EQ(status, 0) << checked;
  for (const char* topic :
       {"/truth/pose", "/lampnav/pose", "/lampnav/scene", "/lampnav/estimate", "/lampnav/lamps",
        "/lampnav/hypotheses", "/ceiling_camera/image", "/lampnav/log"})
    EXPECT_NE(checked.find(std::string("\"") + topic + "\""), std::string::npos) << topic;
  // The replay log reads back with the inputs and the estimates.
  const io::MissionLog back = io::read_mission_log(out + "/replay.mcap");
  EXPECT_EQ(back.wheels.size(), log.wheels.size());
  EXPECT_EQ(back.omni_images.size(), log.omni_images.size());
  EXPECT_FALSE(back.report.truncated);
}

void replay_without_truth_camera_or_end(const Driven& d) {
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

TEST(Mission, OfficeMissionDrivenThroughAKidnapAndReplayed) {
  Driven d;
  fs::create_directories(d.dir);
  std::string text;
  for (const auto& c : d.scenario.commands) text += (text.empty() ? "" : ", ") + c;
  Scorer score;
  RunOutcome r;
  sim::RecordStats stats;
  Pose2 end;
  {
    sim::SimulatedRobot robot(d.scenario, d.log_path);
    Runtime rt(d.map, d.robot);
    score.robot = &robot;
    r = rt.run(robot, d.scenario.start, graph::parse_route_commands(text), &score);
    stats = robot.finish();
    end = robot.truth();
    std::cout << "status " << to_string(r.status) << " after " << r.duration_s() << " s, "
              << stats.kidnaps << " kidnap(s); mean error " << score.sum / score.scored * 100
              << " cm (max " << score.max * 100 << ") over " << score.scored << " steps\n";
    for (const auto& ev : rt.executor().events())
      std::cout << "  " << to_seconds(ev.stamp) << " s: " << ev.text << "\n";
    EXPECT_EQ(rt.executor().replans(), 1);
  }
  ASSERT_EQ(r.status, ExecutorStatus::arrived) << r.reason;
  EXPECT_EQ(stats.kidnaps, 1u);
  EXPECT_EQ(d.map.node_containing(end.translation()), d.map.find_node(d.scenario.goal));
  EXPECT_LE(score.sum / score.scored, 0.05);
  EXPECT_TRUE(score.after_kidnap);
  // Tracking, lost, relocalized, tracking.
  EXPECT_GE(score.modes.size(), 4u);
  {
    SCOPED_TRACE("replay: the live estimates, scored");
    replay_gives_the_live_estimates(d, score);
  }
  {
    SCOPED_TRACE("replay: the outputs");
    replay_writes_the_outputs(d);
  }
  {
    SCOPED_TRACE("replay: no truth, one camera, cut short");
    replay_without_truth_camera_or_end(d);
  }
}

}  // namespace
}  // namespace lampnav::navigation
