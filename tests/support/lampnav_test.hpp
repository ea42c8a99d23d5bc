#pragma once
// Shared test helpers: fixture paths and matchers.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <Eigen/Core>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"

namespace lampnav::test {

inline std::string source_path(const std::string& relative) {
  return std::string(LAMPNAV_SOURCE_DIR) + "/" + relative;
}
inline std::string fixture(const std::string& relative) {
  return source_path("tests/fixtures/" + relative);
}
// A path in the temporary directory, named for this process so that test binaries running side
// by side do not meet.
inline std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("lampnav_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

// The whole content of a file ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs a shell command; returns what it printed on stdout and sets *status to its exit status
// (-1 when it did not exit normally).
inline std::string run_command(const std::string& command, int* status) {
  std::string out;
  *status = -1;
  FILE* p = ::popen(command.c_str(), "r");
  if (!p) return out;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int st = ::pclose(p);
  *status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return out;
}

// Matches a Pose2 within a position tolerance (m) and a yaw tolerance (rad).
MATCHER_P3(IsNearPose, expected, pos_tol, yaw_tol,
           "is within " + ::testing::PrintToString(pos_tol) + " m and " +
               ::testing::PrintToString(yaw_tol) + " rad of " +
               ::testing::PrintToString(expected)) {
  const double dp = (arg.translation() - expected.translation()).norm();
  const double dyaw = std::fabs(wrap_angle(arg.yaw() - expected.yaw()));
  *result_listener << "position off by " << dp << " m, yaw by " << dyaw << " rad";
  return dp <= pos_tol && dyaw <= yaw_tol;
}

// Central-difference Jacobian of f: R^n -> R^m at x (GTSAM's habit: every analytic Jacobian is
// checked against this).
template <int M, int N, class F>
Eigen::Matrix<double, M, N> numerical_jacobian(F f, const Eigen::Matrix<double, N, 1>& x,
                                               double h = 1e-6) {
  Eigen::Matrix<double, M, N> J;
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<double, N, 1> a = x, b = x;
    a(i) += h;
    b(i) -= h;
    J.col(i) = (f(a) - f(b)) / (2 * h);
  }
  return J;
}

// The robot's omni camera replaced by an 800 x 800 Kannala-Brandt one (OpenCV's fisheye model, as
// `robot import` writes it from an OpenCV, ROS or Kalibr calibration), 185 degrees of view.
inline RobotDescription with_kannala_brandt_omni(RobotDescription robot) {
  for (CameraDescription& c : robot.cameras) {
    if (c.name != "omni_camera") continue;
    c.model = CameraModelKind::kannala_brandt;
    c.width = c.height = 800;
    c.fisheye = FisheyeParameters{};
    c.fisheye.u0 = c.fisheye.v0 = 400;
    c.fisheye.f = 230;
    c.fisheye.k = {0.02, -0.01, 0.002, -0.0005};
    c.fisheye.fov_deg = 185;
  }
  return robot;
}

}  // namespace lampnav::test
