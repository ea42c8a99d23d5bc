// Ceiling geometry, chi-square gates and the pose measurement on synthetic detections.

#include <random>

#include <Eigen/LU>

#include "lampnav/fusion/ceiling_geometry.hpp"
#include "lampnav/fusion/ceiling_pipeline.hpp"
#include "lampnav/fusion/chi_square.hpp"
#include "lampnav/fusion/pose_from_lamps.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

CameraDescription ceiling_camera(Eigen::Vector3d rpy = Vector3d::Zero()) {
  CameraDescription c = *read_robot_description(test::source_path("maps/robots/pioneer.json"))
                             .find_camera("ceiling_camera");
  c.mount.rpy = rpy;
  return c;
}

TEST(CeilingGeometry, JacobiansMatchNumericalDerivatives) {
  for (const Vector3d& rpy : {Vector3d(0, 0, 0), Vector3d(0.05, -0.08, 0.7)}) {
    const CeilingGeometry g(ceiling_camera(rpy));
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < 200; ++i) {
      const Vector3d lamp(u(rng), u(rng), 2.7);
      const Vector3d pose(u(rng) * 0.5, u(rng) * 0.5, u(rng) * M_PI);
      Eigen::Matrix<double, 2, 3> J;
      const auto n = g.predict(Pose2(pose.x(), pose.y(), pose.z()), lamp, &J);
      ASSERT_TRUE(n);
      const auto Jn = test::numerical_jacobian<2, 3>(
          [&](const Vector3d& p) { return *g.predict(Pose2(p.x(), p.y(), p.z()), lamp); }, pose);
      EXPECT_LT((J - Jn).norm(), 1e-6);
      // base_point inverts the projection and its Jacobian is right.
      Eigen::Matrix2d Jb;
      const auto b = g.base_point(*n, 2.7, &Jb);
      ASSERT_TRUE(b);
      const Pose2 robot(pose.x(), pose.y(), pose.z());
      EXPECT_LT((robot.transform_from(*b) - lamp.head<2>()).norm(), 1e-9);
      const auto Jbn = test::numerical_jacobian<2, 2>(
          [&](const Vector2d& q) { return *g.base_point(q, 2.7); }, *n);
      EXPECT_LT((Jb - Jbn).norm(), 1e-6);
    }
  }
}

TEST(ChiSquare, KnownQuantiles) {
  EXPECT_NEAR(chi_square_quantile(0.99, 1), 6.6349, 1e-4);
  EXPECT_NEAR(chi_square_quantile(0.99, 2), 9.2103, 1e-4);
  EXPECT_NEAR(chi_square_quantile(0.99, 3), 11.3449, 1e-4);
  EXPECT_NEAR(chi_square_quantile(0.95, 3), 7.8147, 1e-4);
  EXPECT_NEAR(chi_square_cdf(chi_square_quantile(0.9, 5), 5), 0.9, 1e-9);
}

graph::Lamp rect(const char* id, double x, double y, double yaw) {
  graph::Lamp l;
  l.id = LampId(id);
  l.xyz = {x, y, 2.7};
  l.yaw = yaw;
  l.length = 1.2;
  l.width = 0.3;
  return l;
}

// A detection of `lamp` from `pose` with normalized noise `sigma` (and axis noise).
// `sigma` in the normalized plane, or in pixels through `lens` when given.
vision::LampDetection see(const CeilingGeometry& g, const Pose2& pose, const graph::Lamp& lamp,
                          std::mt19937& rng, double sigma, double axis_sigma,
                          const vision::PinholeCamera* lens = nullptr) {
  std::normal_distribution<double> n(0, 1);
  vision::LampDetection d;
  d.centre = *g.predict(pose, lamp.xyz);
  if (lens)
    d.centre = lens->normalized_of_pixel(lens->pixel_of_normalized(d.centre) +
                                         sigma * Vector2d(n(rng), n(rng)));
  else
    d.centre += sigma * Vector2d(n(rng), n(rng));
  const Vector3d e(std::cos(lamp.yaw) * 0.05, std::sin(lamp.yaw) * 0.05, 0);
  const Vector2d a = *g.predict(pose, lamp.xyz + e) - *g.predict(pose, lamp.xyz - e);
  d.orientation = std::atan2(a.y(), a.x()) + axis_sigma * n(rng);
  return d;
}

