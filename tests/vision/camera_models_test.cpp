#include <Eigen/LU>
#include <opencv2/calib3d.hpp>
#include <random>

#include "lampnav/core/error.hpp"
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

TEST(PinholeCamera, JacobiansMatchNumericalDerivatives) {
  const PinholeCamera cam(*pioneer().find_camera("ceiling_camera"));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> xy(-0.6, 0.6), z(1.0, 4.0);
  for (int i = 0; i < 500; ++i) {
    const Vector2d n(xy(rng), xy(rng));
    const auto Jd =
        test::numerical_jacobian<2, 2>([&](const Vector2d& q) { return cam.distort(q); }, n);
    EXPECT_LT((cam.distort_jacobian(n) - Jd).norm(), 1e-7);
    const Vector3d p(xy(rng) * 2, xy(rng) * 2, z(rng));
    const auto Jp =
        test::numerical_jacobian<2, 3>([&](const Vector3d& q) { return *cam.project(q); }, p);
    EXPECT_LT((cam.project_jacobian(p) - Jp).norm(), 1e-5 * (1 + Jp.norm()));
    // Pixel <-> undistorted normalized coordinates round trip.
    const Vector2d px = cam.pixel_of_normalized(n * 0.5);
    EXPECT_LT((cam.normalized_of_pixel(px) - n * 0.5).norm(), 1e-10);
  }
}

TEST(PinholeCamera, JacobianWithTangentialDistortion) {
  CameraDescription d = *pioneer().find_camera("ceiling_camera");
  d.pinhole.distortion = {-0.2, 0.05, 0.003, -0.002, 0.01};
  const PinholeCamera cam(d);
  for (const Vector2d& n : {Vector2d(0.3, -0.2), Vector2d(-0.45, 0.1), Vector2d(0, 0)}) {
    const auto Jd =
        test::numerical_jacobian<2, 2>([&](const Vector2d& q) { return cam.distort(q); }, n);
    EXPECT_LT((cam.distort_jacobian(n) - Jd).norm(), 1e-7);
    EXPECT_LT((cam.undistort(cam.distort(n)) - n).norm(), 1e-12);
  }
}

