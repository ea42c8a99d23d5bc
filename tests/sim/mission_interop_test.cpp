// A simulated mission log, read by the official TypeScript MCAP reader (@mcap/core).

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav_test.hpp"

namespace lampnav::sim {
namespace {

using ::testing::HasSubstr;

TEST(MissionInterop, OfficialReaderOpensASimulatedMission) {
  ASSERT_TRUE(std::filesystem::exists(test::source_path("tests/interop/node_modules/@mcap/core")))
      << "@mcap/core is not installed: run `make test`, which installs it";
  const std::string text = test::slurp(test::source_path("maps/office_floor.geojson"));
  const auto map = graph::parse_map(text, "office");
  const auto robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  Scenario s = make_route_scenario(map.map, text, robot, "D1", "D2", 9);
  s.frame_drop_probability = 0;
  s.kidnaps.push_back({5.0, std::nullopt});
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("lampnav_mission_interop_" + std::to_string(::getpid()) + ".mcap"))
                               .string();
  const RecordStats st = record_mission(s, path);
  const std::string cmd =
      "cd '" + test::source_path("tests/interop") + "' && node read_mcap.mjs '" + path + "' 2>&1";
  int status = -1;
  const std::string out = test::run_command(cmd, &status);
  ASSERT_EQ(status, 0) << out;
  const std::string wheels = std::to_string(st.wheel_messages);
  EXPECT_THAT(
      out, HasSubstr(R"("/wheels":{"schema":"lampnav.WheelOdometry","encoding":"json","count":)" +
                     wheels + "}"));
  EXPECT_THAT(
      out,
      HasSubstr(R"("/truth/pose":{"schema":"foxglove.PoseInFrame","encoding":"json","count":)" +
                wheels + "}"));
  EXPECT_THAT(
      out,
      HasSubstr(
          R"("/ceiling_camera/image":{"schema":"foxglove.CompressedImage","encoding":"json","count":)" +
          std::to_string(st.ceiling_frames) + "}"));
  EXPECT_THAT(
      out,
      HasSubstr(
          R"("/omni_camera/image":{"schema":"foxglove.CompressedImage","encoding":"json","count":)" +
          std::to_string(st.omni_frames) + "}"));
  EXPECT_THAT(out, HasSubstr(R"("/events":{"schema":"lampnav.Event")"));
  EXPECT_THAT(out,
              HasSubstr(R"("/commands":{"schema":"lampnav.Command","encoding":"json","count":2})"));
  EXPECT_THAT(out, HasSubstr(R"("logTimeOrdered":true)"));
  EXPECT_THAT(out, HasSubstr(R"({"name":"robot.json","mediaType":"application/json")"));
  EXPECT_THAT(out, HasSubstr(R"({"name":"map.geojson","mediaType":"application/geo+json","size":)" +
                             std::to_string(text.size()) + "}"));
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace lampnav::sim
