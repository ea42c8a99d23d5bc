// The mission log (shared/spec/mission-log.md) on its own: every input written reads back as it
// was, with its capture and arrival times apart; damaged messages are skipped, counted and named
// by topic and sequence while the rest is kept; the order a replay takes the inputs in; the truth
// between its samples; base64.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "lampnav/core/error.hpp"
#include "lampnav/io/mcap.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav_test.hpp"

namespace lampnav::io {
namespace {

using ::testing::HasSubstr;

Stamp at(double s) { return Stamp(std::chrono::microseconds(std::llround(s * 1e6))); }

Image8 gradient(int w, int h) {
  Image8 img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at(x, y) = static_cast<std::uint8_t>((x * 7 + y * 3) % 256);
  return img;
}

TEST(MissionLog, EveryInputWrittenReadsBackAsItWas) {
  const std::string path = test::temp_path("every_input.mcap");
  const std::string png = encode_png(gradient(32, 24));
  const std::string jpeg = encode_jpeg(gradient(64, 64), 80);
  {
    MissionLogWriter w(path);
    w.attach_robot(R"({"name":"r"})");
    w.attach_map(R"({"type":"FeatureCollection","features":[]})");
    // Arrival after capture, by a different delay for each kind.
    for (int k = 0; k < 50; ++k) {
      const double t = 1.0 + k * 0.02;
      w.write(at(t + 0.001), WheelReading{at(t), k * 0.01, k * 0.011});
      w.write(at(t + 0.002), TruthPose{at(t), Pose2(k * 0.01, -0.5, 0.01 * k - 0.2)});
    }
    w.write_image(at(1.2), ImageFrame{at(1.15), "ceiling_camera", "png", png});
    w.write_image(at(1.5), ImageFrame{at(1.3), "omni_camera", "jpeg", jpeg});
    w.write(at(1.4), MissionEvent{at(1.4), EventKind::kidnap, "carried to C3"});
    w.write(at(1.41), MissionEvent{at(1.41), "door_opened", "another tool's word"});
    w.write(at(1.0), CommandMessage{at(1.0), "follow C1 then turn left at J1"});
    w.close();
  }
  const MissionLog log = read_mission_log(path);
  std::filesystem::remove(path);
  EXPECT_EQ(log.skipped_messages, 0u);
  EXPECT_FALSE(log.report.truncated);
  EXPECT_FALSE(log.ros2_bag);
  ASSERT_EQ(log.wheels.size(), 50u);
  for (int k = 0; k < 50; ++k) {
    const double t = 1.0 + k * 0.02;
    EXPECT_EQ(log.wheels[k].value.stamp, at(t));
    EXPECT_EQ(log.wheels[k].log_time, at(t + 0.001));
    EXPECT_EQ(log.wheels[k].value.left, k * 0.01);  // exactly: JSON numbers round-trip
    EXPECT_EQ(log.wheels[k].value.right, k * 0.011);
    EXPECT_EQ(log.truth[k].log_time, at(t + 0.002));
    EXPECT_NEAR(log.truth[k].value.pose.yaw(), 0.01 * k - 0.2, 1e-12);
    EXPECT_EQ(log.truth[k].value.pose.y(), -0.5);
  }
  ASSERT_EQ(log.ceiling_images.size(), 1u);
  EXPECT_EQ(log.ceiling_images[0].value.data, png);  // the encoded bytes, untouched
  EXPECT_EQ(log.ceiling_images[0].value.format, "png");
  EXPECT_EQ(log.ceiling_images[0].value.stamp, at(1.15));
  EXPECT_EQ(log.ceiling_images[0].log_time, at(1.2));
  ASSERT_EQ(log.omni_images.size(), 1u);
  EXPECT_EQ(log.omni_images[0].value.format, "jpeg");
  EXPECT_EQ(log.omni_images[0].value.frame_id, "omni_camera");
  EXPECT_EQ(decode_image(log.omni_images[0].value.data, "omni").width, 64);
  ASSERT_EQ(log.events.size(), 2u);
  EXPECT_EQ(log.events[0].value.type(), EventKind::kidnap);
  EXPECT_EQ(log.events[0].value.detail, "carried to C3");
  EXPECT_EQ(log.events[1].value.kind, "door_opened");
  EXPECT_EQ(log.events[1].value.type(), EventKind::other);
  ASSERT_EQ(log.commands.size(), 1u);
  EXPECT_EQ(log.commands[0].value.text, "follow C1 then turn left at J1");
  EXPECT_EQ(log.robot_json, R"({"name":"r"})");
  EXPECT_EQ(log.map_geojson, R"({"type":"FeatureCollection","features":[]})");
}

// A log whose messages are written by hand on lampnav's channels, some of them damaged.
std::string damaged_log() {
  const std::string path = test::temp_path("damaged.mcap");
  McapWriter w(path);
  const auto s = w.add_schema("lampnav.Any", "jsonschema", R"({"type":"object"})");
  const auto wheels = w.add_channel(s, topics::kWheels, "json");
  const auto ceiling = w.add_channel(s, topics::kCeilingImage, "json");
  const auto extra = w.add_channel(s, "/someone_elses/topic", "json");
  auto wheel = [](int k) {
    return R"({"timestamp":{"sec":1,"nsec":)" + std::to_string(k * 1000000) +
           R"(},"left":0.5,"right":0.25})";
  };
  const std::uint64_t t0 = 1'000'000'000;
  w.write(wheels, t0, t0, wheel(0));                                    // sequence 0
  w.write(wheels, t0 + 1, t0, R"({"timestamp":{"sec":1,"nsec":1}})");   // 1: no "left"
  w.write(wheels, t0 + 2, t0, wheel(2));                                // 2
  w.write(wheels, t0 + 3, t0, R"({"timestamp":{"sec":1,"nsec":-4},)");  // 3: cut JSON
  w.write(wheels, t0 + 4, t0, R"({"timestamp":{"sec":1,"nsec":1},"left":"far","right":0})");
  w.write(ceiling, t0 + 5, t0,
          R"({"timestamp":{"sec":1,"nsec":0},"frame_id":"ceiling_camera","format":"png",)"
          R"("data":"iVBO*w=="})");  // 0: not base64
  w.write(ceiling, t0 + 6, t0,
          R"({"timestamp":{"sec":1,"nsec":0},"frame_id":"ceiling_camera","format":"gif",)"
          R"("data":"AAAA"})");  // 1: a format the spec does not have
  w.write(extra, t0 + 7, t0, "not even JSON: not ours, left alone");
  w.close();
  std::string bytes = test::slurp(path);
  std::filesystem::remove(path);
  return bytes;
}

TEST(MissionLog, DamagedMessagesAreSkippedCountedAndNamedAndTheRestKept) {
  // The sequence numbers count per channel as the writer gave them.
  const MissionLog log = parse_mission_log(damaged_log(), "damaged.mcap");
  ASSERT_EQ(log.wheels.size(), 2u);
  EXPECT_EQ(log.wheels[1].value.stamp, Stamp(std::chrono::milliseconds(1002)));
  EXPECT_TRUE(log.ceiling_images.empty());
  EXPECT_EQ(log.skipped_messages, 5u);
  ASSERT_EQ(log.problems.size(), 5u);
  auto problem_about = [&](const std::string& start) -> std::string {
    for (const auto& p : log.problems)
      if (p.rfind(start, 0) == 0) return p;
    return "none starts with " + start;
  };
  EXPECT_THAT(problem_about("/wheels message 1:"), HasSubstr("missing \"left\""));
  EXPECT_THAT(problem_about("/wheels message 3:"), HasSubstr("bad JSON"));
  EXPECT_THAT(problem_about("/wheels message 4:"), HasSubstr("\"left\" is not a finite number"));
  EXPECT_THAT(problem_about("/ceiling_camera/image message 0:"), HasSubstr("not base64"));
  EXPECT_THAT(problem_about("/ceiling_camera/image message 1:"), HasSubstr("\"gif\""));
  for (const auto& p : log.problems) EXPECT_THAT(p, HasSubstr("(skipped)"));
}

TEST(MissionLog, WhatIsNotMcapIsAnInputErrorNamingTheFile) {
  try {
    parse_mission_log("{\"this\": \"is JSON\"}", "drive.json");
    ADD_FAILURE() << "read JSON as a mission log";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("drive.json"));
  }
  try {
    read_mission_log(test::temp_path("does_not_exist.mcap"));
    ADD_FAILURE() << "read a file that does not exist";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("does_not_exist.mcap"));
  }
}

