// The live node on DDS (issue 16's targets): `lampnav node` fed over the loopback by a player
// process that plays the recorded corridor run at 3.05 times its pace, so the ceiling camera
// comes at 30 Hz, the wheels at 150 Hz and the omni camera at 3 Hz, as compressed images and
// joint states. The node times each image from its arrival (handed over by DDS) to the pose it
// publishes after it (decoding included); the player counts what it sent, the node what it
// received. The iteration time is the ceiling camera's p99; the rest are counters. Run twice:
// the images as PNG (a 1024 x 1024 omni frame takes 11 ms to decode alone), as most camera
// drivers compress them (JPEG, quality 90; argument 90), and as raw grey frames
// (sensor_msgs/msg/Image, mono8, on .../image_raw; argument -1; -2: yuyv, a webcam's own
// format). Second argument 1: the node is
// told where the robot starts (--initial-pose), as a robot's launch file or /initialpose would;
// 0: it finds the start from the omni camera, enumerating the places its first images fit.
// Images after which no pose went out (the start not found yet) are timed apart, to the
// hypotheses they gave: no pose came out of them. The player sends the cameras' mounts on
// /tf_static, as a robot's robot_state_publisher does; the node waits for them and the first
// images at start (those are counted apart, images_before_start, not in the latencies).
//   Targets: image in to pose out at most 5 ms (p99); no message lost.

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"

namespace {

using namespace lampnav;
namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void BM_NodeImageToPose(benchmark::State& state) {
  const std::string src = LAMPNAV_SOURCE_DIR;
  const std::string dir =
      (fs::temp_directory_path() / ("lampnav_ros_bench_" + std::to_string(::getpid()))).string();
  fs::create_directories(dir);
  const std::string text = slurp(src + "/maps/office_floor.geojson");
  const graph::TopologicalMap map = graph::parse_map(text, "office_floor.geojson").map;
  const RobotDescription robot = read_robot_description(src + "/maps/robots/pioneer.json");
  const std::string log = dir + "/corridor.mcap";
  // Recorded as PNG: the player sends those bytes, or JPEG at the argument's quality made from
  // them.
  sim::Scenario scenario = sim::make_named_scenario("corridor", map, text, robot, 1);
  scenario.images.format = io::ImageEncoding::Format::png;
  sim::record_mission(scenario, log);
  const io::MissionLog mission = io::read_mission_log(log);
  const double messages = static_cast<double>(
      mission.wheels.size() + mission.ceiling_images.size() + mission.omni_images.size());
  const std::string domain = std::to_string(1 + ::getpid() % 230);
  char start[96] = "";
  if (state.range(1) == 1)
    std::snprintf(start, sizeof start, " --initial-pose %.17g,%.17g,%.17g", scenario.start.x(),
                  scenario.start.y(), scenario.start.yaw());
  const std::string start_pose = start;
  for (auto _ : state) {
    fs::remove(dir + "/stats.json");
    const std::string node = std::string(LAMPNAV_BINARY) + " node --robot " + src +
                             "/maps/robots/pioneer.json --map " + src +
                             "/maps/office_floor.geojson --domain " + domain + start_pose +
                             (state.range(0) < 0 ? " --ceiling-topic /ceiling_camera/image_raw"
                                                   " --omni-topic /omni_camera/image_raw"
                                                 : "") +
                             " --joint-states-topic /joint_states --wheel-radius 0.1"
                             " --idle-exit 3 --quiet --stats " +
                             dir + "/stats.json > " + dir + "/node.out 2>&1 &";
    const std::string player = std::string(LAMPNAV_LOG_PLAYER) + " " + log + " --domain " + domain +
                               " --rate 3.05 --wheel-radius 0.1 --tf-static" +
                               (state.range(0) > 0     ? " --jpeg " + std::to_string(state.range(0))
                                : state.range(0) == -2 ? std::string(" --raw-encoding yuyv")
                                : state.range(0) < 0   ? std::string(" --raw")
                                                       : std::string()) +
                               " > " + dir + "/player.out 2>&1";
    if (std::system(node.c_str()) != 0 || std::system(player.c_str()) != 0) {
      state.SkipWithError(("the node or the player failed: " + slurp(dir + "/player.out")).c_str());
      break;
    }
    for (int k = 0; k < 300 && !fs::exists(dir + "/stats.json"); ++k) ::usleep(100000);
    ::usleep(300000);
    nlohmann::json s;
    try {
      s = nlohmann::json::parse(slurp(dir + "/stats.json"));
    } catch (const std::exception&) {
      state.SkipWithError(("no statistics from the node: " + slurp(dir + "/node.out")).c_str());
      break;
    }
    const auto& ms = s["image_to_pose_ms"];
    state.SetIterationTime(ms["ceiling"]["p99"].get<double>() / 1000);
    state.counters["ceiling_p50_ms"] = ms["ceiling"]["p50"].get<double>();
    state.counters["ceiling_p99_ms"] = ms["ceiling"]["p99"].get<double>();
    state.counters["omni_p50_ms"] = ms["omni"]["p50"].get<double>();
    state.counters["omni_p99_ms"] = ms["omni"]["p99"].get<double>();
    state.counters["omni_max_ms"] = ms["omni"]["max"].get<double>();
    state.counters["omni_frames"] = ms["omni"]["n"].get<double>();
    // From the decoded image to the pose: the node's own work, without decoding or waiting.
    state.counters["omni_work_p99_ms"] = s["decoded_to_pose_ms"]["omni"]["p99"].get<double>();
    // Omni images after which no pose went out, only hypotheses (the start not found yet; the
    // first search the whole map): counted apart from the poses.
    const auto& searching = s["image_to_hypotheses_ms"]["omni"];
    state.counters["omni_searching_frames"] = searching["n"].get<double>();
    state.counters["omni_searching_max_ms"] = searching["max"].get<double>();
    state.counters["images_before_start"] = s["images_before_start"]["ceiling"].get<double>() +
                                            s["images_before_start"]["omni"].get<double>();
    const double received = s["odometry"]["used"].get<double>() +
                            s["ceiling"]["used"].get<double>() + s["omni"]["used"].get<double>();
    state.counters["messages"] = messages;
    state.counters["lost"] = messages - received;
  }
  fs::remove_all(dir);
}
BENCHMARK(BM_NodeImageToPose)
    ->Args({0, 0})
    ->Args({90, 0})
    ->Args({90, 1})
    ->Args({-1, 0})
    ->Args({-1, 1})
    ->Args({-2, 1})
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
