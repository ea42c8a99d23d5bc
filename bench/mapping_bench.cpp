// Map building (issue 15's speed target: a 10-minute drive in at most 20 s): `lampnav map build`
// on a recorded drive, from reading the log to the finished map (decoding and detecting every
// ceiling frame, the lamp SLAM, the places), on a generated 100-node building. The log is
// recorded once, before the timing, by the simulator (rendered frames, the real detector).

#include <benchmark/benchmark.h>

#include <unistd.h>
#include <filesystem>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/mapping/map_builder.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav/sim/scenario.hpp"

namespace lampnav {
namespace {

void BM_MapBuildFromLog(benchmark::State& state) {
  sim::BuildingOptions bo;
  bo.nodes = 100;
  bo.block_m = 30;  // corner to corner: 240 m, ten minutes of driving with the turns
  bo.seed = 5;
  const sim::Building b = sim::generate_building(bo);
  const graph::TopologicalMap map = graph::parse_map(b.geojson, "generated").map;
  const RobotDescription robot =
      read_robot_description(std::string(LAMPNAV_SOURCE_DIR) + "/maps/robots/pioneer.json");
  const int k = b.grid - 1;
  const sim::Scenario s = sim::make_route_scenario(
      map, b.geojson, robot, "J0_0", "J" + std::to_string(k) + "_" + std::to_string(k), 1);
  const std::string log_path = (std::filesystem::temp_directory_path() /
                                ("lampnav_map_bench_" + std::to_string(::getpid()) + ".mcap"))
                                   .string();
  const auto stats = sim::record_mission(s, log_path, {});
  double drive_s = 0, lamps = 0;
  for (auto _ : state) {
    const io::MissionLog log = io::read_mission_log(log_path);
    const mapping::MapBuildResult r = mapping::build_map(log, log_path, robot, {}, {});
    lamps = static_cast<double>(r.map.lamp_count());
    drive_s = to_seconds(log.wheels.back().value.stamp - log.wheels.front().value.stamp);
    benchmark::DoNotOptimize(r);
  }
  std::filesystem::remove(log_path);
  state.counters["drive_min"] = drive_s / 60;
  state.counters["lamps"] = lamps;
  (void)stats;
}
BENCHMARK(BM_MapBuildFromLog)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace
}  // namespace lampnav

BENCHMARK_MAIN();
