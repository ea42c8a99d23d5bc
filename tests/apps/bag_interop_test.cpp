// A ROS 2 bag written by independent code replays as the mission it came from. The corridor run
// is recorded by `lampnav sim`; tests/interop/write_ros2_bag.mjs writes it again as a ROS 2 bag
// with the official TypeScript MCAP writer (@mcap/core), Foxglove's ROS 2 CDR serializer
// (@foxglove/rosmsg2-serialization) and ROS 2 Humble's message definitions
// (@foxglove/rosmsg-msgs-common); `lampnav replay` of the bag gives the log's estimates, and so
// does the same bag moved into rosbag2's sqlite3 storage.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_support.hpp"
#include "lampnav/io/mcap.hpp"
#include "lampnav_test.hpp"
#include "rosbag2_writer.hpp"

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

  // The same bag in rosbag2's sqlite3 storage (ROS 2's default up to Humble), as `ros2 bag
  // record --max-bag-size` splits it, its second file compressed message by message: read
  // through its directory, it replays to the same estimates.
  const std::string db3 = dir + "/corridor_db3";
  fs::create_directories(db3);
  {
    const io::McapFile f = io::read_mcap(bag);
    const std::size_t half = f.messages.size() / 2;
    for (int part = 0; part < 2; ++part) {
      test::Rosbag2SqliteWriter w(db3 + "/corridor_db3_" + std::to_string(part) + ".db3");
      w.copy(f, part == 0 ? 0 : half, part == 0 ? half : f.messages.size(),
             [&](const io::McapMessage&) { return part == 1; });
    }
    std::ofstream(db3 + "/metadata.yaml")
        << "rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: sqlite3\n"
           "  relative_file_paths:\n    - corridor_db3_0.db3\n    - corridor_db3_1.db3\n"
           "  compression_format: zstd\n  compression_mode: MESSAGE\n";
  }
  const test::CliResult c = test::run_lampnav("replay '" + db3 + "' --map " + map + " --robot " +
                                              robot + " -q --out '" + dir + "/c'");
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_THAT(c.err, HasSubstr("rosbag2 bag (sqlite3 storage), 2 files"));
  const auto ec = read_tum(dir + "/c/estimate.tum");
  fs::remove_all(dir);
  ASSERT_EQ(ec.size(), eb.size());
  for (std::size_t k = 0; k < eb.size(); ++k) {
    ASSERT_EQ(ec[k].t, eb[k].t) << k;
    ASSERT_EQ(ec[k].x, eb[k].x) << k;
    ASSERT_EQ(ec[k].y, eb[k].y) << k;
  }
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
