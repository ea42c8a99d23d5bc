// Pure pursuit along waypoints.

#include "lampnav/navigation/path_follower.hpp"

#include "lampnav/sim/odometry.hpp"
#include "lampnav_test.hpp"

namespace lampnav::navigation {
namespace {

using sim::drive;
using sim::wheel_travel;

TEST(PathFollower, ArrivesAlongAnLShapedPath) {
  PathFollower f({{0, 0}, {5, 0}, {5, 5}});
  Pose2 pose(0, 0, 0);
  double max_off = 0;
  for (int i = 0; i < 10000 && !f.arrived(); ++i) {
    const auto [v, w] = f.command(pose);
    pose = drive(pose, wheel_travel(v * 0.02, w * 0.02, 0.2), 0.2);
    const double off = pose.x() < 4.5 ? std::fabs(pose.y()) : std::fabs(pose.x() - 5);
    max_off = std::max(max_off, off);
  }
  EXPECT_TRUE(f.arrived());
  EXPECT_LT((pose.translation() - Eigen::Vector2d(5, 5)).norm(), 0.15);
  EXPECT_LT(max_off,
            0.6);  // pure pursuit cuts the corner by about the look-ahead; corridors are 2 m
}

}  // namespace
}  // namespace lampnav::navigation
