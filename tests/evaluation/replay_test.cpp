// Replay on logs written in memory, without rendering: the recorded robot's order of inputs, a
// replay on wheels alone that must equal dead reckoning exactly, frames that do not decode, logs
// that cannot be replayed, and the files a replay writes read back.

#include "lampnav/evaluation/replay.hpp"

#include <nlohmann/json.hpp>
#include <variant>

#include "../navigation/office.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/io/mcap.hpp"

namespace lampnav::evaluation {
namespace {

using test::at_s;

// A drive on the office's C1 by an ideal differential drive: wheel readings at 50 Hz, the truth
// at every reading (dead reckoning is the truth), straight, a left curve, straight.
io::MissionLog office_drive(const test::NavOffice& office, const Pose2& start) {
  io::MissionLog log;
  Pose2 pose = start;
  double left = 0, right = 0;
  for (int k = 0; k <= 500; ++k) {
    const double t = 1.0 + k * 0.02;
    if (k > 0) {
      const bool curve = k > 200 && k <= 350;
      const double dl = (curve ? 0.3 : 0.5) * 0.02, dr = 0.5 * 0.02;
      const fusion::StateVector x =
          fusion::predict_motion(pose.vector(), dl, dr, office.robot.semi_axis);
      pose = Pose2(x(0), x(1), wrap_angle(x(2)));
      left += dl;
      right += dr;
    }
    log.wheels.push_back({at_s(t), {at_s(t), left, right}});
    log.truth.push_back({at_s(t), {at_s(t), pose}});
  }
  return log;
}

io::ImageFrame frame(const std::string& camera, double capture_s, std::string bytes) {
  return {at_s(capture_s), camera, "png", std::move(bytes)};
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

bool any_contains(const std::vector<std::string>& lines, const std::string& part) {
  return std::any_of(lines.begin(), lines.end(),
                     [&](const std::string& l) { return l.find(part) != std::string::npos; });
}

TEST(LogRobot, GivesTheInputsAsTheyArrivedAndSaysWhichFramesDidNotDecode) {
  io::MissionLog log;
  for (int k = 0; k < 3; ++k) log.wheels.push_back({at_s(k * 0.1), {at_s(k * 0.1), k * 0.01, 0}});
  // A ceiling frame taken at 0.05 s reaches the stack with the wheel reading of 0.1 s, an omni
  // frame at 0.15 s does not decode, and one more ceiling frame arrives last.
  const std::string png = io::encode_png(Image8(8, 6, 200));
  log.ceiling_images.push_back({at_s(0.1), frame("ceiling_camera", 0.05, png)});
  log.omni_images.push_back({at_s(0.15), frame("omni_camera", 0.12, "not an image")});
  log.ceiling_images.push_back({at_s(0.3), frame("ceiling_camera", 0.25, png)});

  LogRobot robot(log, /*use_ceiling=*/true, /*use_omni=*/true);
  std::vector<std::string> order;
  while (auto in = robot.next()) {
    if (const auto* w = std::get_if<WheelInput>(&*in)) {
      order.push_back("wheels " + std::to_string(std::lround(to_seconds(w->stamp) * 1000)));
    } else if (const auto* f = std::get_if<FrameInput>(&*in)) {
      EXPECT_EQ(f->camera, CameraRole::ceiling);
      EXPECT_EQ(f->image.width, 8);
      EXPECT_EQ(f->image.at(3, 2), 200);
      order.push_back("ceiling " + std::to_string(std::lround(to_seconds(f->capture) * 1000)) +
                      "/" + std::to_string(std::lround(to_seconds(f->arrival) * 1000)));
    }
  }
  EXPECT_EQ(order, (std::vector<std::string>{"wheels 0", "wheels 100", "ceiling 50/100",
                                             "wheels 200", "ceiling 250/300"}));
  ASSERT_EQ(robot.problems().size(), 1u);
  EXPECT_THAT(robot.problems()[0], ::testing::HasSubstr("omni frame captured at 0.12"));

  // Without the cameras asked for, only the wheels come.
  LogRobot wheels_only(log, false, false);
  int n = 0;
  while (auto in = wheels_only.next()) {
    EXPECT_TRUE(std::holds_alternative<WheelInput>(*in));
    ++n;
  }
  EXPECT_EQ(n, 3);
  EXPECT_TRUE(wheels_only.problems().empty());
}

TEST(Replay, OnExactWheelsFromTheTrueStartItIsTheDeadReckoning) {
  const test::NavOffice office;
  const Pose2 start = office.on_c1(1.0);
  const io::MissionLog log = office_drive(office, start);
  ReplayOptions opt;
  opt.initial_pose = start;
  opt.use_ceiling = opt.use_omni = false;
  const ReplayResult r = replay(log, office.map, office.robot, opt);

  ASSERT_EQ(r.estimates.size(), log.wheels.size());  // one per wheel reading
  for (std::size_t k = 0; k < r.estimates.size(); ++k) {
    EXPECT_EQ(r.estimates[k].stamp, log.wheels[k].value.stamp);
    EXPECT_EQ(r.estimates[k].mode, fusion::LocalizerMode::tracking);
  }
  EXPECT_EQ(r.odometry.size(), log.wheels.size());
  const Metrics& m = r.metrics;
  EXPECT_TRUE(m.has_truth);
  EXPECT_EQ(m.position_error_m.n, log.wheels.size());
  EXPECT_LT(m.position_error_m.max, 1e-9);
  EXPECT_LT(m.yaw_error_deg.max, 1e-7);
  EXPECT_EQ(m.wrong_fixes, 0);
  EXPECT_EQ(m.frames, 0u);
  EXPECT_NEAR(m.duration_s, 10.0, 1e-9);
  EXPECT_GT(m.realtime_factor, 0.0);
  EXPECT_TRUE(any_contains(r.notes, "no ceiling camera"));
  EXPECT_TRUE(any_contains(r.notes, "started from the given pose"));
  // The estimates are in C1 while the robot is.
  EXPECT_EQ(r.estimates.front().node, "C1");
}

TEST(Replay, FramesThatDoNotDecodeAreSkippedAndSaidAndTheRestGoesOn) {
  const test::NavOffice office;
  const Pose2 start = office.on_c1(1.0);
  io::MissionLog log = office_drive(office, start);
  for (int k = 0; k < 20; ++k) {
    const double t = 1.0 + 0.5 * k;
    log.ceiling_images.push_back({at_s(t + 0.03), frame("ceiling_camera", t, "\x89PNG cut")});
  }
  ReplayOptions opt;
  opt.initial_pose = start;
  opt.use_omni = false;
  const ReplayResult r = replay(log, office.map, office.robot, opt);
  EXPECT_EQ(r.metrics.ceiling_frames, 0u);
  EXPECT_EQ(std::count_if(r.notes.begin(), r.notes.end(),
                          [](const std::string& n) {
                            return n.rfind("skipped ceiling frame captured at", 0) == 0;
                          }),
            20);
  ASSERT_EQ(r.estimates.size(), log.wheels.size());
  EXPECT_LT(r.metrics.position_error_m.max, 1e-9);
}

TEST(Replay, RefusesALogWithNothingToLocalizeWithSayingWhy) {
  const test::NavOffice office;
  io::MissionLog log = office_drive(office, office.on_c1(1.0));
  const io::MissionLog no_wheels = [&] {
    io::MissionLog l = log;
    l.wheels.clear();
    return l;
  }();
  try {
    replay(no_wheels, office.map, office.robot, {});
    ADD_FAILURE() << "replayed a log without wheel readings";
  } catch (const JobFailed& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("/wheels"));
  }
  // No start pose and no omni frames: nothing can find the robot.
  try {
    replay(log, office.map, office.robot, {});
    ADD_FAILURE() << "replayed without a start pose or an omni camera";
  } catch (const JobFailed& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("--initial-pose"));
  }
}

TEST(WriteReplay, WritesWhatTheSpecListsAndItReadsBack) {
  const test::NavOffice office;
  const Pose2 start = office.on_c1(1.0);
  io::MissionLog log = office_drive(office, start);
  log.events.push_back({at_s(2.0), {at_s(2.0), io::EventKind::lamp_failure, "C1/lamp2"}});
  log.commands.push_back({at_s(1.0), {at_s(1.0), "follow C1"}});
  ReplayOptions opt;
  opt.initial_pose = start;
  opt.use_ceiling = opt.use_omni = false;
  const ReplayResult r = replay(log, office.map, office.robot, opt);
  const std::string map_text = test::slurp(test::source_path("maps/office_floor.geojson"));
  const std::string robot_text = test::slurp(test::source_path("maps/robots/pioneer.json"));
  const std::string dir = test::temp_path("replay_out");
  write_replay(r, log, office.map, map_text, robot_text, dir);

  const io::McapFile f = io::read_mcap(dir + "/replay.mcap");
  EXPECT_TRUE(f.report.problems.empty());
  auto count = [&](const char* topic) {
    const io::McapChannel* c = f.channel(topic);
    if (!c) return -1;
    return static_cast<int>(
        std::count_if(f.messages.begin(), f.messages.end(),
                      [&](const io::McapMessage& m) { return m.channel_id == c->id; }));
  };
  const int n = static_cast<int>(r.estimates.size());
  EXPECT_EQ(count(io::topics::kPose), n);
  EXPECT_EQ(count(io::topics::kEstimate), n);
  EXPECT_EQ(count(io::topics::kScene), 1);
  // Each estimate carries its mode as the spec's word, the typed mode's own.
  {
    const io::McapChannel* c = f.channel(io::topics::kEstimate);
    ASSERT_NE(c, nullptr);
    std::size_t k = 0;
    for (const io::McapMessage& m : f.messages) {
      if (m.channel_id != c->id || k >= r.estimates.size()) continue;
      const std::string& text = m.data;
      const std::string word = std::string("\"mode\":\"") + to_string(r.estimates[k++].mode) + "\"";
      EXPECT_NE(text.find(word), std::string::npos) << text;
    }
    EXPECT_EQ(k, r.estimates.size());
  }
  EXPECT_GE(count(io::topics::kLog), 2);
  ASSERT_NE(f.attachment("map.geojson"), nullptr);
  EXPECT_EQ(f.attachment("map.geojson")->data, map_text);
  EXPECT_EQ(f.attachment("robot.json")->data, robot_text);

  // The inputs are in it as they were.
  const io::MissionLog back = io::read_mission_log(dir + "/replay.mcap");
  ASSERT_EQ(back.wheels.size(), log.wheels.size());
  for (std::size_t k = 0; k < log.wheels.size(); ++k) {
    EXPECT_EQ(back.wheels[k].log_time, log.wheels[k].log_time);
    EXPECT_EQ(back.wheels[k].value.left, log.wheels[k].value.left);
    EXPECT_EQ(back.wheels[k].value.right, log.wheels[k].value.right);
  }
  EXPECT_EQ(back.truth.size(), log.truth.size());
  ASSERT_EQ(back.events.size(), 1u);
  EXPECT_EQ(back.events[0].value.type(), io::EventKind::lamp_failure);
  ASSERT_EQ(back.commands.size(), 1u);
  EXPECT_EQ(back.commands[0].value.text, "follow C1");

  EXPECT_EQ(lines_of(test::slurp(dir + "/estimate.tum")).size(), r.estimates.size());
  EXPECT_EQ(lines_of(test::slurp(dir + "/truth.tum")).size(), log.truth.size());
  EXPECT_EQ(test::slurp(dir + "/metrics.json"), metrics_json(r.metrics));
  std::filesystem::remove_all(dir);

  // A place it cannot write is an input error naming it.
  try {
    write_replay(r, log, office.map, map_text, robot_text, "/proc/lampnav_cannot_be_here");
    ADD_FAILURE() << "wrote under /proc";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("/proc/lampnav_cannot_be_here"));
  }
}

}  // namespace
}  // namespace lampnav::evaluation
