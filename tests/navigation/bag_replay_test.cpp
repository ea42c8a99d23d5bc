// A ROS 2 bag of a mission replays as the mission's own log does: the office mission (a kidnap)
// written again as a bag (wheel odometry as nav_msgs/msg/Odometry integrated the way ROS's
// diff_drive_controller does, images as sensor_msgs/msg/CompressedImage, header stamps the
// capture times, log times the arrivals), replayed with the robot's semi-axis, gives the same
// mode changes, the same metrics that need no truth (a bag carries none), and the same estimates
// within 5 mm. Not to the last bit: the wheel readings rebuilt from the bag's poses are not the
// log's (every one of the 7,108 differs, by up to 9.6 mm), and some decision in the localizer
// goes the other way (which one was not found). Until 2026-11-26 the estimates agreed to
// 1e-13 m; with the global search's screen widened to 80 degrees, the bag's estimate moves
// 0.7 mm 48 s after the relocalization (1.4 mm at most, 8 um by the end).

#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "cdr_writer.hpp"
#include "lampnav/evaluation/replay.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mcap.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav_test.hpp"

namespace lampnav::navigation {
namespace {

using namespace lampnav::evaluation;  // replay, its results and outputs

namespace fs = std::filesystem;

std::uint64_t ns(Stamp t) { return static_cast<std::uint64_t>(to_nanoseconds(t)); }

// The log's inputs as a ROS 2 bag.
void write_bag(const io::MissionLog& log, double semi_axis, const std::string& path) {
  io::McapWriter w(path, {"ros2"});
  const auto image = w.add_schema("sensor_msgs/msg/CompressedImage", "ros2msg",
                                  "std_msgs/Header header\nstring format\nuint8[] data\n");
  const auto odom = w.add_schema("nav_msgs/msg/Odometry", "ros2msg",
                                 "std_msgs/Header header\nstring child_frame_id\n"
                                 "geometry_msgs/PoseWithCovariance pose\n"
                                 "geometry_msgs/TwistWithCovariance twist\n");
  const auto ceiling = w.add_channel(image, "/ceiling_camera/image/compressed", "cdr");
  const auto omni = w.add_channel(image, "/omni_camera/image/compressed", "cdr");
  const auto odometry = w.add_channel(odom, "/odom", "cdr");
  Pose2 p;
  for (std::size_t k = 0; k < log.wheels.size(); ++k) {
    const auto& r = log.wheels[k];
    if (k > 0) {
      const auto& q = log.wheels[k - 1].value;
      const double dl = r.value.left - q.left, dr = r.value.right - q.right;
      const double ds = 0.5 * (dl + dr), dyaw = (dr - dl) / (2 * semi_axis);
      p = Pose2(p.x() + ds * std::cos(p.yaw() + dyaw / 2),
                p.y() + ds * std::sin(p.yaw() + dyaw / 2), wrap_angle(p.yaw() + dyaw));
    }
    w.write(odometry, ns(r.log_time), ns(r.log_time),
            test::odometry_cdr(to_nanoseconds(r.value.stamp), p.x(), p.y(), p.yaw()));
  }
  for (const auto& f : log.ceiling_images)
    w.write(ceiling, ns(f.log_time), ns(f.log_time),
            test::compressed_image_cdr(to_nanoseconds(f.value.stamp), "ceiling_camera",
                                       f.value.format, f.value.data));
  for (const auto& f : log.omni_images)
    w.write(omni, ns(f.log_time), ns(f.log_time),
            test::compressed_image_cdr(to_nanoseconds(f.value.stamp), "omni_camera", f.value.format,
                                       f.value.data));
  w.close();
}

TEST(BagReplay, ABagOfTheOfficeMissionGivesTheSameEstimates) {
  const std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  const graph::TopologicalMap map = graph::parse_map(geojson, "office_floor.geojson").map;
  const RobotDescription robot =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  const sim::Scenario s = sim::make_named_scenario("office-mission", map, geojson, robot, 1);
  const std::string dir = test::temp_path("bag_replay");
  fs::create_directories(dir);
  sim::record_mission(s, dir + "/mission.mcap");
  const io::MissionLog log = io::read_mission_log(dir + "/mission.mcap");
  write_bag(log, robot.semi_axis, dir + "/mission_bag.mcap");
  io::MissionLog bag = io::read_mission_log(dir + "/mission_bag.mcap");
  fs::remove_all(dir);
  EXPECT_TRUE(bag.ros2_bag);
  EXPECT_EQ(bag.skipped_messages, 0u);
  io::wheels_from_odometry(bag, robot.semi_axis);
  ASSERT_EQ(bag.wheels.size(), log.wheels.size());
  ASSERT_EQ(bag.ceiling_images.size(), log.ceiling_images.size());
  ASSERT_EQ(bag.omni_images.size(), log.omni_images.size());

  ReplayOptions o;
  o.initial_pose = s.start;
  const ReplayResult a = replay(log, map, robot, o);
  const ReplayResult b = replay(bag, map, robot, o);
  ASSERT_EQ(a.estimates.size(), b.estimates.size());
  double worst = 0;
  for (std::size_t k = 0; k < a.estimates.size(); ++k) {
    ASSERT_EQ(a.estimates[k].stamp, b.estimates[k].stamp) << k;
    EXPECT_EQ(a.estimates[k].mode, b.estimates[k].mode) << k;
    worst = std::max(
        worst, (a.estimates[k].pose.translation() - b.estimates[k].pose.translation()).norm());
  }
  std::cout << a.estimates.size() << " estimates, the bag's at most " << worst * 1000
            << " mm from the log's\n";
  EXPECT_LE(worst, 5e-3);
  ASSERT_EQ(a.events.size(), b.events.size());
  for (std::size_t k = 0; k < a.events.size(); ++k) {
    EXPECT_EQ(a.events[k].stamp, b.events[k].stamp) << k;
    EXPECT_EQ(a.events[k].mode, b.events[k].mode) << k;
  }
  EXPECT_GE(a.events.size(), 3u);  // the kidnap: lost, relocalized, tracking
  EXPECT_EQ(a.metrics.lost_s, b.metrics.lost_s);
  EXPECT_EQ(a.metrics.ambiguous_s, b.metrics.ambiguous_s);
  EXPECT_EQ(a.metrics.lamps_seen, b.metrics.lamps_seen);
  EXPECT_EQ(a.metrics.lamps_labelled, b.metrics.lamps_labelled);
  EXPECT_EQ(a.metrics.frames, b.metrics.frames);
  EXPECT_GT(a.estimates.size(), 1000u);
}

}  // namespace
}  // namespace lampnav::navigation
