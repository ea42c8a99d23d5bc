// The robot behind DDS, in one process with a stand-in for the robot's drivers on the same
// domain: its inputs in, a damaged message refused with the topic and field while the next one
// is taken, wheel speeds out as a Twist, an estimate out as the pose and map -> odom.

#include <atomic>
#include <functional>
#include <mutex>
#include <thread>

#include "cdr.hpp"
#include "cdr_writer.hpp"
#include "lampnav/io/image_encoding.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/io/ros2_messages.hpp"
#include "lampnav/ros/ros_robot.hpp"
#include "lampnav_test.hpp"
#include "ros_test_support.hpp"

namespace lampnav::ros {
namespace {

using ::testing::HasSubstr;

Stamp at(double s) { return stamp_from_nanoseconds(static_cast<std::int64_t>(s * 1e9)); }

// The messages a stand-in subscriber heard on one topic.
struct Heard {
  std::mutex m;
  std::vector<std::string> cdr;
  std::size_t size() {
    std::lock_guard<std::mutex> lock(m);
    return cdr.size();
  }
  std::string at(std::size_t k) {
    std::lock_guard<std::mutex> lock(m);
    return cdr.at(k);
  }
};

// A robot with the ceiling camera alone, on `topic` (raw or compressed), its frames 64 x 48.
RosRobotOptions ceiling_camera_only(const std::string& topic) {
  RosRobotOptions o;
  o.semi_axis = 0.2;
  o.topics.ceiling_image = topic;
  o.topics.omni_image.clear();
  o.ceiling_size = {64, 48};
  return o;
}

// The robot's frames and wheel readings, from next() until `enough` holds or 10 s have passed
// (the robot is stopped then).
struct Taken {
  std::vector<FrameInput> frames;
  std::vector<WheelInput> wheels;
};
Taken take_inputs(RosRobot& robot, const std::function<bool(const Taken&)>& enough) {
  Taken taken;
  std::atomic<bool> done{false};
  std::thread stopper([&] {
    for (int k = 0; k < 200 && !done; ++k)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    robot.stop();
  });
  while (!enough(taken)) {
    auto in = robot.next();
    if (!in) break;
    if (auto* f = std::get_if<FrameInput>(&*in)) taken.frames.push_back(std::move(*f));
    if (auto* w = std::get_if<WheelInput>(&*in)) taken.wheels.push_back(*w);
  }
  done = true;
  stopper.join();
  return taken;
}

// A robot with the ceiling camera alone on compressed images, a stand-in for its drivers on the
// same domain, and the problems the robot reported.
struct CeilingRig {
  int domain = test::test_domain();
  Participant node_side{domain}, drivers{domain};
  RosRobotOptions o = ceiling_camera_only("/ceiling_camera/image_raw/compressed");
  RosRobot robot{node_side, o};
  std::vector<std::string> problems;
  CeilingRig() {
    robot.on_problem = [this](const std::string& p) { problems.push_back(p); };
  }
};

TEST(RosRobot, TakesInputsRefusesDamagedOnesAndPublishes) {
  const int domain = test::test_domain();
  Participant node_side(domain), drivers(domain);
  RosRobotOptions o;
  o.semi_axis = 0.2;
  o.topics.ceiling_image = "/ceiling_camera/image_raw";  // raw sensor_msgs/msg/Image
  o.topics.omni_image.clear();
  RosRobot robot(node_side, o);
  std::vector<std::string> problems;
  robot.on_problem = [&](const std::string& p) { problems.push_back(p); };

  Writer& odom = drivers.writer("/odom", "nav_msgs/msg/Odometry", Qos::sensor_data);
  Writer& camera =
      drivers.writer("/ceiling_camera/image_raw", "sensor_msgs/msg/Image", Qos::sensor_data);
  Writer& command = drivers.writer("/lampnav/command", "std_msgs/msg/String", Qos::state);
  Heard cmd_vel, pose, tf, mode;
  auto listen = [&](const char* topic, const char* type, Qos q, Heard& h) {
    drivers.subscribe(topic, type, q, [&h](Sample&& s) {
      std::lock_guard<std::mutex> lock(h.m);
      h.cdr.push_back(std::move(s.cdr));
    });
  };
  listen("/cmd_vel", "geometry_msgs/msg/Twist", Qos::state, cmd_vel);
  listen("/lampnav/pose", "geometry_msgs/msg/PoseWithCovarianceStamped", Qos::state, pose);
  listen("/tf", "tf2_msgs/msg/TFMessage", Qos::tf, tf);
  listen("/lampnav/mode", "std_msgs/msg/String", Qos::state, mode);
  ASSERT_TRUE(test::wait_for([&] {
    return odom.matched() && camera.matched() && command.matched() &&
           test::readers_matched(node_side,
                                 {"/odom", "/ceiling_camera/image_raw", "/lampnav/command"}) &&
           drivers.publishers_matched("/cmd_vel") && drivers.publishers_matched("/tf") &&
           drivers.publishers_matched("/lampnav/pose") &&
           drivers.publishers_matched("/lampnav/mode");
  })) << "the two participants did not find each other";

  ASSERT_TRUE(odom.write(io::ros2::odometry_message(at(1), "odom", "base_link", Pose2(0, 0, 0))));
  const std::string good = io::ros2::odometry_message(at(2), "odom", "base_link", Pose2(1, 0, 0));
  ASSERT_TRUE(odom.write(good.substr(0, 60)));  // cut short
  ASSERT_TRUE(odom.write(good));
  ASSERT_TRUE(camera.write(test::mono8_image_cdr(
      to_nanoseconds(at(1.5)), "ceiling_camera", 4, 3, 6,
      std::string("\x01\x02\x03\x04\xAA\xAA\x05\x06\x07\x08\xAA\xAA\x09\x0A\x0B\x0C\xAA\xAA",
                  18))));
  ASSERT_TRUE(command.write(io::ros2::string_message("follow the corridor")));

  std::vector<WheelInput> wheels;
  std::vector<FrameInput> frames;
  std::vector<CommandInput> commands;
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::seconds(3));
    robot.stop();
  });
  while (auto in = robot.next()) {
    if (auto* w = std::get_if<WheelInput>(&*in)) wheels.push_back(*w);
    if (auto* f = std::get_if<FrameInput>(&*in)) frames.push_back(*f);
    if (auto* c = std::get_if<CommandInput>(&*in)) commands.push_back(*c);
  }
  stopper.join();

  ASSERT_EQ(wheels.size(), 2u);
  EXPECT_EQ(wheels[0].stamp, at(1));
  EXPECT_EQ(wheels[1].stamp, at(2));
  EXPECT_DOUBLE_EQ(wheels[1].left, 1.0);
  EXPECT_DOUBLE_EQ(wheels[1].right, 1.0);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_THAT(problems[0], HasSubstr("/odom, message 2: field"));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].capture, at(1.5));
  ASSERT_EQ(frames[0].image.width, 4);
  ASSERT_EQ(frames[0].image.height, 3);
  EXPECT_EQ(frames[0].image.at(3, 2), 0x0C);  // the row padding skipped
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0].text, "follow the corridor");
  const NodeCounts n = robot.counts();
  EXPECT_EQ(n.odometry.received, 3u);
  EXPECT_EQ(n.odometry.refused, 1u);
  EXPECT_EQ(n.ceiling.used, 1u);

  // Wheel speeds out: forward 0.4 m/s, turning 0.2 / (2 x 0.2) = 0.5 rad/s.
  robot.set_wheel_speeds(0.3, 0.5);
  ASSERT_TRUE(test::wait_for([&] { return cmd_vel.size() == 1; }));
  const std::string twist_cdr = cmd_vel.at(0);  // the reader keeps a reference
  io::CdrReader twist(twist_cdr);
  EXPECT_DOUBLE_EQ(twist.f64("linear.x"), 0.4);
  twist.f64("linear.y");
  twist.f64("linear.z");
  twist.f64("angular.x");
  twist.f64("angular.y");
  EXPECT_DOUBLE_EQ(twist.f64("angular.z"), 0.5);

  // An estimate at the last wheel reading: the pose, and map -> odom = map_base * odom_base^-1
  // with the odometry's own pose (1, 0, 0) there.
  fusion::LocalizerEstimate e;
  e.stamp = at(2);
  e.pose = Pose2(5, 5, M_PI / 2);
  e.mode = fusion::LocalizerMode::tracking;
  robot.publish(e);
  e.mode = fusion::LocalizerMode::ambiguous;  // not certain: no pose, no transform
  robot.publish(e);
  ASSERT_TRUE(
      test::wait_for([&] { return pose.size() == 1 && tf.size() == 1 && mode.size() == 2; }));
  test::wait_for([&] { return pose.size() > 1; }, 0.3);
  EXPECT_EQ(pose.size(), 1u);
  EXPECT_EQ(io::ros2::string_data(mode.at(1)), "ambiguous");
  const std::string tf_cdr = tf.at(0);
  io::CdrReader t(tf_cdr);
  EXPECT_EQ(t.u32("transforms"), 1u);
  EXPECT_EQ(t.i32("sec"), 2);
  t.u32("nanosec");
  EXPECT_EQ(t.string("frame_id"), "map");
  EXPECT_EQ(t.string("child_frame_id"), "odom");
  const double x = t.f64("x"), y = t.f64("y");
  EXPECT_NEAR(x, 5, 1e-12);  // (5, 5, 90 deg) * (1, 0, 0)^-1 = (5, 4, 90 deg)
  EXPECT_NEAR(y, 4, 1e-12);
  EXPECT_EQ(robot.counts().poses_published, 1u);
}

