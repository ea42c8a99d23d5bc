#pragma once
// Dead reckoning in its own frame, kept whatever the filter believes: it carries pose hypotheses
// from one frame's capture time to another's (forwards or backwards), and a first fix to the
// latest reading. A span of readings is kept; outside it the nearest end stands in.

#include <deque>
#include <utility>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/time.hpp"

namespace lampnav::fusion {

class OdometryTrack {
 public:
  explicit OdometryTrack(double semi_axis, Duration kept = std::chrono::seconds(120));

  // Wheel travel since the previous reading (m), read at `stamp`. The first reading is the
  // origin; readings not after the last one, and non-finite ones, are ignored.
  void add(Stamp stamp, double d_left, double d_right);
  bool empty() const { return poses_.empty(); }
  Stamp first_stamp() const { return poses_.front().first; }
  Stamp last_stamp() const { return poses_.back().first; }
  const Pose2& last() const { return poses_.back().second; }

  // The dead-reckoned pose at `t`, interpolated (the nearest end outside the kept span; the
  // origin when empty).
  Pose2 at(Stamp t) const;
  // Distance the robot's wheels covered from a to b (either order), translation plus the arc of
  // turning at the semi-axis: what odometry error grows with.
  double travel(Stamp a, Stamp b) const;

 private:
  double semi_axis_;
  Duration kept_;
  std::deque<std::pair<Stamp, Pose2>> poses_;
  std::deque<double> distance_;  // cumulative travel at each pose
};

}  // namespace lampnav::fusion
