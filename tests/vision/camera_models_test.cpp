#include <random>

#include "lampnav/vision/camera_models.hpp"
#include "lampnav_test.hpp"

namespace lampnav::vision {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

RobotDescription pioneer() {
  return read_robot_description(test::source_path("maps/robots/pioneer.json"));
}

TEST(PinholeCamera, PrincipalPointAndKnownProjection) {
  const PinholeCamera cam(*pioneer().find_camera("ceiling_camera"));
  const auto c = cam.project(Vector3d(0, 0, 2.4));
  ASSERT_TRUE(c);
  EXPECT_LT((*c - Vector2d(175.5, 143.5)).norm(), 1e-12);
  // x = 0.25 -> r2 = 0.0625, radial = 1 - 0.12 * 0.0625 + 0.02 * 0.0625^2
  const auto p = cam.project(Vector3d(0.6, 0, 2.4));
  ASSERT_TRUE(p);
  const double radial = 1 - 0.12 * 0.0625 + 0.02 * 0.0625 * 0.0625;
  EXPECT_NEAR(p->x(), 300 * 0.25 * radial + 175.5, 1e-9);
  EXPECT_FALSE(cam.project(Vector3d(0, 0, -1)));
}

// Projection then back-projection returns the ray, over the whole image.
TEST(PinholeCamera, ProjectUnprojectRoundTrip) {
  const PinholeCamera cam(*pioneer().find_camera("ceiling_camera"));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 351), v(0, 287);
  for (int i = 0; i < 2000; ++i) {
    const Vector2d px(u(rng), v(rng));
    const Vector3d ray = cam.unproject(px);
    EXPECT_NEAR(ray.norm(), 1.0, 1e-12);
    const auto back = cam.project(ray * 2.5);
    ASSERT_TRUE(back);
    EXPECT_LT((*back - px).norm(), 1e-6);
  }
}

TEST(FisheyeCamera, RoundTripBeyondNinetyDegrees) {
  const FisheyeCamera cam(*pioneer().find_camera("omni_camera"));
  EXPECT_NEAR(cam.max_theta(), 92.5 * M_PI / 180, 1e-12);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> th(0, cam.max_theta()), ph(-M_PI, M_PI);
  for (int i = 0; i < 2000; ++i) {
    const double t = th(rng), p = ph(rng);
    const Vector3d ray(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
    const auto px = cam.project(3.0 * ray);
    ASSERT_TRUE(px);
    const auto back = cam.unproject(*px);
    ASSERT_TRUE(back);
    EXPECT_LT((*back - ray).norm(), 1e-9) << "theta " << t;
  }
  // Straight up lands on the image centre; 95 degrees off-axis is outside the 185-degree view.
  EXPECT_LT((*cam.project(Vector3d(0, 0, 1)) - Vector2d(511.5, 511.5)).norm(), 1e-12);
  const double t95 = 95 * M_PI / 180;
  EXPECT_FALSE(cam.project(Vector3d(std::sin(t95), 0, std::cos(t95))));
}

TEST(CeilingView, MatchesThePinholeFootprint) {
  const CameraDescription cam = *pioneer().find_camera("ceiling_camera");
  // No distortion: the view along x is (W / fx) * (h - camera height).
  CameraDescription flat = cam;
  flat.pinhole.distortion = {};
  EXPECT_NEAR(ceiling_view_length(flat, 2.7), 352.0 / 300.0 * 2.4, 1e-6);
  // Barrel distortion (k1 < 0) widens the view.
  EXPECT_GT(ceiling_view_length(cam, 2.7), ceiling_view_length(flat, 2.7));
  EXPECT_EQ(ceiling_view_length(cam, 0.2), 0.0);  // ceiling below the camera
}

}  // namespace
}  // namespace lampnav::vision