TEST(InputsInArrivalOrder, ByArrivalWithTheWheelsFirstAtTheSameInstant) {
  MissionLog log;
  for (int k = 0; k < 3; ++k) log.wheels.push_back({at(k * 0.1), {at(k * 0.1), 0, 0}});
  // A frame arriving with the second wheel reading, captured before it; an omni frame arriving
  // before a ceiling frame captured earlier (arrival decides, not capture).
  log.ceiling_images.push_back({at(0.1), {at(0.02), "ceiling_camera", "png", ""}});
  log.ceiling_images.push_back({at(0.25), {at(0.05), "ceiling_camera", "png", ""}});
  log.omni_images.push_back({at(0.2), {at(0.15), "omni_camera", "png", ""}});
  using K = LogInput::Kind;
  auto kinds = [](const std::vector<LogInput>& in) {
    std::vector<std::pair<K, std::size_t>> out;
    for (const auto& i : in) out.emplace_back(i.kind, i.index);
    return out;
  };
  const std::vector<std::pair<K, std::size_t>> all = {{K::wheels, 0},  {K::wheels, 1},
                                                      {K::ceiling, 0}, {K::wheels, 2},
                                                      {K::omni, 0},    {K::ceiling, 1}};
  EXPECT_EQ(kinds(inputs_in_arrival_order(log)), all);
  const std::vector<std::pair<K, std::size_t>> no_omni = {
      {K::wheels, 0}, {K::wheels, 1}, {K::ceiling, 0}, {K::wheels, 2}, {K::ceiling, 1}};
  EXPECT_EQ(kinds(inputs_in_arrival_order(log, true, false)), no_omni);
  EXPECT_EQ(inputs_in_arrival_order(log, false, false).size(), 3u);
}

