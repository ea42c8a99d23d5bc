// The ROS 2 wire: names as ROS 2 spells them on DDS, and every message the live node reads or
// writes byte for byte as Foxglove's ROS 2 serializer writes it (tests/interop/ros2_messages.mjs),
// and read back by io's decoders.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cdr.hpp"
#include "cdr_writer.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/io/ros2_messages.hpp"
#include "lampnav/ros/participant.hpp"
#include "lampnav_test.hpp"

namespace lampnav::ros {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

TEST(RosWire, NamesAsRos2SpellsThemOnDds) {
  EXPECT_EQ(dds_topic("/lampnav/pose"), "rt/lampnav/pose");
  EXPECT_EQ(dds_topic("/tf"), "rt/tf");
  for (const char* bad : {"", "/", "lampnav/pose", "/lampnav/", "/a//b", "/a b", "/1st", "/a-b"})
    EXPECT_THROW(dds_topic(bad), InputError) << bad;
  EXPECT_EQ(dds_type("sensor_msgs/msg/CompressedImage"),
            "sensor_msgs::msg::dds_::CompressedImage_");
  EXPECT_EQ(dds_type("tf2_msgs/msg/TFMessage"), "tf2_msgs::msg::dds_::TFMessage_");
  EXPECT_THROW(dds_type("Twist"), InputError);
  EXPECT_THROW(dds_type("geometry_msgs/Twist"), InputError);

  ::setenv("ROS_DOMAIN_ID", "42", 1);
  EXPECT_EQ(domain_from_environment(), 42);
  for (const char* bad : {"233", "-1", "4x", "x"}) {
    ::setenv("ROS_DOMAIN_ID", bad, 1);
    EXPECT_THROW(domain_from_environment(), InputError) << bad;
  }
  ::unsetenv("ROS_DOMAIN_ID");
  EXPECT_EQ(domain_from_environment(), 0);
}

std::string hex(const std::string& bytes) {
  static const char* d = "0123456789abcdef";
  std::string s;
  for (unsigned char c : bytes) s += {d[c >> 4], d[c & 15]};
  return s;
}

Json stamp(Stamp t) {
  const std::int64_t ns = to_nanoseconds(t);
  return {{"sec", ns / 1'000'000'000}, {"nanosec", ns % 1'000'000'000}};
}
Json header(Stamp t, const std::string& frame) {
  return {{"stamp", stamp(t)}, {"frame_id", frame}};
}
Json point(double x, double y) { return {{"x", x}, {"y", y}, {"z", 0.0}}; }
Json quaternion(double yaw) {
  return {{"x", 0.0}, {"y", 0.0}, {"z", std::sin(yaw / 2)}, {"w", std::cos(yaw / 2)}};
}
Json pose(const Pose2& p) {
  return {{"position", point(p.x(), p.y())}, {"orientation", quaternion(p.yaw())}};
}

// sensor_msgs/msg/Image, 3 rows of 4 mono8 pixels in rows of 6 bytes, as a driver writes it.
const std::string kMono8Rows(
    "\x01\x02\x03\x04\xAA\xAA\x05\x06\x07\x08\xAA\xAA\x09\x0A\x0B\x0C\xAA\xAA", 18);
std::string raw_mono8(Stamp t) {
  return test::mono8_image_cdr(to_nanoseconds(t), "ceiling_camera", 4, 3, 6, kMono8Rows);
}

TEST(RosWire, EveryMessageIsByteForByteWhatRos2ToolingWrites) {
  const std::string interop = test::source_path("tests/interop");
  ASSERT_TRUE(fs::exists(interop + "/node_modules/@foxglove/rosmsg2-serialization"))
      << "run `make test`, which installs the interop packages";
  const Stamp t = stamp_from_nanoseconds(12'500'000'001);
  const Pose2 p(1.5, -2.25, 0.7), q(-30.125, 4.0, -2.9);
  Eigen::Matrix3d c;
  c << 0.04, 0.001, 0.002, 0.001, 0.05, 0.003, 0.002, 0.003, 0.01;
  Json cases = Json::array();
  auto add = [&](const char* type, const Json& message, const std::string& ours) {
    cases.push_back({{"type", type}, {"message", message}, {"hex", hex(ours)}});
  };

  Json cov = Json::array();
  const int at[6] = {0, 1, -1, -1, -1, 2};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      cov.push_back(at[i] >= 0 && at[j] >= 0 ? c(at[i], at[j]) : i == j ? 1e-9 : 0.0);
  add("geometry_msgs/msg/PoseWithCovarianceStamped",
      {{"header", header(t, "map")}, {"pose", {{"pose", pose(p)}, {"covariance", cov}}}},
      io::ros2::pose_with_covariance_stamped(t, "map", p, c));
  add("geometry_msgs/msg/PoseArray", {{"header", header(t, "map")}, {"poses", {pose(p), pose(q)}}},
      io::ros2::pose_array(t, "map", {p, q}));
  add("geometry_msgs/msg/PoseArray", {{"header", header(t, "map")}, {"poses", Json::array()}},
      io::ros2::pose_array(t, "map", {}));
  add("tf2_msgs/msg/TFMessage",
      {{"transforms",
        {{{"header", header(t, "map")},
          {"child_frame_id", "odom"},
          {"transform",
           {{"translation", point(q.x(), q.y())}, {"rotation", quaternion(q.yaw())}}}}}}},
      io::ros2::tf_message({{t, "map", "odom", q}}));
  // A camera's mount on /tf_static, in three dimensions (the log player sends them so).
  io::FrameTransform mount;
  mount.stamp = t;
  mount.parent = "base_footprint";
  mount.child = "ceiling_optical";
  mount.translation = {0.125, -0.05, 0.375};
  mount.rotation = Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5);
  add("tf2_msgs/msg/TFMessage",
      {{"transforms",
        {{{"header", header(t, "base_footprint")},
          {"child_frame_id", "ceiling_optical"},
          {"transform",
           {{"translation", {{"x", 0.125}, {"y", -0.05}, {"z", 0.375}}},
            {"rotation", {{"x", -0.5}, {"y", 0.5}, {"z", -0.5}, {"w", 0.5}}}}}}}}},
      io::ros2::tf_message(std::vector{mount}));
  add("geometry_msgs/msg/Twist",
      {{"linear", {{"x", 0.35}, {"y", 0.0}, {"z", 0.0}}},
       {"angular", {{"x", 0.0}, {"y", 0.0}, {"z", -0.4}}}},
      io::ros2::twist(0.35, -0.4));
  add("std_msgs/msg/String", {{"data", "turn right at the first corner"}},
      io::ros2::string_message("turn right at the first corner"));
  add("std_msgs/msg/String", {{"data", ""}}, io::ros2::string_message(""));
  const std::string png("\x89PNG\r\n\x1a\n-and-more", 17);
  add("sensor_msgs/msg/CompressedImage",
      {{"header", header(t, "ceiling_camera")}, {"format", "png"}, {"data_hex", hex(png)}},
      io::ros2::compressed_image_message(t, "ceiling_camera", "png", png));
  // What a camera driver writes (the node reads it; lampnav itself never writes one): 3 x 4
  // mono8, each row padded to 6 bytes.
  add("sensor_msgs/msg/Image",
      {{"header", header(t, "ceiling_camera")},
       {"height", 3},
       {"width", 4},
       {"encoding", "mono8"},
       {"is_bigendian", 0},
       {"step", 6},
       {"data_hex", hex(kMono8Rows)}},
      raw_mono8(t));
  Json zeros36 = Json::array();
  for (int k = 0; k < 36; ++k) zeros36.push_back(0.0);
  const Json zero3 = {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}};
  add("nav_msgs/msg/Odometry",
      {{"header", header(t, "odom")},
       {"child_frame_id", "base_link"},
       {"pose", {{"pose", pose(q)}, {"covariance", zeros36}}},
       {"twist", {{"twist", {{"linear", zero3}, {"angular", zero3}}}, {"covariance", zeros36}}}},
      io::ros2::odometry_message(t, "odom", "base_link", q));
  add("sensor_msgs/msg/JointState",
      {{"header", header(t, "")},
       {"name", {"left_wheel_joint", "right_wheel_joint"}},
       {"position", {12.25, -3.5}},
       {"velocity", Json::array()},
       {"effort", Json::array()}},
      io::ros2::joint_state_message(t, {"left_wheel_joint", "right_wheel_joint"}, {12.25, -3.5}));

