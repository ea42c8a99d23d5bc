// The pose EKF at odometry rate: one prediction, one gated update, and a measurement 1 s late
// (100 odometry steps at 100 Hz re-applied). Targets (issue 5): 100 ns, 500 ns, 20 us.
// Global localization from one omnidirectional image on the museum map, both methods, and one
// merit evaluation. Targets (issue 6): `paper` 2 ms, `default` 5 ms per image.

#include <benchmark/benchmark.h>

#include <random>

#include "lampnav/fusion/ekf.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/merit.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav/sim/renderers.hpp"

#include <map>

namespace {

using namespace lampnav;
using fusion::PoseEkf;
namespace graph = lampnav::graph;
namespace vision = lampnav::vision;
namespace sim = lampnav::sim;

const Eigen::Matrix3d kP0 = Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
const Eigen::Matrix3d kR = Eigen::Vector3d(4e-4, 4e-4, 1e-4).asDiagonal();

Stamp at_ms(std::int64_t ms) { return stamp_from_nanoseconds(ms * 1'000'000); }

void BM_EkfPredict(benchmark::State& state) {
  PoseEkf f;
  f.initialize(at_ms(0), Pose2(0, 0, 0), kP0);
  std::int64_t t = 0;
  for (auto _ : state) {
    t += 10;
    benchmark::DoNotOptimize(f.predict(at_ms(t), 0.005, 0.0052));
  }
}
BENCHMARK(BM_EkfPredict);

// A measurement at the latest odometry through the chi-square gate, timed as a pair with the
// prediction before it (which keeps the covariance from collapsing): the update alone is this
// minus BM_EkfPredict. Pausing the timer around the prediction would cost more than the update.
void BM_EkfPredictAndGatedUpdate(benchmark::State& state) {
  PoseEkf f;
  f.initialize(at_ms(0), Pose2(0, 0, 0), kP0);
  std::int64_t t = 0;
  for (auto _ : state) {
    t += 10;
    f.predict(at_ms(t), 0.005, 0.0052);
    benchmark::DoNotOptimize(
        f.update(at_ms(t), Pose2(f.pose().x() + 0.001, f.pose().y(), f.pose().yaw()), kR));
  }
}
BENCHMARK(BM_EkfPredictAndGatedUpdate);

// A measurement captured 1 s ago, between two readings: split, update, re-apply 100 steps.
void BM_EkfLateUpdateOneSecond(benchmark::State& state) {
  PoseEkf f;
  f.initialize(at_ms(0), Pose2(0, 0, 0), kP0);
  std::int64_t t = 0;
  for (int i = 0; i < 300; ++i) f.predict(at_ms(t += 10), 0.005, 0.0052);
  std::int64_t reapplied = 0;
  for (auto _ : state) {
    state.PauseTiming();
    f.predict(at_ms(t += 10), 0.005, 0.0052);
    const Stamp captured = at_ms(t - 1000) + std::chrono::milliseconds(3);
    const Pose2 z = f.state_at(captured)->pose();
    state.ResumeTiming();
    const auto r = f.update(captured, z, kR);
    reapplied += r.reapplied_steps;
    benchmark::DoNotOptimize(r);
  }
  state.counters["steps_reapplied"] =
      benchmark::Counter(static_cast<double>(reapplied), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_EkfLateUpdateOneSecond)->Unit(benchmark::kMicrosecond);

}  // namespace

// Twenty museum views from random places in the halls (floor bumps on), detected once.
struct MuseumViews {
  graph::TopologicalMap map;
  RobotDescription robot;
  std::vector<vision::OmniDetection> detections;
  MuseumViews() {
    const std::string src = LAMPNAV_SOURCE_DIR;
    map = graph::read_map(src + "/maps/domus_museum.geojson").map;
    robot = read_robot_description(src + "/maps/robots/pioneer.json");
    const CameraDescription& cam = *robot.find_camera("omni_camera");
    std::vector<const graph::Lamp*> lamps;
    std::vector<const graph::Node*> halls;
    for (const auto& n : map.nodes()) {
      halls.push_back(&n);
      for (const auto& l : n.lamps) lamps.push_back(&l);
    }
    const sim::OmniRenderer renderer(cam, sim::OmniRenderOptions{});
    vision::OmniLampDetector detector(cam);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    std::normal_distribution<double> bump(0, 0.5 * M_PI / 180);
    while (detections.size() < 20) {
      const graph::Polygon& region = halls[rng() % halls.size()]->region;
      const auto box = region.bounds();
      const Eigen::Vector2d p(box.min.x() + u(rng) * (box.max.x() - box.min.x()),
                              box.min.y() + u(rng) * (box.max.y() - box.min.y()));
      if (!region.contains(p)) continue;
      const Image8 img =
          renderer.render(Pose2(p, 2 * M_PI * u(rng)), {bump(rng), bump(rng)}, lamps, rng);
      detections.push_back(detector.detect(vision::ImageView::of(img)));
    }
  }
  const CameraDescription& cam() const { return *robot.find_camera("omni_camera"); }
};

const MuseumViews& museum() {
  static const MuseumViews views;
  return views;
}

void locate(benchmark::State& state, fusion::GlobalMethod method) {
  const MuseumViews& m = museum();
  const fusion::GlobalLocalizer global(m.map, m.cam());
  std::size_t k = 0, evaluations = 0, images = 0;
  for (auto _ : state) {
    const auto r = global.locate(m.detections[k++ % m.detections.size()], method);
    evaluations += r.merit_evaluations;
    ++images;
    benchmark::DoNotOptimize(r.hypotheses.data());
  }
  state.counters["evaluations"] = double(evaluations) / double(images);
}

void BM_GlobalLocalizationPaper(benchmark::State& state) {
  locate(state, fusion::GlobalMethod::paper);
}
BENCHMARK(BM_GlobalLocalizationPaper)->Unit(benchmark::kMillisecond);

void BM_GlobalLocalizationDefault(benchmark::State& state) {
  locate(state, fusion::GlobalMethod::lamp_pairs);
}
BENCHMARK(BM_GlobalLocalizationDefault)->Unit(benchmark::kMillisecond);

// Global localization restricted by the graph on generated buildings (office lamps 0.9 m above
// the omni camera): views from along the corridors, detected once. Target: 50 ms at 1,000 nodes.
struct BuildingViews {
  graph::TopologicalMap map;
  RobotDescription robot;
  std::vector<vision::OmniDetection> detections;
  int lamps = 0;
  explicit BuildingViews(int nodes) {
    sim::BuildingOptions bo;
    bo.nodes = nodes;
    const sim::Building b = sim::generate_building(bo);
    lamps = b.lamps;
    map = graph::parse_map(b.geojson, "generated").map;
    robot = read_robot_description(std::string(LAMPNAV_SOURCE_DIR) + "/maps/robots/pioneer.json");
    const CameraDescription& cam = *robot.find_camera("omni_camera");
    std::vector<const graph::Lamp*> all;
    std::vector<const graph::Node*> corridors;
    for (const auto& n : map.nodes()) {
      if (n.axis) corridors.push_back(&n);
      for (const auto& l : n.lamps) all.push_back(&l);
    }
    const sim::OmniRenderer renderer(cam, sim::OmniRenderOptions{});
    vision::OmniLampDetector detector(cam);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    while (detections.size() < 10) {
      const graph::Node& c = *corridors[rng() % corridors.size()];
      const Pose2 pose(c.axis->point_at(u(rng) * c.axis->length()), 2 * M_PI * u(rng));
      const Image8 img = renderer.render(pose, {}, map.lamps_within(pose.translation(), 30.0), rng);
      detections.push_back(detector.detect(vision::ImageView::of(img)));
    }
  }
};

void BM_GlobalLocalizationBuilding(benchmark::State& state) {
  static std::map<int, BuildingViews> cache;
  const int nodes = static_cast<int>(state.range(0));
  auto it = cache.find(nodes);
  if (it == cache.end()) it = cache.emplace(nodes, BuildingViews(nodes)).first;
  const BuildingViews& b = it->second;
  const fusion::GlobalLocalizer global(b.map, *b.robot.find_camera("omni_camera"));
  std::size_t k = 0;
  for (auto _ : state) {
    const auto r = global.locate(b.detections[k++ % b.detections.size()]);
    benchmark::DoNotOptimize(r.hypotheses.data());
  }
  state.counters["nodes"] = nodes;
  state.counters["lamps"] = b.lamps;
}
BENCHMARK(BM_GlobalLocalizationBuilding)
    ->Arg(10)
    ->Arg(100)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond);

// One merit evaluation (Alg. 1 + Alg. 2) at a random pose.
void BM_MeritEvaluation(benchmark::State& state) {
  const MuseumViews& m = museum();
  const fusion::CeilingMapProjection projection(m.map, m.cam());
  std::vector<Eigen::Vector2d> detected;
  for (const auto& b : m.detections.front().blobs) detected.push_back(b.centroid_px);
  const fusion::MeritFunction merit(detected, 25.0, 1024, 1024);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> x(-8, 28), y(-12, 4), yaw(-M_PI, M_PI);
  std::vector<Pose2> poses;
  for (int i = 0; i < 1024; ++i) poses.emplace_back(x(rng), y(rng), yaw(rng));
  std::vector<Eigen::Vector2d> px;
  std::size_t k = 0;
  for (auto _ : state) {
    projection.project(poses[k++ % poses.size()], px);
    benchmark::DoNotOptimize(merit(px).value);
  }
}
BENCHMARK(BM_MeritEvaluation);

BENCHMARK_MAIN();
