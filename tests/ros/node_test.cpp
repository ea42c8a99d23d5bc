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

// The corridor drive recorded, `lampnav node` started on it in the background and the player
// playing it; what the node wrote (its counts) and what the player heard (its poses).
struct CorridorRun {
  std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  graph::TopologicalMap map = graph::parse_map(geojson, "office_floor.geojson").map;
  std::string robot_path = test::source_path("maps/robots/pioneer.json");
  RobotDescription robot = read_robot_description(robot_path);
  std::string dir, log_path;
  io::MissionLog log;
  std::string domain = std::to_string(test::test_domain());

  explicit CorridorRun(const std::string& name) : dir(test::temp_path(name)) {
    fs::create_directories(dir);
    log_path = dir + "/corridor.mcap";
    sim::record_mission(sim::make_named_scenario("corridor", map, geojson, robot, 1), log_path);
    log = io::read_mission_log(log_path);
  }
  ~CorridorRun() { fs::remove_all(dir); }

  // Starts the node; every image kept (as replay takes them) however loaded the machine running
  // the tests is.
  void start_node(const std::string& options, const std::string& robot_file = "") const {
    const std::string cmd = std::string(LAMPNAV_BINARY) + " node --robot '" +
                            (robot_file.empty() ? robot_path : robot_file) + "' --map '" +
                            test::source_path("maps/office_floor.geojson") + "' --domain " +
                            domain + " " + options +
                            " --joint-states-topic /joint_states --wheel-radius 0.1"
                            " --images-waiting 100000 --idle-exit 3 --quiet --stats '" +
                            dir + "/stats.json' > '" + dir + "/node.out' 2>&1 &";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
  }
  // Plays the log, then waits for the node's counts.
  nlohmann::json play(const std::string& options) const {
    int status = -1;
    const std::string played = test::run_command(
        std::string(LAMPNAV_LOG_PLAYER) + " '" + log_path + "' --domain " + domain +
            " --wheel-radius 0.1 " + options + " --poses '" + dir + "/poses.txt' 2>&1",
        &status);
    EXPECT_EQ(status, 0) << played;
    std::cout << "player: " << played;
    if (!test::wait_for([&] { return fs::exists(dir + "/stats.json"); }, 30)) {
      ADD_FAILURE() << "no counts from the node: " << test::slurp(dir + "/node.out");
      return {};
    }
    // The file is written whole before the node ends.
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    std::cout << "node: " << test::slurp(dir + "/node.out");
    return nlohmann::json::parse(test::slurp(dir + "/stats.json"));
  }
  // The poses the player heard, by stamp (the first for each).
  std::map<std::int64_t, Pose2> poses() const {
    std::map<std::int64_t, Pose2> out;
    std::ifstream in(dir + "/poses.txt");
    std::string line;
    while (std::getline(in, line)) {
      std::istringstream s(line);
      std::int64_t t;
      double x, y, yaw;
      s >> t >> x >> y >> yaw;
      out.emplace(t, Pose2(x, y, yaw));
    }
    return out;
  }
};

// The node's poses against replay's certain estimates: how many the node published (the first
// for each wheel reading) and how far apart they are at most (m).
struct Agreement {
  std::size_t certain = 0, compared = 0;
  double worst = 0;
};
Agreement agreement(const std::map<std::int64_t, Pose2>& node,
                    const evaluation::ReplayResult& replayed) {
  Agreement a;
  for (const auto& e : replayed.estimates) {
    if (!fusion::is_certain(e.mode)) continue;
    ++a.certain;
    const auto it = node.find(to_nanoseconds(e.stamp));
    if (it == node.end()) continue;
    ++a.compared;
    a.worst = std::max(a.worst, (it->second.translation() - e.pose.translation()).norm());
  }
  std::cout << a.compared << " of replay's " << a.certain << " certain poses published by the "
            << "node, at most " << a.worst * 1000 << " mm apart\n";
  return a;
}

