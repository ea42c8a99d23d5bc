#pragma once
// Truth of a recorded mission at any instant, for tests that score estimates against it.

#include <algorithm>
#include <vector>

#include "lampnav/io/mission_log.hpp"

namespace lampnav::test {

// The true pose at `t`, interpolated between the two truth samples around it (sorted by stamp).
// A kidnap is a jump between two samples: no interpolation across it.
inline Pose2 truth_at(const std::vector<io::Logged<io::TruthPose>>& truth, Stamp t) {
  auto it = std::lower_bound(truth.begin(), truth.end(), t,
                             [](const auto& a, Stamp s) { return a.value.stamp < s; });
  if (it == truth.begin()) return it->value.pose;
  if (it == truth.end()) return truth.back().value.pose;
  const auto& b = it->value;
  if (b.stamp == t) return b.pose;
  const auto& a = std::prev(it)->value;
  if ((b.pose.translation() - a.pose.translation()).norm() > 0.5) return a.pose;
  const double f = to_seconds(t - a.stamp) / std::max(1e-12, to_seconds(b.stamp - a.stamp));
  return Pose2(a.pose.translation() + f * (b.pose.translation() - a.pose.translation()),
               a.pose.yaw() + f * wrap_angle(b.pose.yaw() - a.pose.yaw()));
}

}  // namespace lampnav::test
