// lampnav run [--map M] [--mission NAME] [--out DIR]: the main job, a whole mission in simulation.
// lampnav replay LOG.mcap [--map M] [--robot R.json] [--initial-pose X,Y,YAW] [--out DIR]: the
// stack over a recorded mission.

#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/evaluation/replay.hpp"
#include "lampnav/evaluation/report.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/internal/json_util.hpp"
#include "lampnav/navigation/runtime.hpp"
#include "lampnav/sim/simulated_robot.hpp"

namespace lampnav::apps {

namespace {

namespace fs = std::filesystem;
using evaluation::Metrics;

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

// The summary table both commands print.
void print_table(const std::vector<std::pair<std::string, std::string>>& rows) {
  std::size_t w = 0;
  for (const auto& r : rows) w = std::max(w, r.first.size());
  for (const auto& [k, v] : rows)
    std::cout << std::left << std::setw(static_cast<int>(w + 2)) << k << v << "\n";
}

void add_metric_rows(std::vector<std::pair<std::string, std::string>>& rows, const Metrics& m) {
  if (m.has_truth && m.position_error_m.n) {
    rows.push_back({"position error", "mean " + fixed(m.position_error_m.mean * 100, 2) +
                                          " cm, RMS " + fixed(m.position_error_m.rms * 100, 2) +
                                          " cm, max " + fixed(m.position_error_m.max * 100, 2) +
                                          " cm (outside the lost interval)"});
    rows.push_back({"heading error", "mean " + fixed(m.yaw_error_deg.mean, 2) + " deg, RMS " +
                                         fixed(m.yaw_error_deg.rms, 2) + " deg, max " +
                                         fixed(m.yaw_error_deg.max, 2) + " deg"});
  } else if (m.has_truth) {
    rows.push_back({"errors", "not scored: no pose was ever published as tracking"});
  } else {
    rows.push_back({"errors", "not scored: the log has no truth"});
  }
  if (m.has_truth)
    rows.push_back({"wrong fixes", std::to_string(m.wrong_fixes) +
                                       " (poses published as certain more than 0.5 m off)"});
  rows.push_back(
      {"kidnaps",
       std::to_string(m.kidnaps) + ", recovered " + std::to_string(m.recoveries) +
           (m.relocalization_latency_s.n
                ? " (relocalized " + fixed(m.relocalization_latency_s.mean, 2) + " s after, mean)"
                : "")});
  rows.push_back({"time lost", fixed(m.lost_s, 1) + " s, ambiguous " + fixed(m.ambiguous_s, 1) +
                                   " s (one of several places)"});
  rows.push_back({"frames", std::to_string(m.ceiling_frames) + " ceiling, " +
                                std::to_string(m.omni_frames) + " omni; " +
                                std::to_string(m.lamps_labelled) + " of " +
                                std::to_string(m.lamps_seen) + " lamps labelled"});
  rows.push_back({"replay", fixed(m.runtime_s, 2) + " s for " + fixed(m.duration_s, 1) +
                                " s: " + fixed(m.realtime_factor, 1) + "x real time"});
}

void make_dir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError({dir, "", "--out"}, "cannot create the directory: " + ec.message());
}

// ---------------------------------------------------------------------------------------------
// run

struct RunArgs {
  std::string map, mission = "office-mission", out = "lampnav-out";
  std::uint64_t seed = 1;
  std::string image_format;
  bool quiet = false;
};

struct MissionProgress : navigation::RuntimeObserver {
  ProgressBar* bar;
  const navigation::Executor* executor = nullptr;
  double expected_s = 1;
  std::size_t n = 0;
  void on_estimate(const fusion::LocalizerEstimate& e) override {
    if (++n % 25 != 0) return;
    std::string what =
        std::string(fusion::to_string(e.mode)) + (e.node ? " in " + e.node->name : "");
    if (executor && !executor->plan().commands.empty())
      what += ": " + executor->plan().commands[executor->command()].text();
    bar->update(std::min(0.99, to_seconds(e.stamp) / expected_s), what);
  }
};

int run_mission(const RunArgs& a) {
  const std::string map_path = a.map.empty() ? data_path("maps/office_floor.geojson") : a.map;
  const std::string robot_path = data_path("maps/robots/pioneer.json");
  if (a.mission != "office-mission" && a.mission != "corridor")
    throw InputError({"", "--mission", ""},
                     "'" + a.mission +
                         "' cannot be driven: run takes office-mission or corridor (the domus "
                         "scenarios carry the robot; record them with lampnav sim)");
  const std::string map_text = json::read_file(map_path);
  const graph::LoadedMap loaded = graph::parse_map(map_text, map_path);
  const RobotDescription robot = read_robot_description(robot_path);
  sim::Scenario s = sim::make_named_scenario(a.mission, loaded.map, map_text, robot, a.seed);
  if (!a.image_format.empty())
    s.images = io::parse_image_encoding(a.image_format, "--image-format");
  make_dir(a.out);
  const std::string log_path = a.out + "/mission.mcap";

  std::string text;
  for (const auto& c : s.commands) text += (text.empty() ? "" : ", ") + c;
  const auto commands = graph::parse_route_commands(text, "the mission's commands");
  std::cerr << "lampnav run: " << s.name << " on " << map_path << "\n  commands: " << text << "\n";

  ProgressBar bar(a.quiet);
  navigation::RunOutcome outcome;
  sim::RecordStats stats;
  std::string goal;
  int replans = 0;
  {
    sim::SimulatedRobot sim_robot(s, log_path);
    navigation::Runtime rt(loaded.map, robot);
    MissionProgress progress;
    progress.bar = &bar;
    progress.executor = &rt.executor();
    double length = 0;
    for (std::size_t k = 1; k < s.waypoints.size(); ++k)
      length += (s.waypoints[k] - s.waypoints[k - 1]).norm();
    progress.expected_s = std::max(1.0, 1.2 * length / s.max_speed);
    outcome = rt.run(sim_robot, s.start, commands, &progress);
    stats = sim_robot.finish();
    bar.done();
    for (const auto& ev : rt.executor().events())
      std::cerr << "  " << fixed(to_seconds(ev.stamp), 2) << " s: " << ev.text << "\n";
    goal = rt.executor().goal();
    replans = rt.executor().replans();
  }
  // The recorded mission, replayed: the report's numbers, and the replay's speed.
  const io::MissionLog log = io::read_mission_log(log_path);
  evaluation::ReplayOptions ro;
  ro.initial_pose = s.start;
  const evaluation::ReplayResult r = evaluation::replay(log, loaded.map, robot, ro);
  evaluation::write_replay(r, log, loaded.map, map_text, *log.robot_json, a.out);
  evaluation::write_report(r, log, loaded.map, "lampnav run: " + s.name, a.out);

  const bool arrived = outcome.status == navigation::ExecutorStatus::arrived;
  std::vector<std::pair<std::string, std::string>> rows;
  rows.push_back({"mission", s.name + " (seed " + std::to_string(a.seed) + ")"});
  rows.push_back({"result", arrived ? "arrived at " + goal + " after " +
                                          fixed(outcome.duration_s(), 1) + " s, " +
                                          fixed(stats.path_length_m, 1) + " m driven"
                                    : "did NOT arrive: " + outcome.reason});
  rows.push_back({"plans", std::to_string(1 + replans) +
                               (replans ? " (planned again after relocalization)" : "")});
  add_metric_rows(rows, r.metrics);
  rows.push_back(
      {"outputs",
       a.out + "/{mission.mcap, replay.mcap, estimate.tum, truth.tum, metrics.json, report.html}"});
  print_table(rows);
  if (!arrived) throw JobFailed("the mission did not arrive: " + outcome.reason);
  return 0;
}

// ---------------------------------------------------------------------------------------------
// replay

struct ReplayArgs {
  std::string log, map, robot, initial_pose, out = "lampnav-out";
  io::BagTopics topics;
  bool no_ceiling = false, no_omni = false, quiet = false;
};

int run_replay(const ReplayArgs& a) {
  std::optional<Pose2> initial;
  if (!a.initial_pose.empty()) initial = parse_pose_option(a.initial_pose, "--initial-pose");
  if (!fs::exists(a.log)) throw InputError({a.log, "", ""}, "no such file");
  RobotDescription robot;
  std::string robot_json;
  const io::MissionLog log = read_log_for_robot(a.log, a.robot, a.topics, robot, &robot_json);
  std::string map_text, map_source;
  if (!a.map.empty()) {
    map_text = json::read_file(a.map);
    map_source = a.map;
  } else if (log.map_geojson) {
    map_text = *log.map_geojson;
    map_source = a.log + " (map.geojson attachment)";
  } else {
    throw InputError({a.log, "attachments", "map.geojson"}, "the log has no map: give --map");
  }
  const graph::LoadedMap loaded = graph::parse_map(map_text, map_source);
  evaluation::ReplayOptions o;
  o.use_ceiling = !a.no_ceiling;
  o.use_omni = !a.no_omni;
  o.initial_pose = initial;
  make_dir(a.out);
  const evaluation::ReplayResult r = evaluation::replay(log, loaded.map, robot, o);
  evaluation::write_replay(r, log, loaded.map, map_text, robot_json, a.out);
  evaluation::write_report(r, log, loaded.map,
                           "lampnav replay: " + fs::path(a.log).filename().string(), a.out);
  for (const auto& n : r.notes) std::cerr << "lampnav: note: " << n << "\n";
  std::vector<std::pair<std::string, std::string>> rows;
  rows.push_back({"log", a.log});
  add_metric_rows(rows, r.metrics);
  rows.push_back({"outputs", a.out + "/{replay.mcap, estimate.tum" +
                                 std::string(log.truth.empty() ? "" : ", truth.tum") +
                                 ", metrics.json, report.html}"});
  print_table(rows);
  if (r.estimates.empty()) throw JobFailed("the robot was never localized");
  return 0;
}

}  // namespace

