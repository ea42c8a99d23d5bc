// Map-level costs on the bundled office floor: load and validate, plan, locate a pose, find lamps;
// and how they grow on generated buildings of 10, 100 and 1,000 nodes (sim::generate_building).
// Targets (issue 8) on the 1,000-node building: map load 200 ms, route planning 1 ms.

#include <benchmark/benchmark.h>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/planner.hpp"
#include "lampnav/graph/route_commands.hpp"
#include "lampnav/sim/building.hpp"

#include <map>
#include <random>

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

// Generated buildings, made once per size.
const sim::Building& building(int nodes) {
  static std::map<int, sim::Building> cache;
  auto it = cache.find(nodes);
  if (it == cache.end()) {
    sim::BuildingOptions o;
    o.nodes = nodes;
    it = cache.emplace(nodes, sim::generate_building(o)).first;
  }
  return it->second;
}

void BM_BuildingMapLoad(benchmark::State& state) {
  const sim::Building& b = building(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    graph::LoadedMap lm = graph::parse_map(b.geojson, "generated");
    benchmark::DoNotOptimize(lm);
  }
  state.counters["nodes"] = b.nodes;
  state.counters["lamps"] = b.lamps;
}
BENCHMARK(BM_BuildingMapLoad)->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);

// Corner to the far corner: the longest route of the building.
void BM_BuildingRoutePlanning(benchmark::State& state) {
  const sim::Building& b = building(static_cast<int>(state.range(0)));
  const graph::LoadedMap lm = graph::parse_map(b.geojson, "generated");
  const std::string far = "J" + std::to_string(b.grid - 1) + "_" + std::to_string(b.grid - 1);
  const NodeId from = lm.map.find_node("J0_0")->id, to = lm.map.find_node(far)->id;
  for (auto _ : state) benchmark::DoNotOptimize(graph::plan_route(lm.map, from, to));
  state.counters["nodes"] = b.nodes;
}
BENCHMARK(BM_BuildingRoutePlanning)->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

// Which node holds a point, for points spread over the building.
void BM_BuildingWhichNode(benchmark::State& state) {
  const sim::Building& b = building(static_cast<int>(state.range(0)));
  const graph::LoadedMap lm = graph::parse_map(b.geojson, "generated");
  const double size = 20.0 * (b.grid - 1);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1.0, size + 1.0);
  std::vector<Eigen::Vector2d> pts(4096);
  for (auto& p : pts) p = {u(rng), u(rng)};
  std::size_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(lm.map.node_containing(pts[k++ % pts.size()]));
  state.counters["nodes"] = b.nodes;
}
BENCHMARK(BM_BuildingWhichNode)->Arg(10)->Arg(100)->Arg(1000);

}  // namespace

BENCHMARK_MAIN();
