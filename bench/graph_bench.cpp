// Map-level costs on the bundled office floor: load and validate, plan, locate a pose, find lamps.
// Issue 8 extends these to generated buildings of 10 to 1,000 nodes.

#include <benchmark/benchmark.h>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/planner.hpp"
#include "lampnav/graph/route_commands.hpp"

namespace {

using namespace lampnav;

const std::string kOffice = std::string(LAMPNAV_SOURCE_DIR) + "/maps/office_floor.geojson";

void BM_MapLoadAndValidate(benchmark::State& state) {
  for (auto _ : state) {
    graph::LoadedMap lm = graph::read_map(kOffice);
    benchmark::DoNotOptimize(lm);
  }
}
BENCHMARK(BM_MapLoadAndValidate)->Unit(benchmark::kMicrosecond);

void BM_PlanRouteAndCommands(benchmark::State& state) {
  const graph::LoadedMap lm = graph::read_map(kOffice);
  const NodeId from = lm.map.find_node("Lab 1")->id, to = lm.map.find_node("Workshop")->id;
  for (auto _ : state) {
    const auto route = graph::plan_route(lm.map, from, to);
    auto cmds = graph::route_to_commands(lm.map, *route);
    benchmark::DoNotOptimize(cmds);
  }
}
BENCHMARK(BM_PlanRouteAndCommands)->Unit(benchmark::kMicrosecond);

void BM_NodeContaining(benchmark::State& state) {
  const graph::LoadedMap lm = graph::read_map(kOffice);
  double x = 0;
  for (auto _ : state) {
    x = x > 47 ? 0.3 : x + 0.7;
    benchmark::DoNotOptimize(lm.map.node_containing({x, 10.0}));
  }
}
BENCHMARK(BM_NodeContaining);

void BM_LampsAhead(benchmark::State& state) {
  const graph::LoadedMap lm = graph::read_map(kOffice);
  double x = 2;
  for (auto _ : state) {
    x = x > 38 ? 2.0 : x + 0.37;
    auto lamps = lm.map.lamps_ahead(Pose2(x, 10.0, 0.0), 4.0, 1.0);
    benchmark::DoNotOptimize(lamps);
  }
}
BENCHMARK(BM_LampsAhead);

}  // namespace

BENCHMARK_MAIN();