TEST(PoseFromLamps, OneRectangleGivesThePoseOnTheBranchOfThePrediction) {
  const CeilingGeometry g(ceiling_camera());
  const graph::Lamp lamp = rect("L1", 3.0, 1.0, 0.3);
  const Pose2 truth(2.6, 1.2, 0.5);
  std::mt19937 rng(1);
  const auto d = see(g, truth, lamp, rng, 0, 0);
  PoseMeasurementOptions o;
  for (double off : {0.0, 0.3, -1.2}) {
    const auto m = measure_pose(g, vision::PinholeCamera(ceiling_camera()), {{&lamp, d}},
                                Pose2(2.7, 1.1, 0.5 + off), Stamp{}, o);
    ASSERT_TRUE(m);
    EXPECT_THAT(m->pose, test::IsNearPose(truth, 1e-9, 1e-9));
  }
  // Predicted facing the other way: the rectangle's other branch.
  const auto flipped = measure_pose(g, vision::PinholeCamera(ceiling_camera()), {{&lamp, d}},
                                    Pose2(2.6, 1.2, 0.5 + M_PI), Stamp{}, o);
  ASSERT_TRUE(flipped);
  EXPECT_NEAR(std::fabs(wrap_angle(flipped->pose.yaw() - truth.yaw())), M_PI, 1e-9);
}

// The reported covariance is the spread of the measurement under the modelled pixel noise (in
// pixels, through the lens: a pixel spans more of the normalized plane towards the image's edge).
TEST(PoseFromLamps, CovarianceMatchesMonteCarloSpread) {
  const CeilingGeometry g(ceiling_camera());
  const vision::PinholeCamera lens(ceiling_camera());
  const graph::Lamp a = rect("A", 3.0, 1.0, 0.0), b = rect("B", 5.25, 1.0, 0.0);
  const Pose2 truth(4.0, 1.1, 0.1);
  PoseMeasurementOptions o;
  o.tilt_sigma = 0;    // the simulation below has no tilt
  o.map_sigma = 1e-6;  // nor survey error
  std::mt19937 rng(3);
  const double sp = o.pixel_sigma;
  Eigen::Matrix3d reported = Eigen::Matrix3d::Zero(), spread = Eigen::Matrix3d::Zero();
  const int n = 4000;
  std::string why;
  int refused = 0;
  for (int i = 0; i < n; ++i) {
    const auto m = measure_pose(g, lens,
                                {{&a, see(g, truth, a, rng, sp, o.orientation_sigma, &lens)},
                                 {&b, see(g, truth, b, rng, sp, o.orientation_sigma, &lens)}},
                                truth, Stamp{}, o, &why);
    if (!m) {  // the consistency gate refuses its tail of honest frames (p = 1e-4)
      ++refused;
      continue;
    }
    const Vector3d e(m->pose.x() - truth.x(), m->pose.y() - truth.y(),
                     wrap_angle(m->pose.yaw() - truth.yaw()));
    spread += e * e.transpose() / n;
    reported += m->covariance / n;
  }
  EXPECT_LE(refused, 4);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(spread(i, i), reported(i, i), 0.1 * reported(i, i)) << i;
}

// One round lamp places the robot for a given heading: the measurement sits at the predicted
// heading, on the line of poses that see the lamp where it was seen (the robot turned about the
// lamp), and its information is the lamp's two degrees of freedom: none along that line, the
// pixel noise's across it.
TEST(PoseFromLamps, OneRoundLampPlacesTheRobotForTheHeading) {
  const CeilingGeometry g(ceiling_camera());
  const vision::PinholeCamera lens(ceiling_camera());
  graph::Lamp disc = rect("D", 3, 1, 0);
  disc.shape = graph::LampShape::disc;
  disc.width = disc.length = 0.5;
  const Pose2 truth(2.7, 1.3, 0.4);
  std::mt19937 rng(4);
  const vision::LampDetection d = see(g, truth, disc, rng, 0, 0);
  const auto base = g.base_point(d.centre, disc.xyz.z());
  ASSERT_TRUE(base);
  for (double off : {0.0, 0.05, -0.3}) {
    const Pose2 predicted(2.5, 1.6, truth.yaw() + off);
    const auto m = measure_pose(g, lens, {{&disc, d}}, predicted, Stamp{}, {});
    ASSERT_TRUE(m);
    EXPECT_FALSE(m->heading_measured);
    EXPECT_NEAR(m->pose.yaw(), predicted.yaw(), 1e-12);
    // The robot at the predicted heading that sees the lamp there: the truth turned about it.
    EXPECT_LT((m->pose.transform_from(*base) - disc.xyz.head<2>()).norm(), 1e-9) << off;
    if (off == 0.0) {
      EXPECT_THAT(m->pose, test::IsNearPose(truth, 1e-9, 1e-9));
    }
    // Turning about the lamp costs no information; moving off it does. Both moves take the
    // robot 10 cm: turning by 10 cm over the lever arm to the lamp, or stepping towards it.
    const Matrix3d info = m->covariance.inverse();
    const Vector2d lever = m->pose.translation() - disc.xyz.head<2>();
    const double turn = 0.1 / lever.norm();
    const Vector3d about(-lever.y() * turn, lever.x() * turn, turn);
    const Vector3d towards(-0.1 * lever.x() / lever.norm(), -0.1 * lever.y() / lever.norm(), 0);
    EXPECT_LT(about.dot(info * about), 1e-2) << off;
    EXPECT_GT(towards.dot(info * towards), 9) << off;  // 10 cm is more than 3 sigmas
  }
  // Many frames of pixel noise at the true heading: the position spreads as reported.
  PoseMeasurementOptions o;
  o.tilt_sigma = 0;
  o.map_sigma = 1e-6;
  const int n = 3000;
  Eigen::Matrix2d spread = Eigen::Matrix2d::Zero(), reported = Eigen::Matrix2d::Zero();
  for (int i = 0; i < n; ++i) {
    const auto m = measure_pose(
        g, lens, {{&disc, see(g, truth, disc, rng, o.pixel_sigma, 0, &lens)}}, truth, Stamp{}, o);
    ASSERT_TRUE(m);
    const Vector2d e = m->pose.translation() - truth.translation();
    spread += e * e.transpose() / n;
    // The position's covariance for the heading given: the information's position block.
    const Matrix3d info = m->covariance.inverse();
    reported += info.topLeftCorner<2, 2>().inverse() / n;
  }
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(spread(i, i), reported(i, i), 0.1 * reported(i, i)) << i;
}