void add_run_commands(CLI::App& app, Job& run) {
  auto ra = std::make_shared<RunArgs>();
  CLI::App* rc = app.add_subcommand(
      "run",
      "The main job: a whole mission in simulation (plan, drive by route commands, get "
      "kidnapped, relocalize, arrive), with its log, replay outputs and report");
  rc->add_option("--map", ra->map, "Map (.geojson); default the bundled office floor");
  rc->add_option("--mission", ra->mission, "office-mission or corridor")->capture_default_str();
  rc->add_option("--out", ra->out, "Output directory")->capture_default_str();
  rc->add_option("--seed", ra->seed, "Random seed of the simulated world")->capture_default_str();
  rc->add_option("--image-format", ra->image_format,
                 "How the mission log stores frames: png, jpeg or jpeg:QUALITY (1-100)");
  rc->add_flag("-q,--quiet", ra->quiet, "No progress bar");
  rc->callback([ra, &run] { run = [ra] { return run_mission(*ra); }; });

  auto pa = std::make_shared<ReplayArgs>();
  CLI::App* pc = app.add_subcommand(
      "replay",
      "Run the stack over a recorded mission; write replay.mcap, TUM trajectories, "
      "metrics.json and report.html");
  pc->add_option("LOG", pa->log,
                 "Mission log (.mcap) or ROS 2 bag (its directory, or a .mcap or .db3 file)")
      ->required();
  pc->add_option("--map", pa->map, "Map (.geojson); default the log's attachment");
  pc->add_option("--robot", pa->robot, "robot.json; default the log's attachment");
  pc->add_option("--initial-pose", pa->initial_pose,
                 "X,Y,YAW (m, m, rad) where the robot starts; without it the omni camera finds it");
  pc->add_option("--out", pa->out, "Output directory")->capture_default_str();
  pc->add_flag("--no-ceiling", pa->no_ceiling, "Leave the ceiling camera's frames out");
  pc->add_flag("--no-omni", pa->no_omni, "Leave the omni camera's frames out");
  pc->add_flag("-q,--quiet", pa->quiet, "No progress bar");
  add_bag_topic_options(*pc, pa->topics);
  pc->callback([pa, &run] { run = [pa] { return run_replay(*pa); }; });
}

}  // namespace lampnav::apps
