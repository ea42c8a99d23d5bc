// A ROS 2 bag written by independent code replays as the mission it came from. The corridor run
// is recorded by `lampnav sim`; tests/interop/write_ros2_bag.mjs writes it again as a ROS 2 bag
// with the official TypeScript MCAP writer (@mcap/core), Foxglove's ROS 2 CDR serializer
// (@foxglove/rosmsg2-serialization) and ROS 2 Humble's message definitions
// (@foxglove/rosmsg-msgs-common); `lampnav replay` of the bag gives the log's estimates.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_support.hpp"
#include "lampnav_test.hpp"

namespace lampnav {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct TumPose {
  std::string t;
  double x = 0, y = 0;
};

std::vector<TumPose> read_tum(const std::string& path) {
  std::ifstream in(path);
  std::vector<TumPose> out;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    TumPose p;
    s >> p.t >> p.x >> p.y;
    if (s) out.push_back(p);
  }
  return out;
}

TEST(BagInterop, ABagWrittenByRos2ToolingReplaysAsTheMission) {
  const std::string interop = test::source_path("tests/interop");
  for (const char* package :
       {"@mcap/core", "@foxglove/rosmsg2-serialization", "@foxglove/rosmsg-msgs-common"})
    ASSERT_TRUE(fs::exists(interop + "/node_modules/" + package))
        << package << " is not installed: run `make test`, which installs it";
  const std::string dir = test::temp_path("bag_interop");
  fs::create_directories(dir);
  const std::string log = dir + "/corridor.mcap", bag = dir + "/corridor_bag.mcap";
  ASSERT_EQ(test::run_lampnav("sim --scenario corridor -o '" + log + "'").status, 0);
  int status = -1;
  const std::string written = test::run_command(
      "cd '" + interop + "' && node write_ros2_bag.mjs '" + log + "' '" + bag + "' 0.20 2>&1",
      &status);
  ASSERT_EQ(status, 0) << written;
  EXPECT_THAT(written, HasSubstr("\"messages\":"));

  const std::string map = test::quoted_source("maps/office_floor.geojson");
  const std::string robot = test::quoted_source("maps/robots/pioneer.json");
  // The bag has no robot.json: the robot must be given.
  const test::CliResult no_robot =
      test::run_lampnav("replay '" + bag + "' --map " + map + " -q --out '" + dir + "/none'");
  EXPECT_EQ(no_robot.status, 2);
  EXPECT_THAT(no_robot.err, HasSubstr("give --robot"));

  const test::CliResult a = test::run_lampnav("replay '" + log + "' -q --out '" + dir + "/a'");
  ASSERT_EQ(a.status, 0) << a.err;
  const test::CliResult b = test::run_lampnav("replay '" + bag + "' --map " + map + " --robot " +
                                              robot + " -q --out '" + dir + "/b'");
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_THAT(b.err, HasSubstr("ceiling camera images from /ceiling_camera/image/compressed"));
  EXPECT_THAT(b.err, HasSubstr("wheel odometry from /odom"));
  const auto ea = read_tum(dir + "/a/estimate.tum"), eb = read_tum(dir + "/b/estimate.tum");
  fs::remove_all(dir);
  ASSERT_GT(ea.size(), 1000u);
  ASSERT_EQ(ea.size(), eb.size());
  double worst = 0;
  for (std::size_t k = 0; k < ea.size(); ++k) {
    ASSERT_EQ(ea[k].t, eb[k].t) << k;
    worst = std::max(worst, std::hypot(ea[k].x - eb[k].x, ea[k].y - eb[k].y));
  }
  std::cout << ea.size() << " estimates; the bag's at most " << worst * 1000
            << " mm from the log's\n";
  EXPECT_LE(worst, 0.001);
}

}  // namespace
}  // namespace lampnav
