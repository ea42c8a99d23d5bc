// Faults injected into a recorded mission (the corridor run, 81 s, recorded once per test
// binary): cameras that stop for 30 s, odometry that stops, a clock that jumps back or forward,
// every message twice, messages out of order, a frame that arrives after the filter's history,
// a log cut mid-chunk. Each fault is counted and said (metrics.json's input_faults, the replay's
// notes); the estimate recovers or says lost, never a wrong fix; nothing that arrived whole is
// dropped; no exception escapes.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "lampnav/evaluation/replay.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav_test.hpp"

namespace lampnav::navigation {
namespace {

using namespace lampnav::evaluation;  // replay, its results and outputs

namespace fs = std::filesystem;

struct Recorded {
  graph::TopologicalMap map;
  RobotDescription robot;
  Pose2 start;
  std::string path;
  io::MissionLog log;
  ReplayResult clean;
  Recorded() {
    const std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
    map = graph::parse_map(geojson, "office_floor.geojson").map;
    robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
    const sim::Scenario s = sim::make_named_scenario("corridor", map, geojson, robot, 1);
    start = s.start;
    path = test::temp_path("fault_injection.mcap");
    sim::record_mission(s, path);
    log = io::read_mission_log(path);
    clean = run(log);
  }
  ~Recorded() { fs::remove(path); }
  ReplayResult run(const io::MissionLog& l) const {
    ReplayOptions o;
    o.initial_pose = start;
    return replay(l, map, robot, o);
  }
};

const Recorded& recorded() {
  static const Recorded r;
  return r;
}

Stamp at(double s) { return stamp_from_nanoseconds(static_cast<std::int64_t>(s * 1e9)); }

std::string notes(const ReplayResult& r) {
  std::string s;
  for (const auto& n : r.notes) s += n + "\n";
  return s;
}

// The estimate at the end is certain and right.
void ends_tracking(const ReplayResult& r, const io::MissionLog& log, double tolerance_m) {
  ASSERT_FALSE(r.estimates.empty());
  const EstimateSample& e = r.estimates.back();
  EXPECT_TRUE(fusion::is_certain(e.mode)) << fusion::to_string(e.mode);
  const io::TruthTrack truth(log.truth);
  EXPECT_LT((e.pose.translation() - truth.at(e.stamp).translation()).norm(), tolerance_m);
}

template <class T>
void erase_between(std::vector<io::Logged<T>>& v, Stamp from, Stamp to) {
  v.erase(
      std::remove_if(v.begin(), v.end(),
                     [&](const auto& m) { return m.value.stamp >= from && m.value.stamp < to; }),
      v.end());
}

// The robot's clock jumps at `from`: every stamp after it moves; the messages still arrive when
// they did (backwards) or as late as their stamps say (forwards).
template <class T>
void shift_after(std::vector<io::Logged<T>>& v, Stamp from, Duration by) {
  for (auto& m : v)
    if (m.log_time >= from) {
      if (by > Duration::zero()) m.log_time += by;
      m.value.stamp += by;
    }
}

TEST(FaultInjection, CamerasStopFor30SecondsAndComeBack) {
  io::MissionLog log = recorded().log;
  erase_between(log.ceiling_images, at(20), at(50));
  erase_between(log.omni_images, at(20), at(50));
  const ReplayResult r = recorded().run(log);
  std::cout << notes(r);
  EXPECT_EQ(r.metrics.input_faults[1].gaps, 1u);
  EXPECT_GE(r.metrics.input_faults[1].longest_gap_s, 30.0);
  EXPECT_EQ(r.metrics.input_faults[2].gaps, 1u);
  EXPECT_THAT(notes(r), ::testing::HasSubstr("ceiling camera: 1 gaps"));
  EXPECT_EQ(r.metrics.wrong_fixes, 0);
  EXPECT_EQ(r.outcome.ceiling_frames, log.ceiling_images.size());  // every frame that came
  EXPECT_EQ(r.outcome.omni_frames, log.omni_images.size());
  ends_tracking(r, log, 0.1);
}

TEST(FaultInjection, OdometryStopsFor10Seconds) {
  io::MissionLog log = recorded().log;
  erase_between(log.wheels, at(30), at(40));
  const ReplayResult r = recorded().run(log);
  std::cout << notes(r);
  EXPECT_EQ(r.metrics.input_faults[0].gaps, 1u);
  EXPECT_NEAR(r.metrics.input_faults[0].longest_gap_s, 10.0, 0.1);
  // The localizer lets go of the pose and says why, as a cause a program can act on: the ceiling
  // frames of the gap contradict a robot that seems to stand still (the map's lamps, or the
  // frames' own lamps moving while the wheels say nothing), or the gap itself. Then,
  // perhaps after naming the places it could be (the omni view along C1 fits more than one while
  // the wheels say nothing) and the gap, a global fix, and a measurement that confirms it.
  std::vector<fusion::ModeCause> causes;
  for (const auto& e : r.events) {
    std::cout << to_seconds(e.stamp) << " s: " << fusion::to_string(e.cause) << ", " << e.reason
              << "\n";
    causes.push_back(e.cause);
  }
  ASSERT_GE(r.events.size(), 2u);
  EXPECT_EQ(r.events.front().mode, fusion::LocalizerMode::lost);
  EXPECT_TRUE(causes.front() == fusion::ModeCause::ceiling_contradicts ||
              causes.front() == fusion::ModeCause::moved_unseen ||
              causes.front() == fusion::ModeCause::odometry_gap)
      << fusion::to_string(causes.front());
  EXPECT_GE(to_seconds(r.events.front().stamp), 29.5);
  std::size_t fix = 1;
  while (fix < causes.size() && (causes[fix] == fusion::ModeCause::hypotheses_undecided ||
                                 causes[fix] == fusion::ModeCause::odometry_gap))
    ++fix;
  ASSERT_LT(fix, causes.size());
  EXPECT_EQ(causes[fix], fusion::ModeCause::global_fix);

  EXPECT_EQ(r.metrics.wrong_fixes, 0);
  EXPECT_EQ(r.outcome.wheel_readings, log.wheels.size());
  ends_tracking(r, log, 0.1);
}

// The robot's clock jumps at 40 s (every stamp after it moved, the truth too).
io::MissionLog clock_jump(Duration by) {
  io::MissionLog log = recorded().log;
  shift_after(log.wheels, at(40), by);
  shift_after(log.ceiling_images, at(40), by);
  shift_after(log.omni_images, at(40), by);
  shift_after(log.truth, at(40), by);
  return log;
}

TEST(FaultInjection, TheClockJumpsBack) {
  const io::MissionLog log = clock_jump(std::chrono::seconds(-5));
  const ReplayResult r = recorded().run(log);
  std::cout << notes(r);
  // 5 s of each stream stamped before what came before it.
  EXPECT_NEAR(double(r.metrics.input_faults[0].out_of_order), 5 * 50, 5);
  EXPECT_GT(r.metrics.input_faults[1].out_of_order, 40u);
  EXPECT_EQ(r.outcome.wheel_readings, log.wheels.size());
  // (The truth overlaps itself for those 5 s, so wrong fixes are not scored here.)
  ends_tracking(r, log, 0.1);
}

TEST(FaultInjection, TheClockJumpsForward) {
  const io::MissionLog log = clock_jump(std::chrono::seconds(60));
  const ReplayResult r = recorded().run(log);
  std::cout << notes(r);
  EXPECT_EQ(r.metrics.input_faults[0].gaps, 1u);
  EXPECT_GE(r.metrics.input_faults[0].longest_gap_s, 60.0);
  EXPECT_EQ(r.metrics.wrong_fixes, 0);
  ends_tracking(r, log, 0.1);
}

TEST(FaultInjection, EveryMessageTwice) {
  io::MissionLog log = recorded().log;
  auto twice = [](auto& v) {
    auto copy = v;
    v.insert(v.end(), copy.begin(), copy.end());
    std::stable_sort(v.begin(), v.end(),
                     [](const auto& a, const auto& b) { return a.log_time < b.log_time; });
  };
  twice(log.wheels);
  twice(log.ceiling_images);
  twice(log.omni_images);
  const ReplayResult r = recorded().run(log);
  std::cout << notes(r);
  EXPECT_EQ(r.metrics.input_faults[0].duplicates, recorded().log.wheels.size());
  EXPECT_EQ(r.metrics.input_faults[1].duplicates, recorded().log.ceiling_images.size());
  EXPECT_EQ(r.metrics.wrong_fixes, 0);
  // A second copy adds nothing: the estimate is the clean replay's.
  const EstimateSample &a = r.estimates.back(), &b = recorded().clean.estimates.back();
  EXPECT_EQ(a.stamp, b.stamp);
  EXPECT_LT((a.pose.translation() - b.pose.translation()).norm(), 1e-3);
  EXPECT_NEAR(r.metrics.position_error_m.mean, recorded().clean.metrics.position_error_m.mean,
              0.005);
}

TEST(FaultInjection, MessagesOutOfOrder) {
  io::MissionLog log = recorded().log;
  // Each pair of wheel readings arrives the wrong way round, and so does each pair of frames.
  auto swap_pairs = [](auto& v) {
    for (std::size_t k = 0; k + 1 < v.size(); k += 2) std::swap(v[k].log_time, v[k + 1].log_time);
  };
  swap_pairs(log.wheels);
  swap_pairs(log.ceiling_images);
  const ReplayResult r = recorded().run(log);
  std::cout << notes(r);
  EXPECT_GT(r.metrics.input_faults[0].out_of_order, log.wheels.size() / 3);
  EXPECT_GT(r.metrics.input_faults[1].out_of_order, log.ceiling_images.size() / 3);
  EXPECT_EQ(r.metrics.wrong_fixes, 0);
  EXPECT_EQ(r.outcome.ceiling_frames, log.ceiling_images.size());
  ends_tracking(r, log, 0.1);
}

TEST(FaultInjection, AFrameAfterTheFiltersHistory) {
  io::MissionLog log = recorded().log;
  // One ceiling frame held back 30 s (the history holds a few seconds).
  auto& f = log.ceiling_images[log.ceiling_images.size() / 3];
  f.log_time = f.value.stamp + std::chrono::seconds(30);
  std::stable_sort(log.ceiling_images.begin(), log.ceiling_images.end(),
                   [](const auto& a, const auto& b) { return a.log_time < b.log_time; });
  const ReplayResult r = recorded().run(log);
  std::cout << notes(r);
  // The clean run already has frames from before its first wheel reading: this one adds to them.
  EXPECT_EQ(r.metrics.frames_too_old, recorded().clean.metrics.frames_too_old + 1);
  EXPECT_THAT(notes(r), ::testing::HasSubstr("captured before the filter's history"));
  EXPECT_EQ(r.outcome.ceiling_frames, log.ceiling_images.size());  // it came, and was counted
  EXPECT_EQ(r.metrics.wrong_fixes, 0);
  ends_tracking(r, log, 0.1);
}

TEST(FaultInjection, ALogCutMidChunk) {
  std::ifstream in(recorded().path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const std::string cut = test::temp_path("fault_injection_cut.mcap");
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() * 3 / 5 + 777);
  const io::MissionLog log = io::read_mission_log(cut);
  fs::remove(cut);
  EXPECT_TRUE(log.report.truncated);
  ASSERT_GT(log.wheels.size(), 100u);
  EXPECT_LT(log.wheels.size(), recorded().log.wheels.size());
  const ReplayResult r = recorded().run(log);
  EXPECT_THAT(notes(r), ::testing::HasSubstr("the log is truncated"));
  EXPECT_EQ(r.outcome.wheel_readings, log.wheels.size());  // what arrived whole is replayed
  EXPECT_EQ(r.metrics.wrong_fixes, 0);
  ends_tracking(r, log, 0.1);
}

// Not a fault, found by one: the robot found anew 40 s into the corridor run, under the junction
// lamp J1 with two window glints near the zenith. The glints were among the few blobs that seed
// the global search, the true pose was never enumerated, and a look-alike junction 17 m away was
// published as certain. Glints no longer seed (fusion/src/spurious_blobs.hpp).
TEST(Relocalization, AnUnknownStartUnderAJunctionLampWithGlintsNearTheZenith) {
  io::MissionLog log = recorded().log;
  erase_between(log.wheels, at(0), at(40));
  erase_between(log.ceiling_images, at(0), at(40));
  erase_between(log.omni_images, at(0), at(40));
  const ReplayResult r = replay(log, recorded().map, recorded().robot, ReplayOptions{});
  for (const auto& e : r.events)
    std::cout << to_seconds(e.stamp) << " s: " << fusion::to_string(e.mode) << ", " << e.reason
              << "\n";
  EXPECT_EQ(r.metrics.wrong_fixes, 0);
  ASSERT_FALSE(r.events.empty());
  EXPECT_LE(to_seconds(r.events.front().stamp), 42.0);  // found within two omni frames
  ends_tracking(r, log, 0.1);
}

}  // namespace
}  // namespace lampnav::navigation
