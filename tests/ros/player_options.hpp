#pragma once
// The log player's command line, and the poses and diagnostics it hears back as text lines.

#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>

#include "cdr.hpp"  // io's CDR reader (white-box)
#include "lampnav/core/pose2.hpp"

namespace lampnav::test {

struct PlayerOptions {
  std::string log, poses;
  std::string diagnostics;  // where to write the node's /diagnostics as heard, one status a line
  int domain = 0, loops = 1;
  int jpeg_quality = 0;  // > 0: images sent as JPEG of this quality (decoded and encoded first)
  bool raw = false;      // images sent as sensor_msgs/msg/Image, decoded first
  // Their encoding: mono8, bgr8, yuyv (chroma neutral) or bayer_rggb8 (each site the grey).
  std::string raw_encoding = "mono8";
  // The cameras' mounts of the log's robot.json sent on /tf_static (base_footprint -> each
  // camera's frame), once, before any node is there (transient local, as robot_state_publisher).
  bool tf_static = false;
  // > 0: the ceiling camera's calibration of the log's robot.json (a pinhole) sent as
  // sensor_msgs/msg/CameraInfo on /ceiling_camera/camera_info with each of its images, its focal
  // lengths times this (1: the robot.json's own).
  double camera_info_scale = 0;
  double rate = 1, wheel_radius = 0.1, wait_s = 20, linger_s = 3;
  // An operator's "2D Pose Estimate" (x, y, yaw) sent on /initialpose after the first wheels.
  std::optional<Pose2> pose_estimate;
};

inline PlayerOptions parse_player_options(int argc, char** argv) {
  PlayerOptions o;
  auto number = [&](int& k) -> double {
    if (k + 1 >= argc) throw std::invalid_argument(std::string(argv[k]) + " needs a value");
    const std::string v = argv[++k];
    std::size_t used = 0;
    const double x = std::stod(v, &used);
    if (used != v.size() || !std::isfinite(x) || x < 0)
      throw std::invalid_argument(std::string(argv[k - 1]) + ": \"" + v + "\" is not a number");
    return x;
  };
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--domain")
      o.domain = static_cast<int>(number(k));
    else if (a == "--rate")
      o.rate = number(k);
    else if (a == "--wheel-radius")
      o.wheel_radius = number(k);
    else if (a == "--wait-s")
      o.wait_s = number(k);
    else if (a == "--linger-s")
      o.linger_s = number(k);
    else if (a == "--loops")
      o.loops = static_cast<int>(number(k));
    else if (a == "--jpeg")
      o.jpeg_quality = static_cast<int>(number(k));
    else if (a == "--raw")
      o.raw = true;
    else if (a == "--raw-encoding" && k + 1 < argc) {
      o.raw = true;
      o.raw_encoding = argv[++k];
      if (o.raw_encoding != "mono8" && o.raw_encoding != "bgr8" && o.raw_encoding != "yuyv" &&
          o.raw_encoding != "bayer_rggb8")
        throw std::invalid_argument("--raw-encoding: mono8, bgr8, yuyv or bayer_rggb8");
    } else if (a == "--tf-static")
      o.tf_static = true;
    else if (a == "--camera-info")
      o.camera_info_scale = number(k);
    else if (a == "--pose-estimate" && k + 1 < argc) {
      double x = 0, y = 0, yaw = 0;
      char tail = 0;
      if (std::sscanf(argv[++k], "%lf,%lf,%lf%c", &x, &y, &yaw, &tail) != 3)
        throw std::invalid_argument("--pose-estimate: X,Y,YAW");
      o.pose_estimate = Pose2(x, y, yaw);
    } else if (a == "--poses" && k + 1 < argc)
      o.poses = argv[++k];
    else if (a == "--diagnostics" && k + 1 < argc)
      o.diagnostics = argv[++k];
    else if (!a.empty() && a[0] != '-' && o.log.empty())
      o.log = a;
    else
      throw std::invalid_argument("unknown argument " + a);
  }
  if (o.log.empty()) throw std::invalid_argument("no log given");
  if (o.jpeg_quality > 100) throw std::invalid_argument("--jpeg: quality 1 to 100");
  if (o.raw && o.jpeg_quality > 0) throw std::invalid_argument("--raw or --jpeg, not both");
  if (!(o.rate > 0) || !(o.wheel_radius > 0) || o.loops < 1)
    throw std::invalid_argument("--rate, --wheel-radius and --loops must be positive");
  return o;
}

// diagnostic_msgs/msg/DiagnosticArray as lines "level|name|message|hardware_id|key=value,...".
inline std::string diagnostic_lines(const std::string& cdr) {
  io::CdrReader r(cdr);
  r.i32("sec");
  r.u32("nanosec");
  r.string("frame_id");
  std::string out;
  const std::uint32_t n = r.u32("status");
  for (std::uint32_t k = 0; k < n; ++k) {
    out += std::to_string(r.u8("level"));
    for (const char* f : {"name", "message", "hardware_id"}) out += "|" + r.string(f);
    out += "|";
    const std::uint32_t values = r.u32("values");
    for (std::uint32_t v = 0; v < values; ++v) {
      out += (v ? "," : "") + r.string("key");
      out += "=" + r.string("value");
    }
    out += "\n";
  }
  return out;
}

// geometry_msgs/msg/PoseWithCovarianceStamped as "stamp_ns x y yaw".
inline std::string pose_line(const std::string& cdr) {
  io::CdrReader r(cdr);
  const std::int64_t sec = r.i32("sec"), nsec = r.u32("nanosec");
  r.string("frame_id");
  const double x = r.f64("x"), y = r.f64("y");
  r.f64("z");
  const double qx = r.f64("qx"), qy = r.f64("qy"), qz = r.f64("qz"), qw = r.f64("qw");
  const double yaw = std::atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz));
  char buf[160];
  std::snprintf(buf, sizeof buf, "%lld %.12f %.12f %.12f",
                static_cast<long long>(sec * 1'000'000'000 + nsec), x, y, yaw);
  return buf;
}

}  // namespace lampnav::test