  io::ros2::DiagnosticStatus camera;
  camera.level = io::ros2::DiagnosticStatus::error;
  camera.name = "lampnav: omni camera";
  camera.message = "no image for 3.0 s";
  camera.hardware_id = "/omni_camera/image_raw/compressed";
  camera.values = {{"received", "120"}, {"rate_hz", "0.0"}};
  io::ros2::DiagnosticStatus localization;
  localization.name = "lampnav: localization";
  localization.message = "tracking";
  add("diagnostic_msgs/msg/DiagnosticArray",
      {{"header", header(t, "")},
       {"status",
        {{{"level", 2},
          {"name", camera.name},
          {"message", camera.message},
          {"hardware_id", camera.hardware_id},
          {"values",
           {{{"key", "received"}, {"value", "120"}}, {{"key", "rate_hz"}, {"value", "0.0"}}}}},
         {{"level", 0},
          {"name", localization.name},
          {"message", "tracking"},
          {"hardware_id", ""},
          {"values", Json::array()}}}}},
      io::ros2::diagnostic_array(t, {camera, localization}));

  const std::string file = test::temp_path("ros2_messages.json");
  std::ofstream(file) << cases.dump();
  int status = -1;
  const std::string out = test::run_command(
      "cd '" + interop + "' && node ros2_messages.mjs '" + file + "' 2>&1", &status);
  fs::remove(file);
  std::cout << out;
  EXPECT_EQ(status, 0) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), static_cast<long>(cases.size()));
}

