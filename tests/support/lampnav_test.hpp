#pragma once
// Shared test helpers: fixture paths and matchers.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "lampnav/core/pose2.hpp"

namespace lampnav::test {

inline std::string source_path(const std::string& relative) {
  return std::string(LAMPNAV_SOURCE_DIR) + "/" + relative;
}
inline std::string fixture(const std::string& relative) {
  return source_path("tests/fixtures/" + relative);
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

}  // namespace lampnav::test
