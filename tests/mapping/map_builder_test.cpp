// What `map build` makes of drives that cannot give a map: every frame dark, a robot that never
// moves. A clear failure naming the log, never a map that claims what the drive did not see.

#include "lampnav/mapping/map_builder.hpp"

#include <gtest/gtest.h>

#include "lampnav/core/error.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav_test.hpp"

namespace lampnav::mapping {
namespace {

using ::testing::HasSubstr;

// A log of `seconds` of ceiling frames at 10 Hz showing `image`, and wheels moving at `speed`.
io::MissionLog log_of(const Image8& image, double seconds, double speed) {
  io::MissionLog log;
  const std::string png = io::encode_png(image);
  for (int k = 0; k <= seconds * 50; ++k) {
    const Stamp t = stamp_from_seconds(k * 0.02);
    log.wheels.push_back({t, {t, speed * k * 0.02, speed * k * 0.02}});
    if (k % 5 == 0) log.ceiling_images.push_back({t, {t, "ceiling_camera", "png", png}});
  }
  return log;
}

// A 352 x 288 frame with one lamp (1.2 x 0.3 m at 2.4 m: 150 x 38 px) in the middle.
Image8 frame_with_a_lamp() {
  Image8 img(352, 288, 20);
  for (int y = 125; y < 163; ++y)
    for (int x = 101; x < 251; ++x) img.at(x, y) = 240;
  return img;
}

const RobotDescription& robot() {
  static const RobotDescription r =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  return r;
}

TEST(MapBuilder, EveryFrameDarkIsAFailureNotAnEmptyMap) {
  const io::MissionLog log = log_of(Image8(352, 288, 10), 20, 0.5);
  try {
    build_map(log, "dark.mcap", robot(), {}, {});
    FAIL() << "built a map from dark frames";
  } catch (const JobFailed& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("dark.mcap"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("no lamp was seen whole"));
  }
}

// Lamps only ever at the edge of the view, cut by the border (a wide corridor's two rows, the robot
// down the middle between them): the failure says why, and how to drive.
TEST(MapBuilder, LampsOnlyEverCutByTheBorderSayHowToDrive) {
  Image8 img(352, 288, 20);
  for (int y = 0; y < 19; ++y)  // a 150 x 38 px lamp across the top edge, half of it in view
    for (int x = 101; x < 251; ++x) img.at(x, y) = 240;
  try {
    build_map(log_of(img, 20, 0.5), "beside.mcap", robot(), {}, {});
    FAIL() << "built a map from lamps never seen whole";
  } catch (const JobFailed& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("beside.mcap"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("only lamps cut by the image's border"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("drive under the rows of lamps"));
  }
}

TEST(MapBuilder, ARobotThatNeverMovesIsAFailure) {
  const io::MissionLog log = log_of(frame_with_a_lamp(), 20, 0.0);
  try {
    build_map(log, "still.mcap", robot(), {}, {});
    FAIL() << "built a map without moving";
  } catch (const JobFailed& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("still.mcap"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("moved 0"));
  }
}

TEST(MapBuilder, NoWheelsOrNoCeilingFramesAreBadInput) {
  io::MissionLog log = log_of(frame_with_a_lamp(), 5, 0.5);
  io::MissionLog no_wheels = log;
  no_wheels.wheels.clear();
  EXPECT_THROW(build_map(no_wheels, "w.mcap", robot(), {}, {}), InputError);
  io::MissionLog no_frames = log;
  no_frames.ceiling_images.clear();
  EXPECT_THROW(build_map(no_frames, "f.mcap", robot(), {}, {}), InputError);
  RobotDescription blind = robot();
  blind.cameras.clear();
  EXPECT_THROW(build_map(log, "b.mcap", blind, {}, {}), InputError);
}

}  // namespace
}  // namespace lampnav::mapping