TEST(RosWire, WhatTheNodeWritesItsDecodersRead) {
  const Stamp t = stamp_from_nanoseconds(3'000'000'007);
  const io::OdometryPose o =
      io::ros2::odometry(io::ros2::odometry_message(t, "odom", "base_link", Pose2(2, -1, 2.5)));
  EXPECT_EQ(o.stamp, t);
  EXPECT_NEAR(o.pose.x(), 2, 1e-15);
  EXPECT_NEAR(o.pose.yaw(), 2.5, 1e-12);
  const io::WheelJoints j = io::ros2::wheel_joints(
      io::ros2::joint_state_message(t, {"caster", "wheel_left_joint", "wheel_right_joint"},
                                    {9, 1.5, 2.5}),
      "", "");
  EXPECT_EQ(j.left, 1.5);
  EXPECT_EQ(j.right, 2.5);
  EXPECT_EQ(io::ros2::string_data(io::ros2::string_message("go")), "go");
  const io::ros2::GreyImage g = io::ros2::raw_image_grey(raw_mono8(t));
  EXPECT_EQ(g.stamp, t);
  ASSERT_EQ(g.image.width, 4);
  ASSERT_EQ(g.image.height, 3);
  EXPECT_EQ(g.image.at(0, 0), 1);
  EXPECT_EQ(g.image.at(3, 2), 12);  // the padding of each row left out
  // Cut short anywhere, a message is refused with the field, never read past its end.
  const std::string full = io::ros2::joint_state_message(t, {"l_wheel", "r_wheel"}, {1, 2});
  for (std::size_t n = 0; n < full.size(); ++n)
    EXPECT_THROW(io::ros2::wheel_joints(full.substr(0, n), "l_wheel", "r_wheel"), io::CdrError)
        << n;
  // A sequence count that lies is refused before anything is allocated.
  std::string lying = io::CdrWriter().header(0, "").u32(0xFFFFFFF0u).take();
  try {
    io::ros2::wheel_joints(lying, "", "");
    ADD_FAILURE() << "a lying count was read";
  } catch (const io::CdrError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("field name"));
  }
}

