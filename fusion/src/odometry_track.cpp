#include "lampnav/fusion/odometry_track.hpp"

#include <algorithm>
#include <cmath>

#include "lampnav/fusion/ekf.hpp"

namespace lampnav::fusion {

OdometryTrack::OdometryTrack(double semi_axis, Duration kept)
    : semi_axis_(semi_axis), kept_(kept) {}

void OdometryTrack::add(Stamp stamp, double dl, double dr) {
  if (!std::isfinite(dl) || !std::isfinite(dr)) return;
  if (poses_.empty()) {
    poses_.emplace_back(stamp, Pose2());
    distance_.push_back(0.0);
    return;
  }
  if (stamp <= poses_.back().first) return;
  const StateVector x = predict_motion(poses_.back().second.vector(), dl, dr, semi_axis_);
  poses_.emplace_back(stamp, Pose2(x.x(), x.y(), wrap_angle(x.z())));
  distance_.push_back(distance_.back() + 0.5 * (std::abs(dl) + std::abs(dr)) +
                      0.5 * std::abs(dr - dl));
  while (poses_.size() > 2 && stamp - poses_.front().first > kept_) {
    poses_.pop_front();
    distance_.pop_front();
  }
}

namespace {
// Index of the first entry not before t, and the fraction of the way from the one before.
template <class Deque>
std::pair<std::size_t, double> locate(const Deque& poses, Stamp t) {
  auto it = std::lower_bound(poses.begin(), poses.end(), t,
                             [](const auto& a, Stamp s) { return a.first < s; });
  if (it == poses.begin()) return {0, 1.0};
  if (it == poses.end()) return {poses.size() - 1, 1.0};
  const Stamp ta = std::prev(it)->first, tb = it->first;
  return {static_cast<std::size_t>(it - poses.begin()),
          to_seconds(t - ta) / std::max(1e-12, to_seconds(tb - ta))};
}
}  // namespace

Pose2 OdometryTrack::at(Stamp t) const {
  if (poses_.empty()) return {};
  const auto [i, f] = locate(poses_, t);
  if (i == 0 || f >= 1.0) return poses_[i].second;
  return interpolate(poses_[i - 1].second, poses_[i].second, f);
}

double OdometryTrack::travel(Stamp a, Stamp b) const {
  if (poses_.size() < 2) return 0.0;
  auto dist = [&](Stamp t) {
    const auto [i, f] = locate(poses_, t);
    if (i == 0 || f >= 1.0) return distance_[i];
    return distance_[i - 1] + f * (distance_[i] - distance_[i - 1]);
  };
  return std::abs(dist(b) - dist(a));
}

}  // namespace lampnav::fusion