TEST(PoseFromLamps, RefusesWhatCannotGiveAPose) {
  const CeilingGeometry g(ceiling_camera());
  graph::Lamp disc = rect("D", 3, 1, 0);
  disc.shape = graph::LampShape::disc;
  disc.width = disc.length = 0.5;
  std::mt19937 rng(1);
  const Pose2 truth(3.1, 1.0, 0.2);
  std::string why;
  PoseMeasurementOptions no_point;
  no_point.round_lamp_position = false;
  EXPECT_FALSE(measure_pose(g, vision::PinholeCamera(ceiling_camera()),
                            {{&disc, see(g, truth, disc, rng, 0, 0)}}, truth, Stamp{}, no_point,
                            &why));
  EXPECT_EQ(why, "one round lamp does not give the heading");
  // Two lamps labelled the wrong way round disagree.
  const graph::Lamp a = rect("A", 3.0, 1.0, 0.0), b = rect("B", 4.2, 1.9, 1.0);
  EXPECT_FALSE(measure_pose(g, vision::PinholeCamera(ceiling_camera()),
                            {{&a, see(g, truth, b, rng, 0, 0)}, {&b, see(g, truth, a, rng, 0, 0)}},
                            truth, Stamp{}, {}, &why));
  EXPECT_THAT(why, testing::HasSubstr("mislabelled"));
  EXPECT_FALSE(
      measure_pose(g, vision::PinholeCamera(ceiling_camera()), {}, truth, Stamp{}, {}, &why));
}

}  // namespace
}  // namespace lampnav::fusion

namespace lampnav::fusion {
namespace {

// Lamps 2.25 m apart along a corridor: a confident prediction labels, a lost one does not guess.
TEST(LampLabeller, AcceptsOnlyALoneLampInTheGate) {
  const std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  const graph::TopologicalMap map = graph::parse_map(geojson, "office_floor.geojson").map;
  const CameraDescription cam = ceiling_camera();
  const LampLabeller labeller(map, cam);
  const CeilingGeometry g(cam);
  const graph::Lamp& lamp = *map.find_lamp(LampId("C1-L4"));
  const Pose2 truth(lamp.xyz.x() - 0.3, lamp.xyz.y() + 0.1, 0.0);
  std::mt19937 rng(1);
  const vision::LampDetection d = see(g, truth, lamp, rng, 0, 0);
  const Pose2 predicted(truth.x() + 0.15, truth.y() - 0.05, 0.02);
  const Matrix3d confident = Eigen::Vector3d(0.04, 0.04, 0.003).asDiagonal();
  const LabelResult ok = labeller.label(d, predicted, confident);
  EXPECT_EQ(ok.outcome, LabelOutcome::labelled);
  ASSERT_TRUE(ok.lamp);
  EXPECT_EQ(ok.lamp->id.value, "C1-L4");
  EXPECT_GT(ok.candidates, 8);  // C1 and the nodes next to it
  // Two metres of uncertainty along the corridor: several lamps fit, none is chosen.
  const Matrix3d lost = Eigen::Vector3d(4.0, 0.04, 0.003).asDiagonal();
  const LabelResult amb = labeller.label(d, predicted, lost);
  EXPECT_EQ(amb.outcome, LabelOutcome::ambiguous);
  EXPECT_EQ(amb.lamp, nullptr);
  EXPECT_GT(amb.in_gate, 1);
  // The lamp is taken by another track: nothing else fits.
  EXPECT_EQ(labeller.label(d, predicted, confident, {LampId("C1-L4")}).outcome,
            LabelOutcome::no_candidate);
  vision::LampDetection cut = d;
  cut.view = vision::LampView::partial;
  EXPECT_EQ(labeller.label(cut, predicted, confident).outcome, LabelOutcome::partial_view);
}

}  // namespace
}  // namespace lampnav::fusion
