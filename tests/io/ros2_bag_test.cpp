// ROS 2 bags in MCAP: CDR decoding against bytes written by hand from the published encoding
// (both byte orders, alignment, strings, sequences), the message types lampnav reads, which topic
// is which camera, and a clear word for what cannot be read.

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "cdr_writer.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/io/mcap.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav_test.hpp"

namespace lampnav::io {
namespace {

using test::CdrWriter;
using ::testing::HasSubstr;

// A bag: topics (name, type) and messages (topic index, log time ns, CDR bytes).
struct Bag {
  std::vector<std::pair<std::string, std::string>> topics;
  struct Message {
    int topic;
    std::uint64_t log_time;
    std::string data;
  };
  std::vector<Message> messages;
  std::string write(const std::string& name) const {
    const std::string path = test::temp_path(name);
    McapWriter w(path, {"ros2"});
    std::vector<std::uint16_t> channels;
    for (const auto& [topic, type] : topics) {
      const auto s = w.add_schema(type, "ros2msg", "# " + type + "\n");
      channels.push_back(w.add_channel(s, topic, "cdr"));
    }
    for (const auto& m : messages) w.write(channels[m.topic], m.log_time, m.log_time, m.data);
    w.close();
    return path;
  }
};

Image8 gradient(int w, int h) {
  Image8 img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.pixels[y * w + x] = static_cast<std::uint8_t>((x * 7 + y * 3) % 256);
  return img;
}

// sensor_msgs/msg/Image with `encoding`, each grey pixel written as that encoding holds it, rows
// padded to `step`.
std::string raw_image_cdr(const Image8& g, const std::string& encoding, std::uint32_t step,
                          bool little, bool big_endian_pixels = false) {
  const int channels = encoding == "mono8" || encoding == "mono16" ? 1
                       : encoding == "bgra8"                       ? 4
                                                                   : 3;
  const int depth = encoding == "mono16" ? 2 : 1;
  std::string data(std::size_t(step) * g.height, '\x55');
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      const std::uint8_t v = g.pixels[y * g.width + x];
      char* p = &data[std::size_t(y) * step + std::size_t(x) * channels * depth];
      if (depth == 2) {
        const std::uint16_t w16 = static_cast<std::uint16_t>(v * 257);
        p[big_endian_pixels ? 0 : 1] = static_cast<char>(w16 >> 8);
        p[big_endian_pixels ? 1 : 0] = static_cast<char>(w16 & 0xFF);
      } else {
        for (int c = 0; c < std::min(channels, 3); ++c) p[c] = static_cast<char>(v);
        if (channels == 4) p[3] = '\xFF';
      }
    }
  return CdrWriter(little)
      .header(5'000'000'000, "cam")
      .u32(static_cast<std::uint32_t>(g.height))
      .u32(static_cast<std::uint32_t>(g.width))
      .string(encoding)
      .u8(big_endian_pixels ? 1 : 0)
      .u32(step)
      .bytes(data)
      .data();
}

TEST(Ros2Bag, ImagesOdometryAndCalibrationInBothByteOrders) {
  const Image8 g = gradient(37, 21);
  const std::string png = encode_png(g);
  Bag bag;
  bag.topics = {{"/ceiling_camera/image/compressed", "sensor_msgs/msg/CompressedImage"},
                {"/omni/image_raw", "sensor_msgs/msg/Image"},
                {"/odom", "nav_msgs/msg/Odometry"},
                {"/omni/camera_info", "sensor_msgs/msg/CameraInfo"}};
  bag.messages.push_back(
      {0, 2'100'000'000, test::compressed_image_cdr(2'000'000'000, "ceiling", "png", png, true)});
  bag.messages.push_back(
      {0, 2'200'000'000, test::compressed_image_cdr(2'100'000'000, "ceiling", "png", png, false)});
  bag.messages.push_back({1, 5'100'000'000, raw_image_cdr(g, "mono8", 40, true)});
  bag.messages.push_back({1, 5'200'000'000, raw_image_cdr(g, "bgr8", 37 * 3 + 5, false)});
  bag.messages.push_back({1, 5'300'000'000, raw_image_cdr(g, "mono16", 80, true, true)});
  bag.messages.push_back({1, 5'400'000'000, raw_image_cdr(g, "bgra8", 37 * 4, true)});
  bag.messages.push_back({2, 1'010'000'000, test::odometry_cdr(1'000'000'000, 1.0, 2.0, 0.3)});
  bag.messages.push_back(
      {2, 1'030'000'000, test::odometry_cdr(1'020'000'000, 1.5, 2.25, -3.0, false)});
  CdrWriter info(true);
  info.header(1'000'000'000, "omni").u32(480).u32(640).string("equidistant");
  info.f64s({0.1, -0.02, 0.003, 0.0004});
  for (int k = 0; k < 9; ++k) info.f64(k + 1);
  for (int k = 0; k < 9; ++k) info.f64(k == 0 || k == 4 || k == 8);
  for (int k = 0; k < 12; ++k) info.f64(10 + k);
  info.u32(0).u32(0).u32(0).u32(0).u32(0).u32(0).u8(0);
  bag.messages.push_back({3, 1'000'000'000, info.data()});
  const std::string path = bag.write("all.mcap");
  const MissionLog log = read_mission_log(path);
  std::filesystem::remove(path);

  EXPECT_TRUE(log.ros2_bag);
  EXPECT_EQ(log.skipped_messages, 0u) << (log.problems.empty() ? "" : log.problems.front());
  ASSERT_EQ(log.ceiling_images.size(), 2u);
  EXPECT_EQ(log.ceiling_images[0].value.stamp, stamp_from_nanoseconds(2'000'000'000));
  EXPECT_EQ(log.ceiling_images[0].log_time, stamp_from_nanoseconds(2'100'000'000));
  EXPECT_EQ(log.ceiling_images[1].value.format, "png");
  EXPECT_EQ(log.ceiling_images[1].value.data, png);
  ASSERT_EQ(log.omni_images.size(), 4u);
  for (const auto& f : log.omni_images) {
    const Image8 back = decode_image(f.value.data, "omni");
    EXPECT_EQ(back.width, g.width);
    EXPECT_EQ(back.pixels, g.pixels);
  }
  ASSERT_EQ(log.odometry.size(), 2u);
  EXPECT_NEAR(log.odometry[0].value.pose.x(), 1.0, 1e-12);
  EXPECT_NEAR(log.odometry[0].value.pose.yaw(), 0.3, 1e-12);
  EXPECT_NEAR(log.odometry[1].value.pose.y(), 2.25, 1e-12);
  EXPECT_NEAR(log.odometry[1].value.pose.yaw(), -3.0, 1e-12);
  ASSERT_EQ(log.camera_info.count("/omni/camera_info"), 1u);
  const CameraInfo& ci = log.camera_info.at("/omni/camera_info");
  EXPECT_EQ(ci.width, 640);
  EXPECT_EQ(ci.height, 480);
  EXPECT_EQ(ci.distortion_model, "equidistant");
  EXPECT_EQ(ci.d.size(), 4u);
  EXPECT_EQ(ci.k[8], 9.0);
  EXPECT_EQ(ci.p[11], 21.0);
  // How the topics were taken is said.
  std::string notes;
  for (const auto& n : log.notes) notes += n + "\n";
  EXPECT_THAT(notes, HasSubstr("/ceiling_camera/image/compressed"));
  EXPECT_THAT(notes, HasSubstr("/omni/image_raw"));
  EXPECT_THAT(notes, HasSubstr("/odom"));
}

// A differential drive's odometry, split back into the travel of its two wheels.
TEST(Ros2Bag, OdometryBecomesWheelTravel) {
  MissionLog log;
  const double b = 0.2;
  Pose2 p(3, -1, 0.5);
  double left = 0, right = 0;
  std::vector<std::pair<double, double>> expected;
  for (int k = 0; k < 50; ++k) {
    log.odometry.push_back(
        {stamp_from_nanoseconds(k * 20'000'000), {stamp_from_nanoseconds(k * 20'000'000), p}});
    expected.push_back({left, right});
    const double dl = 0.01 + 0.002 * std::sin(k), dr = 0.012 - 0.001 * k / 50.0;
    left += dl;
    right += dr;
    const double ds = 0.5 * (dl + dr), dyaw = (dr - dl) / (2 * b);
    // The midpoint rule, as ROS's diff_drive_controller integrates.
    p = Pose2(p.x() + ds * std::cos(p.yaw() + dyaw / 2), p.y() + ds * std::sin(p.yaw() + dyaw / 2),
              wrap_angle(p.yaw() + dyaw));
  }
  wheels_from_odometry(log, b);
  ASSERT_EQ(log.wheels.size(), log.odometry.size());
  for (std::size_t k = 0; k < log.wheels.size(); ++k) {
    EXPECT_NEAR(log.wheels[k].value.left, expected[k].first, 1e-9) << k;
    EXPECT_NEAR(log.wheels[k].value.right, expected[k].second, 1e-9) << k;
  }
  // A log with wheel readings of its own keeps them.
  const auto before = log.wheels;
  wheels_from_odometry(log, 0.3);
  EXPECT_EQ(log.wheels.size(), before.size());
}

// sensor_msgs/msg/JointState with these joints at these angles (rad).
std::string joint_state_cdr(std::int64_t stamp_ns, const std::vector<std::string>& names,
                            const std::vector<double>& position) {
  CdrWriter w;
  w.header(stamp_ns, "");
  w.u32(static_cast<std::uint32_t>(names.size()));
  for (const auto& n : names) w.string(n);
  w.f64s(position).f64s({}).f64s({});
  return w.data();
}

// Without odometry, the wheel joints: found by name, turned into travel by the wheel radius.
TEST(Ros2Bag, WheelJointsBecomeWheelTravel) {
  Bag bag;
  bag.topics = {{"/joint_states", "sensor_msgs/msg/JointState"}};
  const std::vector<std::string> names = {"caster_left", "left_wheel_joint", "right_wheel_joint"};
  for (int k = 0; k < 20; ++k)
    bag.messages.push_back({0, 1'000'000'000ULL + k * 20'000'000ULL,
                            joint_state_cdr(1'000'000'000LL + k * 20'000'000LL, names,
                                            {0.3, 2.0 + 0.1 * k, -1.0 + 0.12 * k})});
  bag.messages.push_back(
      {0, 2'000'000'000, joint_state_cdr(1'900'000'000, {"left_a", "left_b", "right"}, {1, 2, 3})});
  const std::string path = bag.write("joints.mcap");
  MissionLog log = read_mission_log(path);
  std::filesystem::remove(path);
  ASSERT_EQ(log.wheel_joints.size(), 20u);
  EXPECT_EQ(log.skipped_messages, 1u);
  ASSERT_FALSE(log.problems.empty());
  EXPECT_THAT(log.problems.front(), HasSubstr("no single left wheel joint among: left_a, left_b"));
  std::string notes;
  for (const auto& n : log.notes) notes += n + "\n";
  EXPECT_THAT(notes, HasSubstr("wheel joints of /joint_states"));
  wheels_from_joints(log, 0.1);
  ASSERT_EQ(log.wheels.size(), 20u);
  EXPECT_NEAR(log.wheels.back().value.left, 0.1 * 0.1 * 19, 1e-12);
  EXPECT_NEAR(log.wheels.back().value.right, 0.1 * 0.12 * 19, 1e-12);
}

TEST(Ros2Bag, TopicsNamedOrGuessedOrRefusedWithTheList) {
  const std::string png = encode_png(gradient(8, 8));
  Bag bag;
  bag.topics = {{"/cam0/image", "sensor_msgs/msg/CompressedImage"},
                {"/cam1/image", "sensor_msgs/msg/CompressedImage"},
                {"/wheel_odom", "nav_msgs/msg/Odometry"},
                {"/fused_odom", "nav_msgs/msg/Odometry"}};
  bag.messages.push_back({0, 1'000'000'000, test::compressed_image_cdr(1, "c", "png", png)});
  bag.messages.push_back({1, 1'000'000'000, test::compressed_image_cdr(1, "c", "png", png)});
  bag.messages.push_back({2, 1'000'000'000, test::odometry_cdr(1, 0, 0, 0)});
  bag.messages.push_back({3, 1'000'000'000, test::odometry_cdr(1, 0, 0, 0)});
  const std::string path = bag.write("names.mcap");
  // Neither the cameras nor the odometry can be told apart: the message lists every topic.
  try {
    read_mission_log(path);
    ADD_FAILURE() << "read a bag whose topics it cannot tell apart";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, path);
    EXPECT_THAT(e.what(), HasSubstr("--odometry-topic"));
    EXPECT_THAT(e.what(), HasSubstr("/cam1/image (sensor_msgs/CompressedImage, 1 messages)"));
  }
  BagTopics t;
  t.odometry = "/wheel_odom";
  try {
    read_mission_log(path, t);
    ADD_FAILURE() << "read images without knowing which camera they are";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--ceiling-topic"));
  }
  t.ceiling_image = "/cam1/image";
  t.omni_image = "/cam0/image";
  const MissionLog log = read_mission_log(path, t);
  EXPECT_EQ(log.ceiling_images.size(), 1u);
  EXPECT_EQ(log.omni_images.size(), 1u);
  EXPECT_EQ(log.odometry.size(), 1u);
  // A named topic that is not there, or not an image.
  t.omni_image = "/cam2/image";
  EXPECT_THROW(read_mission_log(path, t), InputError);
  t.omni_image = "/fused_odom";
  try {
    read_mission_log(path, t);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("\"/fused_odom\" is a nav_msgs/Odometry"));
  }
  std::filesystem::remove(path);
}

// What cannot be read is skipped and said, with the topic, the message and the field; the rest is
// kept.
TEST(Ros2Bag, DamagedMessagesAreSkippedNamingTheField) {
  const std::string png = encode_png(gradient(8, 8));
  Bag bag;
  bag.topics = {{"/ceiling/image", "sensor_msgs/msg/CompressedImage"},
                {"/omni/image", "sensor_msgs/msg/Image"},
                {"/odom", "nav_msgs/msg/Odometry"}};
  const std::string good = test::compressed_image_cdr(1'000'000'000, "c", "png", png);
  bag.messages.push_back({0, 1'000'000'000, good});
  bag.messages.push_back({0, 1'100'000'000, good.substr(0, good.size() - 10)});  // cut short
  bag.messages.push_back({0, 1'200'000'000, test::compressed_image_cdr(1, "c", "png", "GIF89a")});
  std::string wrong_header = good;
  wrong_header[1] = 7;
  bag.messages.push_back({0, 1'300'000'000, wrong_header});
  const Image8 g = gradient(4, 4);
  bag.messages.push_back({1, 1'000'000'000, raw_image_cdr(g, "mono8", 3, true)});  // step < row
  bag.messages.push_back({1, 1'000'000'000,
                          CdrWriter()
                              .header(1, "o")
                              .u32(4)
                              .u32(4)
                              .string("32FC1")
                              .u8(0)
                              .u32(8)
                              .bytes(std::string(32, 'x'))
                              .data()});
  std::string odo = test::odometry_cdr(1, 0, 0, 0);
  bag.messages.push_back({2, 1'000'000'000, odo.substr(0, 60)});
  // A sequence count far beyond the bytes left.
  bag.messages.push_back({1, 1'000'000'000,
                          CdrWriter()
                              .header(1, "o")
                              .u32(4)
                              .u32(4)
                              .string("mono8")
                              .u8(0)
                              .u32(4)
                              .u32(0x7FFFFFFF)
                              .data()});
  const std::string path = bag.write("damaged.mcap");
  const MissionLog log = read_mission_log(path);
  std::filesystem::remove(path);
  EXPECT_EQ(log.ceiling_images.size(), 1u);
  EXPECT_EQ(log.skipped_messages, 7u);
  std::string all;
  for (const auto& p : log.problems) all += p + "\n";
  EXPECT_THAT(all, HasSubstr("/ceiling/image message 1 (sensor_msgs/CompressedImage): field data"));
  EXPECT_THAT(all, HasSubstr("neither PNG nor JPEG"));
  EXPECT_THAT(all, HasSubstr("encapsulation header"));
  EXPECT_THAT(all, HasSubstr("step 3 is shorter than a row"));
  EXPECT_THAT(all, HasSubstr("encoding \"32FC1\" is not read"));
  EXPECT_THAT(all, HasSubstr("/odom message 0"));
  EXPECT_THAT(all, HasSubstr("sequence of 2147483647 elements"));
}

// Thousands of corrupted messages of every type (bytes flipped, cut short, counts and lengths
// lying) in one bag: each is read or skipped with a reason, nothing else happens (run under the
// sanitizers too).
TEST(Ros2Bag, CorruptedMessagesAreReadOrSkippedNeverMore) {
  const std::string png = encode_png(gradient(6, 5));
  const Image8 g = gradient(6, 5);
  CdrWriter info(true);
  info.header(1, "c").u32(5).u32(6).string("plumb_bob").f64s({0.1, 0.2, 0, 0, 0});
  for (int k = 0; k < 9 + 9 + 12; ++k) info.f64(k);
  const std::vector<std::string> originals = {
      test::compressed_image_cdr(1'000'000'000, "c", "png", png),
      raw_image_cdr(g, "bgr8", 6 * 3 + 2, false), test::odometry_cdr(1'000'000'000, 1, 2, 0.5),
      joint_state_cdr(1'000'000'000, {"left_wheel", "right_wheel"}, {1.0, 2.0}), info.data()};
  Bag bag;
  bag.topics = {{"/ceiling/image", "sensor_msgs/msg/CompressedImage"},
                {"/omni/image", "sensor_msgs/msg/Image"},
                {"/odom", "nav_msgs/msg/Odometry"},
                {"/joint_states", "sensor_msgs/msg/JointState"},
                {"/camera_info", "sensor_msgs/msg/CameraInfo"}};
  std::mt19937_64 rng(7);
  std::size_t sent = 0;
  for (int i = 0; i < 3000; ++i) {
    const int topic = static_cast<int>(rng() % originals.size());
    std::string m = originals[topic];
    switch (rng() % 4) {
      case 0:  // bytes flipped
        for (int k = 0, n = 1 + static_cast<int>(rng() % 4); k < n; ++k)
          m[rng() % m.size()] ^= static_cast<char>(1 + rng() % 255);
        break;
      case 1:  // cut short
        m.resize(rng() % m.size());
        break;
      case 2: {  // a length or count lying (every aligned 4-byte word is one, perhaps)
        const std::size_t at = 4 + 4 * (rng() % ((m.size() - 4) / 4));
        const std::uint32_t lie =
            rng() % 2 ? 0xFFFFFFFFu : static_cast<std::uint32_t>(rng() % 4096);
        std::memcpy(&m[at], &lie, 4);
        break;
      }
      default:  // garbage appended
        m += std::string(rng() % 16, '\x7f');
    }
    bag.messages.push_back({topic, 1'000'000'000ULL + static_cast<std::uint64_t>(i), m});
    ++sent;
  }
  const std::string path = bag.write("corrupt.mcap");
  const MissionLog log = read_mission_log(path);
  std::filesystem::remove(path);
  const std::size_t read = log.ceiling_images.size() + log.omni_images.size() +
                           log.odometry.size() + log.wheel_joints.size();
  // Camera infos are kept by topic (the last one), so they are counted by what was skipped.
  EXPECT_LE(read + log.skipped_messages, sent);
  EXPECT_GT(log.skipped_messages, 500u);
  EXPECT_EQ(log.problems.size(), log.skipped_messages);
  for (const auto& p : log.problems) EXPECT_THAT(p, HasSubstr("(skipped)"));
}

// tf2_msgs/msg/TFMessage of (parent, child, xyz, quaternion x y z w).
struct Tf {
  std::string parent, child;
  Eigen::Vector3d xyz;
  Eigen::Quaterniond q;
};
std::string tf_cdr(const std::vector<Tf>& tfs) {
  test::CdrWriter w;
  w.u32(static_cast<std::uint32_t>(tfs.size()));
  for (const auto& t : tfs) {
    w.header(0, t.parent).string(t.child);
    w.f64(t.xyz.x()).f64(t.xyz.y()).f64(t.xyz.z());
    w.f64(t.q.x()).f64(t.q.y()).f64(t.q.z()).f64(t.q.w());
  }
  return w.data();
}

Eigen::Quaterniond about(const Eigen::Vector3d& axis, double deg) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(deg * M_PI / 180, axis));
}

TEST(Ros2Bag, CameraMountsFromTheBagsTransforms) {
  Bag bag;
  bag.topics = {{"/tf_static", "tf2_msgs/msg/TFMessage"}, {"/tf", "tf2_msgs/msg/TFMessage"}};
  const Eigen::Quaterniond none = Eigen::Quaterniond::Identity();
  bag.messages.push_back(
      {0, 1,
       tf_cdr({{"base_footprint", "base_link", {0, 0, 0.15}, none},
               {"base_link", "ceiling_mount", {0.1, 0, 0.2}, about(Eigen::Vector3d::UnitZ(), 90)},
               {"ceiling_mount",
                "ceiling_optical",
                {0, 0, 0.05},
                about(Eigen::Vector3d::UnitY(), 5)}})});
  // The robot moving in odom does not change where its cameras are on it.
  for (int k = 0; k < 3; ++k)
    bag.messages.push_back({1, 2 + std::uint64_t(k),
                            tf_cdr({{"odom",
                                     "base_footprint",
                                     {k * 1.0, 0, 0},
                                     about(Eigen::Vector3d::UnitZ(), 10 * k)}})});
  // Refused: not a unit quaternion.
  bag.messages.push_back(
      {0, 9, tf_cdr({{"base_link", "omni_optical", {0, 0, 1}, Eigen::Quaterniond(2, 0, 0, 0)}})});
  const std::string path = bag.write("tf.mcap");
  const MissionLog log = read_mission_log(path);
  std::filesystem::remove(path);
  EXPECT_EQ(log.transforms.size(), 6u);
  EXPECT_EQ(log.skipped_messages, 1u);
  ASSERT_FALSE(log.problems.empty());
  EXPECT_THAT(log.problems.front(), HasSubstr("not a unit quaternion"));

  const auto m = mount_from_tf(log, "ceiling_optical");
  ASSERT_TRUE(m);
  EXPECT_EQ(m->base, "base_footprint");
  EXPECT_TRUE(m->xyz.isApprox(Eigen::Vector3d(0.1, 0, 0.40), 1e-12)) << m->xyz.transpose();
  EXPECT_NEAR(m->rpy.x(), 0, 1e-12);
  EXPECT_NEAR(m->rpy.y(), 5 * M_PI / 180, 1e-12);
  EXPECT_NEAR(m->rpy.z(), M_PI / 2, 1e-12);
  EXPECT_FALSE(mount_from_tf(log, "omni_optical"));  // its only transform was refused
  EXPECT_FALSE(mount_from_tf(log, "nowhere"));

  // Without base_footprint, base_link is the base.
  Bag link;
  link.topics = {{"/tf_static", "tf2_msgs/msg/TFMessage"}};
  link.messages.push_back({0, 1, tf_cdr({{"base_link", "cam", {0.2, 0.1, 1.5}, none}})});
  const std::string p2 = link.write("tf_link.mcap");
  const MissionLog l2 = read_mission_log(p2);
  std::filesystem::remove(p2);
  const auto m2 = mount_from_tf(l2, "cam");
  ASSERT_TRUE(m2);
  EXPECT_EQ(m2->base, "base_link");
  EXPECT_TRUE(m2->xyz.isApprox(Eigen::Vector3d(0.2, 0.1, 1.5), 1e-12));
}

// What cameras send besides grey 8-bit frames comes out grey: a colour JPEG as its luma (libjpeg
// reads only that plane), within 2 grey levels of OpenCV's own colour-to-grey of the same JPEG
// (colours whose decoding does not clip; where it clips, the luma is the truer of the two); a
// 16-bit PNG scaled to 8 bits; a PNG with alpha converted. A grey JPEG gives what OpenCV gives.
TEST(Images, ColourAndDeepImagesComeOutGrey) {
  cv::Mat colour(48, 64, CV_8UC3);
  for (int y = 0; y < colour.rows; ++y)
    for (int x = 0; x < colour.cols; ++x)
      colour.at<cv::Vec3b>(y, x) =
          cv::Vec3b(static_cast<std::uint8_t>(x * 4), static_cast<std::uint8_t>(y * 5),
                    static_cast<std::uint8_t>(250 - 2 * (x + y)));
  auto bytes = [](const cv::Mat& m, const char* ext) {
    std::vector<std::uint8_t> b;
    EXPECT_TRUE(cv::imencode(ext, m, b));
    return std::string(b.begin(), b.end());
  };
  const std::string jpeg = bytes(colour, ".jpg");
  const Image8 grey = decode_image(jpeg, "colour.jpg");
  ASSERT_EQ(grey.width, 64);
  ASSERT_EQ(grey.height, 48);
  cv::Mat theirs;
  cv::cvtColor(cv::imdecode(cv::Mat(1, static_cast<int>(jpeg.size()), CV_8UC1,
                                    const_cast<char*>(jpeg.data())),
                            cv::IMREAD_COLOR),
               theirs, cv::COLOR_BGR2GRAY);
  int worst = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x)
      worst = std::max(worst, std::abs(int(grey.at(x, y)) - int(theirs.at<std::uint8_t>(y, x))));
  EXPECT_LE(worst, 2);

  cv::Mat deep(5, 6, CV_16UC1);
  for (int k = 0; k < 30; ++k)
    deep.at<std::uint16_t>(k / 6, k % 6) = static_cast<std::uint16_t>(k * 2000);
  const Image8 scaled = decode_image(bytes(deep, ".png"), "deep.png");
  ASSERT_EQ(scaled.width, 6);
  for (int k = 0; k < 30; ++k) EXPECT_EQ(scaled.pixels[k], std::lround(k * 2000 / 257.0)) << k;

  cv::Mat alpha(3, 4, CV_8UC4, cv::Scalar(10, 200, 30, 128));
  const Image8 flat = decode_image(bytes(alpha, ".png"), "alpha.png");
  ASSERT_EQ(flat.width, 4);
  cv::Mat expected;
  cv::cvtColor(alpha, expected, cv::COLOR_BGRA2GRAY);
  EXPECT_EQ(flat.at(2, 1), expected.at<std::uint8_t>(1, 2));

  const Image8 g = gradient(33, 17);
  const std::string grey_jpeg = encode_jpeg(g, 75);
  const cv::Mat same = cv::imdecode(
      cv::Mat(1, static_cast<int>(grey_jpeg.size()), CV_8UC1, const_cast<char*>(grey_jpeg.data())),
      cv::IMREAD_UNCHANGED);
  const Image8 ours = decode_image(grey_jpeg, "grey.jpg");
  ASSERT_EQ(same.type(), CV_8UC1);
  EXPECT_EQ(ours.pixels, std::vector<std::uint8_t>(same.datastart, same.dataend));
}

// Images are PNG or JPEG, told by their bytes (OpenCV's other decoders, JPEG 2000 among them, are
// never reached), and a header that asks for gigapixels is refused before anything is allocated.
TEST(Images, OnlyPngAndJpegOfASizeLampnavReads) {
  const Image8 g = gradient(9, 7);
  EXPECT_EQ(decode_image(encode_png(g), "a.png").pixels, g.pixels);
  EXPECT_EQ(decode_image(encode_jpeg(g, 90), "a.jpg").width, 9);
  try {
    decode_image(std::string("\x00\x00\x00\x0cjP  \r\n\x87\n", 12), "a.jp2");
    ADD_FAILURE() << "JPEG 2000 decoded";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("not a PNG or JPEG image"));
  }
  std::string bomb = encode_png(g);
  for (int k = 16; k < 24; ++k) bomb[k] = k % 4 == 1 ? '\x01' : '\x00';  // 65536 x 65536
  try {
    decode_image(bomb, "bomb.png");
    ADD_FAILURE() << "a 4-gigapixel header was decoded";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("65536 x 65536 pixels"));
  }
  // Found by the fuzzer's long run: stray bytes before the frame header hid it from the header
  // scan, and libjpeg, which skips them, decoded 27,000 x 25,714 pixels (12 s, 700 MB). The scan
  // now skips them as libjpeg does.
  const std::string jpeg = encode_jpeg(g, 90);
  const std::size_t sof = jpeg.find("\xFF\xC0");
  ASSERT_NE(sof, std::string::npos);
  std::string hidden = jpeg.substr(0, sof) + std::string("\x1e\x1d\x1a\x1c", 4) + jpeg.substr(sof);
  hidden[sof + 4 + 5] = '\x64';  // height 0x6472
  hidden[sof + 4 + 6] = '\x72';
  hidden[sof + 4 + 7] = '\x69';  // width 0x6976
  hidden[sof + 4 + 8] = '\x76';
  try {
    decode_image(hidden, "hidden.jpg");
    ADD_FAILURE() << "a 694-megapixel frame header behind stray bytes was decoded";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("26998 x 25714 pixels"));
  }
  // The same stray bytes before a frame of the image's own size: read, as libjpeg reads it.
  const std::string stray =
      jpeg.substr(0, sof) + std::string("\x1e\x1d\x1a\x1c", 4) + jpeg.substr(sof);
  EXPECT_EQ(decode_image(stray, "stray.jpg").width, 9);
  // No frame header before the scan: refused before decoding.
  const std::size_t sos = jpeg.find("\xFF\xDA");
  std::string headless = jpeg;
  headless.erase(sof, 2 + ((static_cast<unsigned char>(jpeg[sof + 2]) << 8) |
                           static_cast<unsigned char>(jpeg[sof + 3])));
  ASSERT_LT(sof, sos);
  try {
    decode_image(headless, "headless.jpg");
    ADD_FAILURE() << "a JPEG without a frame header was decoded";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("frame header"));
  }
}

}  // namespace
}  // namespace lampnav::io