// Every certain pose of replay's (more than 3,000 on the corridor run) published by the node,
// within 1 mm.
void expect_published_as_replayed(const std::map<std::int64_t, Pose2>& node,
                                  const evaluation::ReplayResult& replayed) {
  const Agreement a = agreement(node, replayed);
  EXPECT_GT(a.certain, 3000u);
  EXPECT_EQ(a.compared, a.certain);
  EXPECT_LE(a.worst, 1e-3);
}

// The node's /diagnostics as the player heard them while it played (diagnostic_lines): every
// second the localization and each input; while played, the cameras and the wheels OK at their
// rates, the localization OK once tracking. An input that is ERROR says it is silent (the node
// reports before the player starts and after it stops too).
void expect_healthy_while_played(const std::string& lines) {
  std::istringstream in(lines);
  std::string line;
  std::map<std::string, int> ok;
  int reports = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::istringstream fields(line);
    for (std::string x; std::getline(fields, x, '|');) f.push_back(x);
    ASSERT_GE(f.size(), 4u) << line;
    const std::string &level = f[0], name = f[1], message = f[2];
    ASSERT_TRUE(level == "0" || level == "1" || level == "2") << line;
    if (name == "lampnav: localization") {
      ++reports;
      if (level == "0") {
        EXPECT_TRUE(message == "tracking" || message == "relocalized") << line;
      }
      if (level == "1") {
        EXPECT_FALSE(message.empty()) << line;
      }
      EXPECT_NE(level, "2") << line;
    } else {
      ASSERT_TRUE(name == "lampnav: ceiling camera" || name == "lampnav: omni camera" ||
                  name == "lampnav: odometry")
          << line;
      if (level == "2") {
        EXPECT_EQ(message.rfind("nothing", 0), 0u) << line;
      }
      if (level == "0") {
        EXPECT_THAT(message, ::testing::EndsWith(" Hz")) << line;
      }
    }
    if (level == "0") ++ok[name];
  }
  std::cout << reports << " diagnostics reports\n";
  EXPECT_GE(reports, 10);
  for (const char* name : {"lampnav: localization", "lampnav: ceiling camera",
                           "lampnav: omni camera", "lampnav: odometry"})
    EXPECT_GE(ok[name], 5) << name;
}

TEST(Node, PublishesThePosesReplayComputesFromTheSameLog) {
  const CorridorRun run("node_test");
  const evaluation::ReplayResult replayed = evaluation::replay(run.log, run.map, run.robot);
  run.start_node("");
  // The ceiling camera's driver publishes a calibration 1 % longer in focal length than
  // robot.json's: the node says so, and goes on with robot.json's.
  const nlohmann::json stats =
      run.play("--rate 2 --camera-info 1.01 --diagnostics '" + run.dir + "/diagnostics.txt'");
  ASSERT_FALSE(stats.is_null());
  expect_healthy_while_played(test::slurp(run.dir + "/diagnostics.txt"));
  EXPECT_GT(stats["camera_info"]["used"], 0u);
  EXPECT_THAT(test::slurp(run.dir + "/node.out"),
              ::testing::HasSubstr("warning: /ceiling_camera/camera_info: its calibration "
                                   "(plumb_bob, fx 303) puts pixels up to"));

  // Nothing lost: every message the player sent arrived and was used.
  EXPECT_EQ(stats["odometry"]["received"], run.log.wheels.size());
  EXPECT_EQ(stats["odometry"]["used"], run.log.wheels.size());
  EXPECT_EQ(stats["ceiling"]["used"], run.log.ceiling_images.size());
  EXPECT_EQ(stats["omni"]["used"], run.log.omni_images.size());
  // Nothing on /tf_static: robot.json's mounts.
  EXPECT_EQ(stats["static_transforms"]["received"], 0u);
  EXPECT_TRUE(stats["mounts_from_tf"].empty());

  // The first pose published for each wheel reading is replay's estimate there.
  expect_published_as_replayed(run.poses(), replayed);
}

