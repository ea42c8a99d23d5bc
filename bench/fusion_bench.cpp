// The pose EKF at odometry rate: one prediction, one gated update, and a measurement 1 s late
// (100 odometry steps at 100 Hz re-applied). Targets (issue 5): 100 ns, 500 ns, 20 us.

#include <benchmark/benchmark.h>

#include "lampnav/fusion/ekf.hpp"

namespace {

using namespace lampnav;
using fusion::PoseEkf;

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

BENCHMARK_MAIN();