TEST(TruthTrack, InterpolatesBetweenSamplesButNeverAcrossAKidnap) {
  std::vector<Logged<TruthPose>> samples;
  // Out of order on purpose: the track sorts by capture time.
  samples.push_back({at(2.0), {at(2.0), Pose2(1.0, 0.0, M_PI - 0.1)}});
  samples.push_back({at(1.0), {at(1.0), Pose2(0.0, 0.0, 0.0)}});
  samples.push_back({at(1.5), {at(1.5), Pose2(0.5, 0.0, M_PI - 0.2)}});
  samples.push_back({at(2.5), {at(2.5), Pose2(1.0, 0.0, -M_PI + 0.1)}});
  samples.push_back({at(3.0), {at(3.0), Pose2(9.0, 4.0, 0.0)}});  // carried away
  const TruthTrack truth(samples);
  EXPECT_EQ(truth.samples().front().value.stamp, at(1.0));
  EXPECT_NEAR(truth.at(at(1.25)).x(), 0.25, 1e-12);
  EXPECT_NEAR(truth.at(at(1.75)).x(), 0.75, 1e-12);
  // Yaw takes the short way across +-pi.
  EXPECT_NEAR(std::fabs(truth.at(at(2.25)).yaw()), M_PI, 1e-9);
  // Across the jump: the last pose before it, never a point between the two places.
  EXPECT_EQ(truth.at(at(2.9)).x(), 1.0);
  EXPECT_EQ(truth.at(at(3.0)).x(), 9.0);
  // Outside the samples: the nearest end.
  EXPECT_EQ(truth.at(at(0.0)).x(), 0.0);
  EXPECT_EQ(truth.at(at(10.0)).y(), 4.0);
  EXPECT_TRUE(TruthTrack({}).empty());
}

TEST(Base64, RoundTripsEveryByteAndNamesABadCharacter) {
  std::string bytes;
  for (int i = 0; i < 256; ++i) bytes.push_back(static_cast<char>(i));
  for (std::size_t n : {0, 1, 2, 3, 4, 255, 256}) {
    const std::string part = bytes.substr(0, n);
    const std::string text = base64_encode(part);
    EXPECT_EQ(text.size() % 4, 0u);
    EXPECT_EQ(base64_decode(text), part) << n;
  }
  EXPECT_EQ(base64_encode("Man"), "TWFu");
  EXPECT_EQ(base64_encode("Ma"), "TWE=");
  try {
    base64_decode("TW*u");
    ADD_FAILURE() << "decoded a '*'";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("'*' at 2"));
  }
}

}  // namespace
}  // namespace lampnav::io