// A robot.json whose camera mounts are wrong (the ceiling camera 8 cm off and turned 5 degrees,
// the omni camera 6 cm off) on a robot whose /tf_static has them right (the player sends the
// log's, before the node is matched, as robot_state_publisher does): the node takes the mounts
// from /tf_static and publishes the poses replay computes with the right robot.json.
TEST(Node, TakesTheCameraMountsFromTfStatic) {
  const CorridorRun run("node_tf_test");
  RobotDescription wrong = run.robot;
  for (auto& c : wrong.cameras) {
    if (c.name == "ceiling_camera") {
      c.mount.xyz.x() += 0.08;
      c.mount.rpy.z() += 5 * M_PI / 180;
    }
    if (c.name == "omni_camera") c.mount.xyz.y() += 0.06;
  }
  const std::string wrong_path = run.dir + "/wrong_mounts.json";
  std::ofstream(wrong_path) << to_robot_json(wrong);
  const evaluation::ReplayResult replayed = evaluation::replay(run.log, run.map, run.robot);
  // The wrong mounts matter: replayed with them, the poses are centimetres off.
  const evaluation::ReplayResult misplaced = evaluation::replay(run.log, run.map, wrong);
  std::map<std::int64_t, Pose2> misplaced_poses;
  for (const auto& e : misplaced.estimates)
    if (fusion::is_certain(e.mode)) misplaced_poses.emplace(to_nanoseconds(e.stamp), e.pose);
  EXPECT_GT(agreement(misplaced_poses, replayed).worst, 0.02);

  run.start_node("", wrong_path);
  // The driver's calibration is robot.json's: nothing said of it.
  const nlohmann::json stats = run.play("--rate 2 --tf-static --camera-info 1");
  ASSERT_FALSE(stats.is_null());
  EXPECT_GT(stats["camera_info"]["used"], 0u);
  EXPECT_THAT(test::slurp(run.dir + "/node.out"),
              ::testing::Not(::testing::HasSubstr("camera_info")));
  EXPECT_EQ(stats["static_transforms"]["used"], 1u);
  EXPECT_EQ(stats["mounts_from_tf"], nlohmann::json({"ceiling_camera", "omni_camera"}));
  expect_published_as_replayed(run.poses(), replayed);
}

// Without a start and without the omni camera the node cannot find the robot; an operator's "2D
// Pose Estimate" on /initialpose (sent by the player after the first wheel reading, where the
// robot starts) tells it, and it tracks the drive from there on the ceiling camera alone.
TEST(Node, TracksFromAnOperatorsPoseEstimate) {
  const CorridorRun run("node_estimate_test");
  const io::TruthTrack truth(run.log.truth);
  const Pose2 start = truth.at(run.log.wheels.front().value.stamp);
  run.start_node("--no-omni");
  char at[96];
  std::snprintf(at, sizeof at, "%.9f,%.9f,%.9f", start.x(), start.y(), start.yaw());
  const nlohmann::json stats = run.play(std::string("--rate 3 --pose-estimate ") + at);
  ASSERT_FALSE(stats.is_null());
  EXPECT_EQ(stats["pose_estimates"]["used"], 1u);
  EXPECT_EQ(stats["omni_frames"], 0u);
  const std::map<std::int64_t, Pose2> poses = run.poses();
  double worst = 0;
  for (const auto& [t, p] : poses)
    worst = std::max(worst,
                     (truth.at(stamp_from_nanoseconds(t)).translation() - p.translation()).norm());
  std::cout << poses.size() << " poses published, at most " << worst * 100
            << " cm from the truth\n";
  EXPECT_GT(poses.size(), 3000u);  // one a wheel reading from the estimate on
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
  out = test::run_command(base + "--tf-wait 100 2>&1", &status);
  EXPECT_EQ(status, 2) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("--tf-wait"));
  out = test::run_command(base + "--tf-static-topic tf_static 2>&1", &status);
  EXPECT_EQ(status, 2) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("tf_static: not a ROS 2 topic name"));
  out = test::run_command("ROS_DOMAIN_ID=abc " + base + "2>&1", &status);
  EXPECT_EQ(status, 2) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("ROS_DOMAIN_ID"));
}

}  // namespace
}  // namespace lampnav
