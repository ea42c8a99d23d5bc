// lampnav_log_player: plays a recorded mission over DDS as a ROS 2 robot's drivers would (the
// wheel joints as sensor_msgs/msg/JointState, the cameras as sensor_msgs/msg/CompressedImage
// (or, with --raw, as sensor_msgs/msg/Image in mono8 on .../image_raw; --raw-encoding bgr8,
// yuyv or bayer_rggb8 for those),
// header stamps the capture times), at the pace of the log's arrival times (times --rate), and
// writes what the node publishes on /lampnav/pose. For the node's tests and benchmark.
//
//   lampnav_log_player LOG.mcap --domain D [--rate R] [--wheel-radius M] [--poses OUT]
//                      [--diagnostics OUT]
//                      [--wait-s S] [--loops N] [--jpeg QUALITY | --raw | --raw-encoding E]
//                      [--pose-estimate X,Y,YAW]   (sent on /initialpose after the first wheels)
//                      [--tf-static]   (the log's camera mounts on /tf_static, transient local)
//                      [--camera-info SCALE]   (the ceiling camera's CameraInfo, focal x SCALE)
// Prints one line of counts; exit 0, 1 when no node answered, 2 for bad arguments.

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cdr_writer.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/core/image.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/io/ros2_messages.hpp"
#include "lampnav/ros/participant.hpp"
#include "player_options.hpp"