TEST(FisheyeCamera, JacobianMatchesNumericalDerivative) {
  CameraDescription d = *pioneer().find_camera("omni_camera");
  d.fisheye.beta = 1.05;
  const FisheyeCamera cam(d);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> th(0.05, cam.max_theta() - 0.01), ph(-M_PI, M_PI),
      dist(1.0, 12.0);
  for (int i = 0; i < 500; ++i) {
    const double t = th(rng), p = ph(rng);
    const Vector3d pt =
        dist(rng) * Vector3d(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
    const auto J = test::numerical_jacobian<2, 3>(
        [&](const Vector3d& q) { return *cam.project(q); }, pt, 1e-7);
    EXPECT_LT((cam.project_jacobian(pt) - J).norm(), 1e-4 * (1 + J.norm())) << "theta " << t;
  }
}

// A fisheye calibrated with OpenCV (cv::fisheye), ROS (equidistant) or Kalibr (pinhole-equi).
CameraDescription kannala_brandt(double fx = 283.0, double fy = 285.0) {
  CameraDescription d;
  d.name = "omni_camera";
  d.model = CameraModelKind::kannala_brandt;
  d.width = 1024;
  d.height = 1024;
  d.fisheye.f = fx;
  d.fisheye.beta = fy / fx;
  d.fisheye.u0 = 511.2;
  d.fisheye.v0 = 509.8;
  d.fisheye.k = {0.021, -0.0064, 0.0009, -0.00011};
  d.fisheye.fov_deg = 180;
  return d;
}

// Our projection against OpenCV's own (cv::fisheye::projectPoints) over the whole image: every
// 8th pixel unprojected to a ray, projected by both.
TEST(KannalaBrandt, AgreesWithOpenCvsFisheyeOverTheWholeImage) {
  const CameraDescription d = kannala_brandt();
  const FisheyeCamera cam(d);
  const cv::Matx33d K(d.fisheye.f, 0, d.fisheye.u0, 0, d.fisheye.f * d.fisheye.beta, d.fisheye.v0,
                      0, 0, 1);
  const cv::Vec4d D(d.fisheye.k[0], d.fisheye.k[1], d.fisheye.k[2], d.fisheye.k[3]);
  std::vector<cv::Point3d> points;
  std::vector<Vector2d> ours;
  for (int v = 0; v < d.height; v += 8)
    for (int u = 0; u < d.width; u += 8) {
      const auto ray = cam.unproject(Vector2d(u, v));
      // OpenCV's model sees in front of the lens only (Z > 0).
      if (!ray || ray->z() < 0.02) continue;
      points.emplace_back(2 * ray->x(), 2 * ray->y(), 2 * ray->z());
      ours.push_back(*cam.project(2 * *ray));
      EXPECT_LT((ours.back() - Vector2d(u, v)).norm(), 1e-6) << u << ", " << v;
    }
  ASSERT_GT(points.size(), 9000u);
  std::vector<cv::Point2d> theirs;
  cv::fisheye::projectPoints(points, theirs, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    worst = std::max(worst, (ours[i] - Vector2d(theirs[i].x, theirs[i].y)).norm());
  std::cout << points.size() << " pixels, worst difference from OpenCV " << worst << " px\n";
  EXPECT_LT(worst, 0.01);
}

TEST(KannalaBrandt, JacobianMatchesNumericalDerivativeAndRoundTrips) {
  const FisheyeCamera cam(kannala_brandt());
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> th(0.05, cam.max_theta() - 0.01), ph(-M_PI, M_PI),
      dist(1.0, 12.0);
  for (int i = 0; i < 500; ++i) {
    const double t = th(rng), p = ph(rng);
    const Vector3d ray(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
    const Vector3d pt = dist(rng) * ray;
    const auto J = test::numerical_jacobian<2, 3>(
        [&](const Vector3d& q) { return *cam.project(q); }, pt, 1e-7);
    EXPECT_LT((cam.project_jacobian(pt) - J).norm(), 1e-4 * (1 + J.norm())) << "theta " << t;
    const auto back = cam.unproject(*cam.project(pt));
    ASSERT_TRUE(back);
    EXPECT_LT((*back - ray).norm(), 1e-9);
  }
  // A model whose radius folds back ends its field of view there, not at fov_deg.
  CameraDescription folding = kannala_brandt();
  folding.fisheye.k = {-0.3, 0, 0, 0};
  const FisheyeCamera f(folding);
  EXPECT_NEAR(f.max_theta(), std::sqrt(1 / 0.9), 1e-3);  // where 1 - 0.9 theta^2 = 0
  EXPECT_GT(f.radius_derivative(f.max_theta()), 0);
}

TEST(KannalaBrandt, RobotJsonRoundTrip) {
  RobotDescription r = pioneer();
  r.cameras[1] = kannala_brandt();
  const RobotDescription back = parse_robot_description(to_robot_json(r), "written");
  const CameraDescription& c = *back.find_camera("omni_camera");
  EXPECT_EQ(c.model, CameraModelKind::kannala_brandt);
  EXPECT_DOUBLE_EQ(c.fisheye.f, 283.0);
  EXPECT_DOUBLE_EQ(c.fisheye.f * c.fisheye.beta, 285.0);
  EXPECT_EQ(c.fisheye.k, r.cameras[1].fisheye.k);
  EXPECT_EQ(to_robot_json(back), to_robot_json(r));
  // Its own fields only: a Pajdla-Bakstein field is an error naming it.
  std::string text = to_robot_json(r);
  text.replace(text.find("\"k\""), 3, "\"a\": 1, \"k\"");
  try {
    parse_robot_description(text, "bad.json");
    ADD_FAILURE() << "read an unknown key";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("a: unknown key"));
  }
}

// A wide-angle webcam calibrated with cv::fisheye as the ceiling camera: the ceiling pipeline's
// model (PinholeCamera, through the normalized plane) against OpenCV's own distortion
// (cv::fisheye::distortPoints) over the whole image, and its undistortion against
// cv::fisheye::undistortPoints.
CameraDescription wide_ceiling_camera() {
  CameraDescription d = kannala_brandt(345.0, 343.5);
  d.name = "ceiling_camera";
  d.width = 640;
  d.height = 480;
  d.fisheye.u0 = 321.4;
  d.fisheye.v0 = 238.7;
  d.fisheye.k = {0.031, -0.012, 0.0021, -0.00017};
  return d;
}

TEST(KannalaBrandtCeiling, AgreesWithOpenCvsFisheyeOverTheWholeImage) {
  const CameraDescription d = wide_ceiling_camera();
  const PinholeCamera cam(d);
  EXPECT_TRUE(cam.equidistant());
  const PinholeParameters k = PinholeCamera::intrinsics(d);
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  const cv::Vec4d D(d.fisheye.k[0], d.fisheye.k[1], d.fisheye.k[2], d.fisheye.k[3]);
  std::vector<cv::Point2d> normalized, pixels;
  std::vector<Vector2d> ours_px, ours_n;
  for (int v = 0; v < d.height; v += 4)
    for (int u = 0; u < d.width; u += 4) {
      const Vector2d n = cam.normalized_of_pixel(Vector2d(u, v));
      normalized.emplace_back(n.x(), n.y());
      pixels.emplace_back(u, v);
      ours_n.push_back(n);
      ours_px.push_back(cam.pixel_of_normalized(n));
      EXPECT_LT((ours_px.back() - Vector2d(u, v)).norm(), 1e-6) << u << ", " << v;
    }
  std::vector<cv::Point2d> their_px, their_n;
  cv::fisheye::distortPoints(normalized, their_px, K, D);
  cv::fisheye::undistortPoints(pixels, their_n, K, D);
  double worst_px = 0, worst_n = 0;
  for (std::size_t i = 0; i < normalized.size(); ++i) {
    worst_px = std::max(worst_px, (ours_px[i] - Vector2d(their_px[i].x, their_px[i].y)).norm());
    // OpenCV's undistortion iterates to its own tolerance: compared in pixels at the image.
    worst_n = std::max(worst_n, k.fx * (ours_n[i] - Vector2d(their_n[i].x, their_n[i].y)).norm());
  }
  std::cout << normalized.size() << " pixels, worst difference from OpenCV " << worst_px
            << " px distorting, " << worst_n << " px undistorting\n";
  EXPECT_LT(worst_px, 0.01);
  EXPECT_LT(worst_n, 0.01);
  // Its corner is 65 degrees off the axis (a normalized radius over 2; the bundled webcam's, 39).
  EXPECT_GT(cam.corner_radius(), 2.0);
}

TEST(KannalaBrandtCeiling, JacobiansMatchNumericalDerivatives) {
  const PinholeCamera cam(wide_ceiling_camera());
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int i = 0; i < 300; ++i) {
    const Vector2d n(u(rng), u(rng));
    const Eigen::Matrix2d Jn =
        test::numerical_jacobian<2, 2>([&](const Vector2d& q) { return cam.distort(q); }, n);
    EXPECT_LT((cam.distort_jacobian(n) - Jn).norm(), 1e-6 * (1 + Jn.norm())) << n.transpose();
    const Vector3d p(n.x() * 2.4, n.y() * 2.4, 2.4);
    const auto J =
        test::numerical_jacobian<2, 3>([&](const Vector3d& q) { return *cam.project(q); }, p, 1e-7);
    EXPECT_LT((cam.project_jacobian(p) - J).norm(), 1e-4 * (1 + J.norm())) << n.transpose();
    EXPECT_LT((cam.undistort(cam.distort(n)) - n).norm(), 1e-12);
  }
  // A pixel spans more of the normalized plane off the axis: the covariance of a pixel's error
  // there is the one the numerical derivative of the pixel -> normalized mapping gives, several
  // times the centre's along the radius.
  const double centre = cam.normalized_covariance(Vector2d::Zero(), 1.0).trace();
  const Vector2d edge(1.8, 0.0);
  const Eigen::Matrix2d far = cam.normalized_covariance(edge, 1.0);
  const Eigen::Matrix2d Jn = test::numerical_jacobian<2, 2>(
      [&](const Vector2d& px) { return cam.normalized_of_pixel(px); },
      cam.pixel_of_normalized(edge));
  EXPECT_LT((far - Jn * Jn.transpose()).norm(), 1e-6 * far.norm());
  EXPECT_GT(far(0, 0), 4 * centre / 2);
  // Past its field of view (or 89 degrees) it projects nothing.
  EXPECT_FALSE(cam.project(Vector3d(100, 0, 1)));
  EXPECT_TRUE(cam.project(Vector3d(2, 0, 1)));
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
