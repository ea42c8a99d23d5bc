#include <Eigen/Geometry>

#include "lampnav/core/error.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav_test.hpp"

namespace lampnav {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

TEST(RobotDescription, ReadsBundledPioneer) {
  const RobotDescription r = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  EXPECT_EQ(r.name, "pioneer-2at");
  EXPECT_DOUBLE_EQ(r.semi_axis, 0.20);
  ASSERT_EQ(r.cameras.size(), 2u);
  const CameraDescription* ceiling = r.find_camera("ceiling_camera");
  ASSERT_NE(ceiling, nullptr);
  EXPECT_EQ(ceiling->model, CameraModelKind::pinhole);
  EXPECT_EQ(ceiling->width, 352);
  EXPECT_DOUBLE_EQ(ceiling->pinhole.distortion[0], -0.12);
  const CameraDescription* omni = r.find_camera("omni_camera");
  ASSERT_NE(omni, nullptr);
  EXPECT_EQ(omni->model, CameraModelKind::pajdla_bakstein);
  EXPECT_DOUBLE_EQ(omni->fisheye.fov_deg, 185.0);
  EXPECT_DOUBLE_EQ(omni->mount.xyz.z(), 1.80);
}

TEST(RobotDescription, WriteReadsBackIdentically) {
  const RobotDescription r = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  const RobotDescription back = parse_robot_description(to_robot_json(r), "written");
  EXPECT_EQ(to_robot_json(back), to_robot_json(r));
}

TEST(RobotDescription, MountRotationIsZYX) {
  Mount m;
  m.rpy = {0.0, 0.0, M_PI / 2};
  const Eigen::Vector3d x = m.rotation() * Eigen::Vector3d::UnitX();
  EXPECT_LT((x - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  m.rpy = {0.1, 0.2, 0.3};
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  EXPECT_LT((m.rotation() - expected).norm(), 1e-12);
}

struct BadRobot {
  const char* name;
  std::string json;
  const char* place;
  const char* field;
  const char* message;
};

class BadRobotTest : public ::testing::TestWithParam<BadRobot> {};

TEST_P(BadRobotTest, RefusedNamingPlaceAndField) {
  const BadRobot& c = GetParam();
  try {
    parse_robot_description(c.json, "robot.json");
    FAIL() << "accepted " << c.json;
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, "robot.json");
    EXPECT_EQ(e.where().place, c.place);
    EXPECT_EQ(e.where().field, c.field);
    EXPECT_THAT(e.message(), HasSubstr(c.message));
  }
}

constexpr const char* kCam =
    R"("name": "c", "model": "pinhole", "width": 352, "height": 288, "fx": 300, "fy": 300,
       "cx": 175.5, "cy": 143.5, "mount": {"xyz": [0,0,0.3], "rpy": [0,0,0]})";

INSTANTIATE_TEST_SUITE_P(
    Refusals, BadRobotTest,
    ::testing::Values(
        BadRobot{"not_json", "{\"name\": ", "line 1, column 10", "", "not valid JSON"},
        BadRobot{"misspelt_top", R"({"name": "r", "wheels": {"semi_axis": 0.2}, "camera": []})", "",
                 "camera", "unknown key"},
        BadRobot{"misspelt_wheels", R"({"name": "r", "wheels": {"semiaxis": 0.2}})", "",
                 "wheels.semiaxis", "unknown key"},
        BadRobot{"negative_axis", R"({"name": "r", "wheels": {"semi_axis": -0.2}})", "",
                 "wheels.semi_axis", "greater than zero"},
        BadRobot{
            "unknown_model",
            R"({"name": "r", "wheels": {"semi_axis": 0.2}, "cameras": [{"name": "c", "model": "fisheye", "width": 1, "height": 1, "mount": {"xyz": [0,0,0], "rpy": [0,0,0]}}]})",
            "camera 0 (c)", "model", "unknown camera model"},
        BadRobot{"fisheye_key_on_pinhole",
                 (std::string(R"({"name": "r", "wheels": {"semi_axis": 0.2}, "cameras": [{)") +
                  kCam + R"(, "fov_deg": 90}]})"),
                 "camera 0 (c)", "fov_deg", "unknown key"},
        BadRobot{
            "zero_width",
            R"({"name": "r", "wheels": {"semi_axis": 0.2}, "cameras": [{"name": "c", "model": "pinhole", "width": 0, "height": 288, "fx": 300, "fy": 300, "cx": 1, "cy": 1, "mount": {"xyz": [0,0,0], "rpy": [0,0,0]}}]})",
            "camera 0 (c)", "width", "pixel count"},
        BadRobot{"short_distortion",
                 (std::string(R"({"name": "r", "wheels": {"semi_axis": 0.2}, "cameras": [{)") +
                  kCam + R"(, "distortion": [0.1, 0.0]}]})"),
                 "camera 0 (c)", "distortion", "expected 5 elements"}),
    [](const auto& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace lampnav