using namespace lampnav;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  test::PlayerOptions o;
  try {
    o = test::parse_player_options(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "lampnav_log_player: " << e.what() << "\n";
    return 2;
  }
  io::MissionLog log = io::read_mission_log(o.log);
  if (o.jpeg_quality > 0)
    for (auto* frames : {&log.ceiling_images, &log.omni_images})
      for (auto& f : *frames) {
        f.value.data = io::encode_jpeg(io::decode_image(f.value.data, o.log), o.jpeg_quality);
        f.value.format = "jpeg";
      }
  ros::ParticipantOptions po;
  po.name = "lampnav_log_player";
  ros::Participant p(o.domain, po);
  ros::Writer& joints =
      p.writer("/joint_states", "sensor_msgs/msg/JointState", ros::Qos::sensor_data);
  const std::string suffix = o.raw ? "" : "/compressed";
  const std::string image_type =
      o.raw ? "sensor_msgs/msg/Image" : "sensor_msgs/msg/CompressedImage";
  ros::Writer& ceiling =
      p.writer("/ceiling_camera/image_raw" + suffix, image_type, ros::Qos::sensor_data);
  ros::Writer& omni =
      p.writer("/omni_camera/image_raw" + suffix, image_type, ros::Qos::sensor_data);
  ros::Writer& estimate =
      p.writer("/initialpose", "geometry_msgs/msg/PoseWithCovarianceStamped", ros::Qos::state);
  if ((o.tf_static || o.camera_info_scale > 0) && !log.robot_json) {
    std::cerr << "lampnav_log_player: --tf-static, --camera-info: the log has no robot.json\n";
    return 2;
  }
  const RobotDescription robot =
      log.robot_json ? parse_robot_description(*log.robot_json, o.log) : RobotDescription{};
  // The ceiling camera's calibration as its driver would publish it, with each image.
  ros::Writer& info_writer =
      p.writer("/ceiling_camera/camera_info", "sensor_msgs/msg/CameraInfo", ros::Qos::sensor_data);
  const CameraDescription* ceiling_camera = robot.find_camera("ceiling_camera");
  if (o.camera_info_scale > 0 &&
      (!ceiling_camera || ceiling_camera->model != CameraModelKind::pinhole)) {
    std::cerr << "lampnav_log_player: --camera-info: the log's ceiling camera is not a pinhole\n";
    return 2;
  }
  const auto info_message = [&](Stamp stamp) {
    const PinholeParameters& k = ceiling_camera->pinhole;
    const double s = o.camera_info_scale;
    return test::camera_info_cdr(to_nanoseconds(stamp), "ceiling_camera",
                                 static_cast<std::uint32_t>(ceiling_camera->width),
                                 static_cast<std::uint32_t>(ceiling_camera->height), "plumb_bob",
                                 std::vector<double>(k.distortion.begin(), k.distortion.end()),
                                 k.fx * s, k.fy * s, k.cx, k.cy);
  };
  if (o.tf_static) {
    // Written now, before the node is matched: DDS keeps it for readers that come later.
    std::vector<io::FrameTransform> mounts;
    for (const auto& c : robot.cameras) {
      io::FrameTransform t;
      t.parent = "base_footprint";
      t.child = c.name;  // the frame the player stamps the camera's images with
      t.translation = c.mount.xyz;
      t.rotation = Eigen::Quaterniond(c.mount.rotation());
      mounts.push_back(t);
    }
    p.writer("/tf_static", "tf2_msgs/msg/TFMessage", ros::Qos::tf_static)
        .write(io::ros2::tf_message(mounts));
  }
  // Raw frames are decoded and laid out in their encoding before playing, as a camera driver
  // hands them over.
  const int bytes = test::raw_bytes_per_pixel(o.raw_encoding);
  struct Raw {
    std::uint32_t width, height;
    std::string rows;
  };
  auto raw = [&](const io::ImageFrame& f) {
    const Image8 g = io::decode_image(f.data, o.log);
    return Raw{static_cast<std::uint32_t>(g.width), static_cast<std::uint32_t>(g.height),
               test::raw_rows(g.pixels, o.raw_encoding)};
  };
  std::vector<Raw> raw_ceiling, raw_omni;
  if (o.raw) {
    for (const auto& f : log.ceiling_images) raw_ceiling.push_back(raw(f.value));
    for (const auto& f : log.omni_images) raw_omni.push_back(raw(f.value));
  }
  const auto image_message = [&](Stamp stamp, const char* frame, const Raw& image) {
    return test::raw_image_cdr(to_nanoseconds(stamp), frame, o.raw_encoding, image.width,
                               image.height, image.width * bytes, image.rows);
  };
  std::mutex m;
  std::vector<std::string> poses;
  std::atomic<long> received{0};
  std::atomic<std::int64_t> last_pose_ns{0};
  p.subscribe("/lampnav/pose", "geometry_msgs/msg/PoseWithCovarianceStamped", ros::Qos::state,
              [&](ros::Sample&& s) {
                std::lock_guard<std::mutex> lock(m);
                poses.push_back(std::move(s.cdr));
                ++received;
                last_pose_ns = s.arrival.time_since_epoch().count();
              });

  std::vector<std::string> diagnostics;
  if (!o.diagnostics.empty())
    p.subscribe("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray", ros::Qos::state,
                [&](ros::Sample&& s) {
                  std::lock_guard<std::mutex> lock(m);
                  diagnostics.push_back(std::move(s.cdr));
                });

  // The node must be there before anything is played (its omni reader too, unless the node is
  // to be told where the robot is: then it may run without the omni camera).
  const auto deadline = Clock::now() + std::chrono::duration<double>(o.wait_s);
  while (joints.matched() == 0 || ceiling.matched() == 0 ||
         (omni.matched() == 0 && !o.pose_estimate) ||
         (o.pose_estimate && estimate.matched() == 0) ||
         p.publishers_matched("/lampnav/pose") == 0) {
    if (Clock::now() > deadline) {
      std::cerr << "lampnav_log_player: no node matched in " << o.wait_s << " s\n";
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));

  const std::vector<io::LogInput> items = io::inputs_in_arrival_order(log);

  long sent[3] = {0, 0, 0}, refused = 0;
  const Duration span = items.empty() ? Duration(0) : items.back().arrival - items.front().arrival;
  const auto t0 = Clock::now();
  for (int loop = 0; loop < o.loops; ++loop) {
    // Each loop shifts the log's times by its span (and 1 s), so stamps keep increasing.
    const Duration shift = (span + std::chrono::seconds(1)) * loop;
    const Stamp first = items.empty() ? Stamp{} : items.front().arrival;
    for (const io::LogInput& it : items) {
      const double due_s = (to_seconds(it.arrival - first) + to_seconds(shift)) / o.rate;
      std::this_thread::sleep_until(
          t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(due_s)));
      bool ok = false;
      const int kind = static_cast<int>(it.kind);  // 0 wheels, 1 ceiling, 2 omni
      if (kind == 0) {
        const auto& w = log.wheels[it.index].value;
        ok = joints.write(io::ros2::joint_state_message(
            w.stamp + shift, {"left_wheel_joint", "right_wheel_joint"},
            {w.left / o.wheel_radius, w.right / o.wheel_radius}));
        if (o.pose_estimate && loop == 0 && sent[0] == 0)  // RViz's covariance
          estimate.write(io::ros2::pose_with_covariance_stamped(
              w.stamp, "map", *o.pose_estimate,
              Eigen::Vector3d(0.25, 0.25, 0.06853891945200942).asDiagonal()));
      } else {
        const auto& f = (kind == 1 ? log.ceiling_images : log.omni_images)[it.index].value;
        const char* frame = kind == 1 ? "ceiling_camera" : "omni_camera";
        if (kind == 1 && o.camera_info_scale > 0) info_writer.write(info_message(f.stamp + shift));
        ok = (kind == 1 ? ceiling : omni)
                 .write(o.raw ? image_message(f.stamp + shift, frame,
                                              (kind == 1 ? raw_ceiling : raw_omni)[it.index])
                              : io::ros2::compressed_image_message(f.stamp + shift, frame, f.format,
                                                                   f.data));
      }
      if (ok)
        ++sent[kind];
      else
        ++refused;
    }
  }
  const double played_s = std::chrono::duration<double>(Clock::now() - t0).count();
  // The node's last poses: until none has come for `linger` seconds.
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const auto last = Clock::time_point(Clock::duration(last_pose_ns.load()));
    if (Clock::now() - last > std::chrono::duration<double>(o.linger_s)) break;
  }
  if (!o.poses.empty()) {
    std::ofstream out(o.poses);
    std::lock_guard<std::mutex> lock(m);
    for (const auto& cdr : poses) out << test::pose_line(cdr) << "\n";
  }
  if (!o.diagnostics.empty()) {
    std::ofstream out(o.diagnostics);
    std::lock_guard<std::mutex> lock(m);
    for (const auto& cdr : diagnostics) out << test::diagnostic_lines(cdr);
  }
  std::cout << "sent " << sent[0] << " joint states, " << sent[1] << " ceiling and " << sent[2]
            << " omni images in " << played_s << " s (" << refused << " refused); received "
            << received << " poses\n";
  return 0;
}
