// Replay throughput: the recorded office mission (140 s of robot time: 1,400 ceiling frames,
// 140 omni frames, 7,000 wheel readings) through the runtime loop, images decoded included.
// Target (issue 7): at least 50 times faster than real time.

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/navigation/replay.hpp"
#include "lampnav/sim/scenario.hpp"

namespace {

using namespace lampnav;

struct RecordedMission {
  graph::TopologicalMap map;
  RobotDescription robot;
  Pose2 start;
  io::MissionLog log;
  RecordedMission() {
    const std::string src = LAMPNAV_SOURCE_DIR;
    const std::string text = [&] {
      std::ifstream in(src + "/maps/office_floor.geojson");
      return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    map = graph::parse_map(text, "office_floor.geojson").map;
    robot = read_robot_description(src + "/maps/robots/pioneer.json");
    const sim::Scenario s = sim::make_named_scenario("office-mission", map, text, robot, 1);
    start = s.start;
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("lampnav_bench_" + std::to_string(::getpid()) + ".mcap"))
                                 .string();
    sim::record_mission(s, path);
    log = io::read_mission_log(path);
    std::filesystem::remove(path);
  }
};

void BM_ReplayOfficeMission(benchmark::State& state) {
  static const RecordedMission m;
  navigation::ReplayOptions o;
  o.initial_pose = m.start;
  double robot_s = 0, factor = 0;
  for (auto _ : state) {
    const navigation::ReplayResult r = navigation::replay(m.log, m.map, m.robot, o);
    robot_s = r.metrics.duration_s;
    factor = r.metrics.realtime_factor;
    benchmark::DoNotOptimize(r.estimates.data());
  }
  state.counters["robot_s"] = robot_s;
  state.counters["realtime_factor"] = factor;
}
BENCHMARK(BM_ReplayOfficeMission)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