// geometry_msgs/msg/PoseWithCovarianceStamped read back as written (the encoder is checked byte
// for byte against ROS 2's tooling above); a covariance that is not symmetric positive definite
// over (x, y, yaw), or a message cut short anywhere, is refused naming the field.
TEST(RosWire, PoseEstimatesReadAsWrittenOrRefused) {
  const Stamp t = stamp_from_nanoseconds(42'000'000'001);
  Eigen::Matrix3d c;
  c << 0.3, 0.01, 0.002, 0.01, 0.2, 0.003, 0.002, 0.003, 0.05;
  const std::string full =
      io::ros2::pose_with_covariance_stamped(t, "map", Pose2(-4.5, 8.25, -2.75), c);
  const io::ros2::PoseEstimate e = io::ros2::pose_estimate(full);
  EXPECT_EQ(e.stamp, t);
  EXPECT_EQ(e.frame_id, "map");
  EXPECT_NEAR(e.pose.x(), -4.5, 1e-15);
  EXPECT_NEAR(e.pose.y(), 8.25, 1e-15);
  EXPECT_NEAR(e.pose.yaw(), -2.75, 1e-12);
  EXPECT_EQ(e.covariance, c);
  for (std::size_t n = 0; n < full.size(); ++n)
    EXPECT_THROW(io::ros2::pose_estimate(full.substr(0, n)), io::CdrError) << n;
  Eigen::Matrix3d bad = c;
  bad(2, 2) = -0.05;  // a negative variance
  Eigen::Matrix3d lopsided = c;
  lopsided(0, 1) = 0.2;  // not symmetric
  for (const Eigen::Matrix3d& m : {bad, lopsided, Eigen::Matrix3d::Zero().eval()}) {
    try {
      io::ros2::pose_estimate(io::ros2::pose_with_covariance_stamped(t, "map", Pose2(), m));
      ADD_FAILURE() << "taken:\n" << m;
    } catch (const io::CdrError& err) {
      EXPECT_THAT(err.what(), ::testing::HasSubstr("pose.covariance"));
    }
  }
}

// Wheel travel from odometry and joints, one reading at a time, as bags and the node take them.
TEST(RosWire, WheelTravelFromOdometryAndJoints) {
  io::ros2::OdometryWheels odo(0.2);
  const auto s = [](double sec) { return stamp_from_nanoseconds(std::int64_t(sec * 1e9)); };
  EXPECT_EQ(odo.add({s(1), Pose2(0, 0, 0)})->left, 0.0);
  const auto w = odo.add({s(2), Pose2(1, 0, 0)});
  EXPECT_DOUBLE_EQ(w->left, 1.0);
  EXPECT_DOUBLE_EQ(w->right, 1.0);
  EXPECT_FALSE(odo.add({s(2), Pose2(5, 0, 0)}));  // not later: nothing
  const auto turn = odo.add({s(3), Pose2(1, 0, 0.5)});
  EXPECT_DOUBLE_EQ(turn->right - turn->left, 2 * 0.2 * 0.5);
  io::ros2::JointWheels joints(0.1);
  EXPECT_EQ(joints.add({s(1), 10, 20})->right, 0.0);
  const auto j = joints.add({s(2), 12, 19});
  EXPECT_DOUBLE_EQ(j->left, 0.2);
  EXPECT_DOUBLE_EQ(j->right, -0.1);
}

}  // namespace
}  // namespace lampnav::ros