// The participant outlives the robot (it was made first), and DDS calls the robot's callbacks
// until the participant goes: a robot destroyed while its camera and wheels keep publishing must
// not be called after it is gone. With the callbacks holding the robot, DDS called a destroyed
// robot's and the participant's destruction hung (traced with gdb); the sanitized suite would
// report the use after free.
TEST(RosRobot, GoesWhileItsInputsKeepComing) {
  const int domain = test::test_domain();
  Participant drivers(domain);
  Writer& odom = drivers.writer("/odom", "nav_msgs/msg/Odometry", Qos::sensor_data);
  Writer& camera =
      drivers.writer("/ceiling_camera/image_raw", "sensor_msgs/msg/Image", Qos::sensor_data);
  std::atomic<bool> publishing{true};
  std::thread driver([&] {
    for (int k = 0; publishing; ++k) {
      odom.write(
          io::ros2::odometry_message(at(0.01 * k), "odom", "base_link", Pose2(0.01 * k, 0, 0)));
      camera.write(test::mono8_image_cdr(to_nanoseconds(at(0.01 * k)), "ceiling_camera", 64, 48, 64,
                                         std::string(64 * 48, '\x20')));
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  for (int round = 0; round < 2; ++round) {
    Participant node_side(domain);
    Taken taken;
    {
      RosRobot robot(node_side, ceiling_camera_only("/ceiling_camera/image_raw"));
      taken = take_inputs(
          robot, [](const Taken& t) { return t.frames.size() >= 20 && t.wheels.size() >= 20; });
    }  // gone while the inputs keep coming
    EXPECT_GE(taken.frames.size(), 20u) << "round " << round;
    EXPECT_GE(taken.wheels.size(), 20u) << "round " << round;
    // The participant still hears them for a while.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  publishing = false;
  driver.join();
}

TEST(RosRobot, RefusesOptionsThatCannotWork) {
  Participant p(test::test_domain());
  RosRobotOptions o;
  EXPECT_THROW(RosRobot(p, o), InputError);  // no semi-axis
  o.semi_axis = 0.2;
  o.topics.joint_states = "/joint_states";  // joints without a radius
  EXPECT_THROW(RosRobot(p, o), InputError);
  o.topics.joint_states.clear();
  o.topics.odometry = "odom";  // not a ROS 2 topic name
  EXPECT_THROW(RosRobot(p, o), InputError);
  o.topics.odometry = "/odom";
  o.omni_size = {1024, 0};  // a width without a height
  EXPECT_THROW(RosRobot(p, o), InputError);
  o.omni_size = {-1, -1};
  EXPECT_THROW(RosRobot(p, o), InputError);
  o.omni_size = {9000, 9000};  // more than a frame lampnav decodes
  EXPECT_THROW(RosRobot(p, o), InputError);
  o.omni_size = {};
  o.max_images_waiting = 0;  // every image dropped
  EXPECT_THROW(RosRobot(p, o), InputError);
}

// A camera faster than the node: while nothing is taken, each image past the five waiting drops
// the camera's oldest, so that the node then processes the five newest and no backlog; the wheel
// readings are all kept. (With the queue alone bounding it, all 30 images waited.)
TEST(RosRobot, KeepsTheNewestImagesWhenItFallsBehind) {
  const int domain = test::test_domain();
  Participant node_side(domain), drivers(domain);
  const RosRobotOptions o = ceiling_camera_only("/ceiling_camera/image_raw");
  ASSERT_EQ(o.max_images_waiting, 5u);
  RosRobot robot(node_side, o);
  Writer& odom = drivers.writer("/odom", "nav_msgs/msg/Odometry", Qos::sensor_data);
  Writer& camera =
      drivers.writer(o.topics.ceiling_image, "sensor_msgs/msg/Image", Qos::sensor_data);
  ASSERT_TRUE(test::wait_for([&] {
    return camera.matched() && odom.matched() &&
           test::readers_matched(node_side, {"/odom", o.topics.ceiling_image});
  }));
  const int sent = 30;
  for (int k = 0; k < sent; ++k) {
    ASSERT_TRUE(odom.write(
        io::ros2::odometry_message(at(0.1 * k), "odom", "base_link", Pose2(0.01 * k, 0, 0))));
    ASSERT_TRUE(camera.write(test::mono8_image_cdr(to_nanoseconds(at(0.1 * k)), "ceiling_camera",
                                                   64, 48, 64, std::string(64 * 48, char(k)))));
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(test::wait_for([&] {
    const NodeCounts c = robot.counts();
    return c.ceiling.received == std::size_t(sent) && c.odometry.received == std::size_t(sent);
  })) << "the driver's messages did not all come";
  EXPECT_EQ(robot.counts().ceiling.dropped, std::size_t(sent) - 5);

  const Taken taken = take_inputs(
      robot, [&](const Taken& t) { return t.frames.size() >= 5 && t.wheels.size() >= 30; });
  ASSERT_EQ(taken.frames.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    const int n = sent - 5 + k;
    EXPECT_EQ(taken.frames[k].capture, at(0.1 * n));
    EXPECT_EQ(taken.frames[k].image.pixels[0], std::uint8_t(n)) << "frame " << k;
  }
  EXPECT_EQ(taken.wheels.size(), std::size_t(sent));
  const NodeCounts c = robot.counts();
  EXPECT_EQ(c.ceiling.used, 5u);
  EXPECT_EQ(c.ceiling.dropped, std::size_t(sent) - 5);
  EXPECT_EQ(c.odometry.dropped, 0u);
}

// A node that waits for its cameras' mounts before it starts holds every image that comes until
// it releases them: those go first, all of them, and the bound applies to the images after.
TEST(RosRobot, HoldsEveryImageUntilReleased) {
  const int domain = test::test_domain();
  Participant node_side(domain), drivers(domain);
  RosRobotOptions o = ceiling_camera_only("/ceiling_camera/image_raw");
  o.hold_images = true;
  RosRobot robot(node_side, o);
  Writer& camera =
      drivers.writer(o.topics.ceiling_image, "sensor_msgs/msg/Image", Qos::sensor_data);
  ASSERT_TRUE(test::wait_for([&] {
    return camera.matched() && test::readers_matched(node_side, {o.topics.ceiling_image});
  }));
  auto send = [&](int first, int count) {
    for (int k = first; k < first + count; ++k) {
      ASSERT_TRUE(camera.write(test::mono8_image_cdr(to_nanoseconds(at(0.1 * k)), "ceiling_camera",
                                                     64, 48, 64, std::string(64 * 48, char(k)))));
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ASSERT_TRUE(test::wait_for(
        [&] { return robot.counts().ceiling.received == std::size_t(first + count); }));
  };
  send(0, 20);  // held
  EXPECT_EQ(robot.counts().ceiling.dropped, 0u);
  robot.release_images();
  send(20, 10);  // the newest 5 of these kept
  EXPECT_EQ(robot.counts().ceiling.dropped, 5u);

  const Taken taken = take_inputs(robot, [&](const Taken& t) { return t.frames.size() >= 25; });
  ASSERT_EQ(taken.frames.size(), 25u);
  for (int k = 0; k < 25; ++k) {
    const int n = k < 20 ? k : k + 5;
    EXPECT_EQ(taken.frames[k].image.pixels[0], std::uint8_t(n)) << "frame " << k;
  }
}

// Compressed images, decoded on the camera's own thread after it decoded frames of the camera's
// size at start: each comes out as its bytes decode, in arrival order; a damaged one is reported
// with its topic and number and the next one taken.
TEST(RosRobot, DecodesCompressedImagesOnTheCamerasThread) {
  CeilingRig rig;
  Participant& drivers = rig.drivers;
  const RosRobotOptions& o = rig.o;
  RosRobot& robot = rig.robot;
  std::vector<std::string>& problems = rig.problems;
  Writer& camera =
      drivers.writer(o.topics.ceiling_image, "sensor_msgs/msg/CompressedImage", Qos::sensor_data);
  ASSERT_TRUE(test::wait_for([&] {
    return camera.matched() && test::readers_matched(rig.node_side, {o.topics.ceiling_image});
  }));

  Image8 lamp(64, 48, 12);
  for (int y = 20; y < 28; ++y)
    for (int x = 10; x < 40; ++x) lamp.at(x, y) = 250;
  io::ImageEncoding jpeg, png;
  png.format = io::ImageEncoding::Format::png;
  const std::string jpeg_bytes = io::encode_image(lamp, jpeg);
  const std::string png_bytes = io::encode_image(lamp, png);
  const std::vector<std::string> sent = {
      io::ros2::compressed_image_message(at(1), "ceiling_camera", "jpeg", jpeg_bytes),
      io::ros2::compressed_image_message(at(2), "ceiling_camera", "jpeg", "not an image"),
      io::ros2::compressed_image_message(at(3), "ceiling_camera", "png", png_bytes)};
  for (const std::string& cdr : sent) ASSERT_TRUE(camera.write(cdr));

  const std::vector<FrameInput> frames =
      take_inputs(robot, [](const Taken& t) { return t.frames.size() >= 2; }).frames;
  ASSERT_EQ(frames.size(), 2u) << "the images did not come";
  EXPECT_EQ(frames[0].capture, at(1));
  EXPECT_EQ(frames[1].capture, at(3));
  EXPECT_EQ(frames[0].image.pixels, io::decode_image(jpeg_bytes, "jpeg").pixels);
  EXPECT_EQ(frames[1].image.pixels, lamp.pixels);  // PNG keeps every pixel
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_THAT(problems[0], HasSubstr("/ceiling_camera/image_raw/compressed, message 2"));
  EXPECT_EQ(robot.counts().ceiling.refused, 1u);
}

// An operator's "2D Pose Estimate" on /initialpose, as RViz sends it (the map frame, its default
// covariance), comes out as a pose input at the newest wheel reading's time; one in another frame
// or with a zero covariance is refused naming the topic, the message and the field.
TEST(RosRobot, TakesAnOperatorsPoseEstimate) {
  const int domain = test::test_domain();
  Participant node_side(domain), drivers(domain);
  RosRobotOptions o = ceiling_camera_only("/ceiling_camera/image_raw");
  o.idle_exit_s = 0.5;  // next() ends once the messages are all taken
  RosRobot robot(node_side, o);
  std::vector<std::string> problems;
  robot.on_problem = [&](const std::string& p) { problems.push_back(p); };
  Writer& odom = drivers.writer("/odom", "nav_msgs/msg/Odometry", Qos::sensor_data);
  Writer& estimate =
      drivers.writer("/initialpose", "geometry_msgs/msg/PoseWithCovarianceStamped", Qos::state);
  ASSERT_TRUE(test::wait_for([&] {
    return odom.matched() && estimate.matched() &&
           test::readers_matched(node_side, {"/odom", "/initialpose"});
  }));
  ASSERT_TRUE(odom.write(io::ros2::odometry_message(at(7), "odom", "base_link", Pose2())));
  ASSERT_TRUE(test::wait_for([&] { return robot.counts().odometry.received == 1; }));
  const Eigen::Matrix3d rviz = Eigen::Vector3d(0.25, 0.25, 0.06853891945200942).asDiagonal();
  const Pose2 there(12.5, -3.25, 1.2);
  // RViz stamps with its own clock: not the robot's.
  ASSERT_TRUE(estimate.write(io::ros2::pose_with_covariance_stamped(at(1e6), "map", there, rviz)));
  ASSERT_TRUE(estimate.write(io::ros2::pose_with_covariance_stamped(at(1e6), "odom", there, rviz)));
  ASSERT_TRUE(estimate.write(
      io::ros2::pose_with_covariance_stamped(at(1e6), "map", there, Eigen::Matrix3d::Zero(), 0)));
  ASSERT_TRUE(test::wait_for([&] { return robot.counts().pose_estimates.received == 3; }));
  std::vector<PoseInput> poses;
  std::size_t wheels = 0;
  while (auto in = robot.next()) {
    if (std::get_if<WheelInput>(&*in)) ++wheels;
    if (auto* p = std::get_if<PoseInput>(&*in)) poses.push_back(*p);
  }
  EXPECT_EQ(wheels, 1u);
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_EQ(poses[0].arrival, at(7));
  EXPECT_NEAR(poses[0].pose.x(), 12.5, 1e-12);
  EXPECT_NEAR(poses[0].pose.y(), -3.25, 1e-12);
  EXPECT_NEAR(poses[0].pose.yaw(), 1.2, 1e-12);
  EXPECT_EQ(poses[0].covariance, rviz);
  EXPECT_EQ(robot.counts().pose_estimates.used, 1u);
  EXPECT_EQ(robot.counts().pose_estimates.refused, 2u);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_THAT(problems[0], HasSubstr("/initialpose, message 2"));
  EXPECT_THAT(problems[0], HasSubstr("header.frame_id is 'odom'"));
  EXPECT_THAT(problems[1], HasSubstr("/initialpose, message 3"));
  EXPECT_THAT(problems[1], HasSubstr("pose.covariance"));
}

// The cameras' mounts as a ROS robot publishes them: robot_state_publisher's /tf_static, sent
// before the node was there (transient local), reaches it; a camera's frame is known from its
// first image before anything is taken; a damaged TFMessage is refused naming the topic and the
// message, and the transforms taken before it stay.
TEST(RosRobot, TakesStaticTransformsAndTheCamerasFrame) {
  const int domain = test::test_domain();
  Participant drivers(domain);
  Writer& tf_static = drivers.writer("/tf_static", "tf2_msgs/msg/TFMessage", Qos::tf_static);
  io::FrameTransform base, camera;
  base.parent = "base_footprint";
  base.child = "base_link";
  base.translation = {0, 0, 0.1};
  camera.parent = "base_link";
  camera.child = "ceiling_optical";
  camera.translation = {0.2, 0, 0.3};
  camera.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(tf_static.write(io::ros2::tf_message(std::vector{base, camera})));

  Participant node_side(domain);  // joins after the transforms were sent
  const RosRobotOptions o = ceiling_camera_only("/ceiling_camera/image_raw/compressed");
  RosRobot robot(node_side, o);
  std::vector<std::string> problems;
  robot.on_problem = [&](const std::string& p) { problems.push_back(p); };
  ASSERT_TRUE(test::wait_for([&] { return robot.counts().static_transforms.used == 1; }))
      << "the transforms sent before the node came did not reach it";
  EXPECT_EQ(robot.camera_frame(CameraRole::ceiling), "");

  Writer& image =
      drivers.writer(o.topics.ceiling_image, "sensor_msgs/msg/CompressedImage", Qos::sensor_data);
  ASSERT_TRUE(test::wait_for([&] {
    return image.matched() && test::readers_matched(node_side, {o.topics.ceiling_image});
  }));
  ASSERT_TRUE(image.write(io::ros2::compressed_image_message(at(1), "ceiling_optical", "png",
                                                             "not decoded before it is taken")));
  ASSERT_TRUE(test::wait_for([&] { return !robot.camera_frame(CameraRole::ceiling).empty(); }));
  EXPECT_EQ(robot.camera_frame(CameraRole::ceiling), "ceiling_optical");

  const std::string whole = io::ros2::tf_message(std::vector{camera});
  ASSERT_TRUE(tf_static.write(whole.substr(0, whole.size() - 9)));
  ASSERT_TRUE(test::wait_for([&] { return robot.counts().static_transforms.refused == 1; }));
  // Sent again (a publisher that repeats them): the latest of each frame is kept, no more.
  ASSERT_TRUE(tf_static.write(whole));
  ASSERT_TRUE(test::wait_for([&] { return robot.counts().static_transforms.used == 2; }));
  const std::vector<io::FrameTransform> taken = robot.static_transforms();
  ASSERT_EQ(taken.size(), 2u);
  EXPECT_TRUE(taken[0].is_static);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_THAT(problems[0], HasSubstr("/tf_static, message 2"));
  EXPECT_EQ(taken[1].child, "ceiling_optical");

  const auto mount = io::mount_from_tf(taken, robot.camera_frame(CameraRole::ceiling));
  ASSERT_TRUE(mount.has_value());
  EXPECT_EQ(mount->base, "base_footprint");
  EXPECT_NEAR((mount->xyz - Eigen::Vector3d(0.2, 0, 0.4)).norm(), 0, 1e-12);
  EXPECT_NEAR((mount->rpy - Eigen::Vector3d(0, 0, M_PI / 2)).norm(), 0, 1e-12);
}

// A camera's calibration as its driver publishes it, beside its images (image_transport's
// naming): the newest one kept; a damaged one refused naming the topic and the message.
TEST(RosRobot, TakesEachCamerasCalibrationBesideItsImages) {
  EXPECT_EQ(camera_info_topic("/ceiling_camera/image_raw/compressed"),
            "/ceiling_camera/camera_info");
  EXPECT_EQ(camera_info_topic("/fisheye/image_raw"), "/fisheye/camera_info");
  EXPECT_EQ(camera_info_topic("/image_raw"), "/camera_info");
  CeilingRig rig;
  Participant& drivers = rig.drivers;
  RosRobot& robot = rig.robot;
  std::vector<std::string>& problems = rig.problems;
  Writer& info = drivers.writer("/ceiling_camera/camera_info", "sensor_msgs/msg/CameraInfo",
                                Qos::state);  // a reliable publisher: the reader takes it too
  ASSERT_TRUE(test::wait_for([&] { return info.matched(); }));
  EXPECT_FALSE(robot.camera_info(CameraRole::ceiling));
  for (const double fx : {300.0, 303.0})
    ASSERT_TRUE(
        info.write(test::camera_info_cdr(1'000'000'000, "ceiling_camera", 352, 288, "plumb_bob",
                                         {-0.12, 0.02, 0, 0, 0}, fx, fx, 175.5, 143.5)));
  const std::string whole = test::camera_info_cdr(1'000'000'000, "ceiling_camera", 352, 288,
                                                  "plumb_bob", {}, 300, 300, 175.5, 143.5);
  ASSERT_TRUE(info.write(whole.substr(0, 60)));
  ASSERT_TRUE(test::wait_for([&] { return robot.counts().camera_info.received == 3; }));
  const auto newest = robot.camera_info(CameraRole::ceiling);
  ASSERT_TRUE(newest);
  EXPECT_EQ(newest->k[0], 303.0);
  EXPECT_EQ(newest->width, 352);
  EXPECT_EQ(robot.counts().camera_info.refused, 1u);
  robot.static_transforms();  // reports what was refused
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_THAT(problems[0], HasSubstr("/ceiling_camera/camera_info, message 3"));
}

}  // namespace
}  // namespace lampnav::ros
