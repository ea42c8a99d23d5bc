// `lampnav node` on the loopback, fed by a player process that plays a recorded mission as a
// ROS 2 robot's drivers would (wheel joints and compressed images, at twice the log's pace): the
// poses the node publishes are those `replay` computes from the same log, to 1 mm; every message
// sent arrives and is used.

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "lampnav/evaluation/replay.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav_test.hpp"
#include "ros_test_support.hpp"

namespace lampnav {
namespace {

namespace fs = std::filesystem;

TEST(Node, PublishesThePosesReplayComputesFromTheSameLog) {
  const std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  const graph::TopologicalMap map = graph::parse_map(geojson, "office_floor.geojson").map;
  const std::string robot_path = test::source_path("maps/robots/pioneer.json");
  const RobotDescription robot = read_robot_description(robot_path);
  const std::string dir = test::temp_path("node_test");
  fs::create_directories(dir);
  const std::string log_path = dir + "/corridor.mcap";
  sim::record_mission(sim::make_named_scenario("corridor", map, geojson, robot, 1), log_path);
  const io::MissionLog log = io::read_mission_log(log_path);
  const evaluation::ReplayResult replayed = evaluation::replay(log, map, robot);

  const std::string domain = std::to_string(test::test_domain());
  const std::string node_cmd = std::string(LAMPNAV_BINARY) + " node --robot '" + robot_path +
                               "' --map '" + test::source_path("maps/office_floor.geojson") +
                               "' --domain " + domain +
                               " --joint-states-topic /joint_states --wheel-radius 0.1"
                               // Every image, as replay takes them, however loaded the
                               // machine running the tests is.
                               " --images-waiting 100000"
                               " --idle-exit 3 --quiet --stats '" +
                               dir + "/stats.json' > '" + dir + "/node.out' 2>&1 &";
  ASSERT_EQ(std::system(node_cmd.c_str()), 0);
  int status = -1;
  const std::string played =
      test::run_command(std::string(LAMPNAV_LOG_PLAYER) + " '" + log_path + "' --domain " + domain +
                            " --rate 2 --wheel-radius 0.1 --poses '" + dir + "/poses.txt' 2>&1",
                        &status);
  ASSERT_EQ(status, 0) << played;
  std::cout << "player: " << played;
  ASSERT_TRUE(test::wait_for([&] { return fs::exists(dir + "/stats.json"); }, 30))
      << test::slurp(dir + "/node.out");
  std::this_thread::sleep_for(
      std::chrono::milliseconds(500));  // the file is written whole before the node ends
  std::cout << "node: " << test::slurp(dir + "/node.out");
  const nlohmann::json stats = nlohmann::json::parse(test::slurp(dir + "/stats.json"));

  // Nothing lost: every message the player sent arrived and was used.
  EXPECT_EQ(stats["odometry"]["received"], log.wheels.size());
  EXPECT_EQ(stats["odometry"]["used"], log.wheels.size());
  EXPECT_EQ(stats["ceiling"]["used"], log.ceiling_images.size());
  EXPECT_EQ(stats["omni"]["used"], log.omni_images.size());

  // The first pose published for each wheel reading is replay's estimate there.
  std::map<std::int64_t, Pose2> node;
  std::ifstream in(dir + "/poses.txt");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::int64_t t;
    double x, y, yaw;
    s >> t >> x >> y >> yaw;
    node.emplace(t, Pose2(x, y, yaw));
  }
  fs::remove_all(dir);
  std::size_t certain = 0, compared = 0;
  double worst = 0;
  for (const auto& e : replayed.estimates) {
    if (!fusion::is_certain(e.mode)) continue;
    ++certain;
    const auto it = node.find(to_nanoseconds(e.stamp));
    if (it == node.end()) continue;
    ++compared;
    worst = std::max(worst, (it->second.translation() - e.pose.translation()).norm());
  }
  std::cout << compared << " of replay's " << certain << " certain poses published by the node, "
            << "at most " << worst * 1000 << " mm apart\n";
  EXPECT_GT(certain, 3000u);
  EXPECT_EQ(compared, certain);
  EXPECT_LE(worst, 1e-3);
}

// Without a start and without the omni camera the node cannot find the robot; an operator's "2D
// Pose Estimate" on /initialpose (sent by the player after the first wheel reading, where the
// robot starts) tells it, and it tracks the drive from there on the ceiling camera alone.
TEST(Node, TracksFromAnOperatorsPoseEstimate) {
  const std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  const graph::TopologicalMap map = graph::parse_map(geojson, "office_floor.geojson").map;
  const std::string robot_path = test::source_path("maps/robots/pioneer.json");
  const RobotDescription robot = read_robot_description(robot_path);
  const std::string dir = test::temp_path("node_estimate_test");
  fs::create_directories(dir);
  const std::string log_path = dir + "/corridor.mcap";
  sim::record_mission(sim::make_named_scenario("corridor", map, geojson, robot, 1), log_path);
  const io::MissionLog log = io::read_mission_log(log_path);
  const io::TruthTrack truth(log.truth);
  const Pose2 start = truth.at(log.wheels.front().value.stamp);

  const std::string domain = std::to_string(test::test_domain());
  const std::string node_cmd = std::string(LAMPNAV_BINARY) + " node --robot '" + robot_path +
                               "' --map '" + test::source_path("maps/office_floor.geojson") +
                               "' --domain " + domain +
                               " --no-omni --joint-states-topic /joint_states --wheel-radius 0.1"
                               " --images-waiting 100000 --idle-exit 3 --quiet --stats '" +
                               dir + "/stats.json' > '" + dir + "/node.out' 2>&1 &";
  ASSERT_EQ(std::system(node_cmd.c_str()), 0);
  char at[96];
  std::snprintf(at, sizeof at, "%.9f,%.9f,%.9f", start.x(), start.y(), start.yaw());
  int status = -1;
  const std::string played =
      test::run_command(std::string(LAMPNAV_LOG_PLAYER) + " '" + log_path + "' --domain " + domain +
                            " --rate 3 --wheel-radius 0.1 --pose-estimate " + at + " --poses '" +
                            dir + "/poses.txt' 2>&1",
                        &status);
  ASSERT_EQ(status, 0) << played;
  std::cout << "player: " << played;
  ASSERT_TRUE(test::wait_for([&] { return fs::exists(dir + "/stats.json"); }, 30))
      << test::slurp(dir + "/node.out");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const nlohmann::json stats = nlohmann::json::parse(test::slurp(dir + "/stats.json"));
  EXPECT_EQ(stats["pose_estimates"]["used"], 1u);
  EXPECT_EQ(stats["omni_frames"], 0u);

  std::ifstream in(dir + "/poses.txt");
  std::string line;
  std::size_t poses = 0;
  double worst = 0;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::int64_t t;
    double x, y, yaw;
    s >> t >> x >> y >> yaw;
    ++poses;
    worst = std::max(
        worst, (truth.at(stamp_from_nanoseconds(t)).translation() - Eigen::Vector2d(x, y)).norm());
  }
  fs::remove_all(dir);
  std::cout << poses << " poses published, at most " << worst * 100 << " cm from the truth\n";
  EXPECT_GT(poses, 3000u);  // one a wheel reading from the estimate on
  EXPECT_LT(worst, 0.1);
}

TEST(Node, RefusesBadOptionsWithStatus2) {
  const std::string base = std::string(LAMPNAV_BINARY) + " node --robot '" +
                           test::source_path("maps/robots/pioneer.json") + "' --map '" +
                           test::source_path("maps/office_floor.geojson") + "' ";
  int status = -1;
  std::string out = test::run_command(base + "--odometry-topic odom 2>&1", &status);
  EXPECT_EQ(status, 2) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("not a ROS 2 topic name"));
  out = test::run_command(base + "--joint-states-topic /joint_states 2>&1", &status);
  EXPECT_EQ(status, 2) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("--wheel-radius"));
  out = test::run_command(base + "--domain 300 2>&1", &status);
  EXPECT_EQ(status, 2) << out;
  out = test::run_command("ROS_DOMAIN_ID=abc " + base + "2>&1", &status);
  EXPECT_EQ(status, 2) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("ROS_DOMAIN_ID"));
}

}  // namespace
}  // namespace lampnav
