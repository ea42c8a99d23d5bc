// The ceiling pipeline over the simulated `corridor` scenario (E1 -> K1 on the office floor), read
// back from its mission log: labels checked against truth, pose measurements scored against truth.
// Between measurements the pose is dead-reckoned from the wheels with the EKF's motion and noise
// model; each measurement resets it (the Localizer tests run the full filter).

#include <unistd.h>

#include <filesystem>
#include <set>

#include "lampnav/fusion/ceiling_geometry.hpp"
#include "lampnav/fusion/ceiling_pipeline.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;

struct Score {
  int frames = 0, measurements = 0, labels = 0, wrong_labels = 0, lamps_seen = 0;
  double sum_pos = 0, sum_yaw = 0, max_pos = 0, max_yaw = 0;
  double mean_pos() const { return sum_pos / measurements; }
  double mean_yaw_deg() const { return sum_yaw / measurements * 180 / M_PI; }
};

RobotDescription pioneer() {
  return read_robot_description(test::source_path("maps/robots/pioneer.json"));
}

// Records scenario `s` on `map` (ceiling camera only) and scores the pipeline over it.
Score drive(const graph::TopologicalMap& map, sim::Scenario s, const RobotDescription& robot);

Score corridor(double bump_rad, const std::set<std::string>& failed, std::uint64_t seed) {
  const std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  const graph::TopologicalMap map = graph::parse_map(geojson, "office_floor.geojson").map;
  const RobotDescription robot = pioneer();
  sim::Scenario s = sim::make_named_scenario("corridor", map, geojson, robot, seed);
  s.bump_sigma_rad = bump_rad;
  s.failed_lamps = failed;
  return drive(map, std::move(s), robot);
}

Score drive(const graph::TopologicalMap& map, sim::Scenario s, const RobotDescription& robot) {
  s.omni_rate = 0;
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("lampnav_pipeline_" + std::to_string(::getpid()) + ".mcap"))
                               .string();
  sim::record_mission(s, path);
  io::MissionLog log = io::read_mission_log(path);
  std::filesystem::remove(path);
  auto by_capture = [](const auto& a, const auto& b) { return a.value.stamp < b.value.stamp; };
  std::sort(log.ceiling_images.begin(), log.ceiling_images.end(), by_capture);
  std::sort(log.wheels.begin(), log.wheels.end(), by_capture);
  const io::TruthTrack truth_track(log.truth);

  const CameraDescription& cam = *robot.find_camera("ceiling_camera");
  CeilingPipeline pipeline(map, cam);
  const CeilingGeometry geometry(cam);
  Pose2 pose = s.start;
  Matrix3d P = Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
  const double a = robot.semi_axis;
  EkfOptions ekf;
  ekf.semi_axis = a;
  std::size_t w = 0;
  double left = log.wheels.front().value.left, right = log.wheels.front().value.right;
  Score sc;
  for (const auto& f : log.ceiling_images) {
    const Stamp t = f.value.stamp;
    // Dead reckoning to the capture time (conventions.md's mid-point unicycle).
    for (; w < log.wheels.size() && log.wheels[w].value.stamp <= t; ++w) {
      const double dl = log.wheels[w].value.left - left, dr = log.wheels[w].value.right - right;
      left = log.wheels[w].value.left;
      right = log.wheels[w].value.right;
      // The EKF's motion model and input noise, without its updates.
      const Eigen::Vector3d x(pose.x(), pose.y(), pose.yaw());
      Matrix3d F;
      motion_jacobians(x, dl, dr, a, &F, nullptr);
      P = F * P * F.transpose() + process_noise(x, dl, dr, ekf);
      const Eigen::Vector3d next = predict_motion(x, dl, dr, a);
      pose = Pose2(next.x(), next.y(), next.z());
    }
    const Image8 img = io::decode_image(f.value.data, "frame");
    const CeilingObservation ob = pipeline.process(t, vision::ImageView::of(img), pose, P);
    ++sc.frames;
    const Pose2 truth = truth_track.at(t);
    for (const auto& l : ob.lamps) {
      if (l.detection.view == vision::LampView::partial) continue;
      ++sc.lamps_seen;
      if (!l.lamp) continue;
      ++sc.labels;
      // The lamp truly under the detection: the nearest map lamp projected from the true pose.
      const graph::Lamp* nearest = nullptr;
      double best = 1e9;
      for (const auto* m : map.lamps_within(truth.translation(), 6.0)) {
        const auto n = geometry.predict(truth, m->xyz);
        if (n && (*n - l.detection.centre).norm() < best) {
          best = (*n - l.detection.centre).norm();
          nearest = m;
        }
      }
      if (nearest != l.lamp) ++sc.wrong_labels;
    }
    if (ob.measurement) {
      const Pose2& m = ob.measurement->pose;
      const double e = (m.translation() - truth.translation()).norm();
      const double ey = std::fabs(wrap_angle(m.yaw() - truth.yaw()));
      ++sc.measurements;
      sc.sum_pos += e;
      sc.sum_yaw += ey;
      sc.max_pos = std::max(sc.max_pos, e);
      sc.max_yaw = std::max(sc.max_yaw, ey);
      pose = m;
      P = ob.measurement->covariance;
    }
  }
  std::cout << "frames " << sc.frames << ", lamps in full view " << sc.lamps_seen << ", labelled "
            << sc.labels << " (" << sc.wrong_labels << " wrong), measurements " << sc.measurements
            << ": position error mean " << sc.mean_pos() * 100 << " cm, max " << sc.max_pos * 100
            << " cm; yaw error mean " << sc.mean_yaw_deg() << " deg, max "
            << sc.max_yaw * 180 / M_PI << " deg\n";
  return sc;
}

TEST(CeilingPipeline, CorridorWithoutBumps) {
  const Score s = corridor(0.0, {}, 1);
  EXPECT_EQ(s.wrong_labels, 0);
  EXPECT_GT(s.labels, s.lamps_seen * 9 / 10);
  EXPECT_GT(s.measurements, s.frames * 8 / 10);
  EXPECT_LE(s.mean_pos(), 0.015);
  EXPECT_LE(s.mean_yaw_deg(), 0.5);
}

TEST(CeilingPipeline, CorridorWithDefaultBumps) {
  const Score s = corridor(0.5 * M_PI / 180, {}, 2);
  EXPECT_EQ(s.wrong_labels, 0);
  EXPECT_GT(s.measurements, s.frames * 8 / 10);
  EXPECT_LE(s.mean_pos(), 0.04);
  EXPECT_LE(s.mean_yaw_deg(), 0.5);
}

// A failed lamp in the middle of C1 must not shift the labels of the lamps after it.
TEST(CeilingPipeline, CorridorWithAFailedLamp) {
  const Score s = corridor(0.5 * M_PI / 180, {"C1-L4", "C2-L3"}, 3);
  EXPECT_EQ(s.wrong_labels, 0);
  EXPECT_GT(s.measurements, s.frames * 6 / 10);
  EXPECT_LE(s.mean_pos(), 0.04);
}

// Offices often hold more lamps in their rooms, of another kind, than in their corridors. The
// detector looks for the kind the robot drives under: here the corridors' rectangles, not the
// rooms' round lamps, which outnumber them (before, every lamp of the drive went unseen).
TEST(CeilingPipeline, CorridorsOfABuildingWhoseRoomsHoldMoreLamps) {
  sim::BuildingOptions b;
  b.nodes = 30;
  b.block_m = 14;
  b.lamp_spacing_m = 2.5;
  b.seed = 7;
  const std::string geojson = sim::generate_building(b).geojson;
  const graph::TopologicalMap map = graph::parse_map(geojson, "building.geojson").map;
  int in_rooms = 0, elsewhere = 0;
  for (const auto& n : map.nodes())
    (n.place == graph::Place::room ? in_rooms : elsewhere) += int(n.lamps.size());
  ASSERT_GT(in_rooms, elsewhere);  // the case this test is for

  const RobotDescription robot = pioneer();
  const vision::LampShapePrior kind = shape_prior_for(map, *robot.find_camera("ceiling_camera"));
  EXPECT_TRUE(kind.rectangle);
  EXPECT_DOUBLE_EQ(kind.length, 1.2);
  EXPECT_DOUBLE_EQ(kind.width, 0.3);

  const Score s =
      drive(map, sim::make_route_scenario(map, geojson, robot, "J0_0", "J2_2", 4), robot);
  EXPECT_EQ(s.wrong_labels, 0);
  EXPECT_GT(s.labels, s.lamps_seen * 9 / 10);
  EXPECT_GT(s.measurements, s.frames * 8 / 10);
  EXPECT_LE(s.mean_pos(), 0.04);
}

graph::Lamp lamp_at(const std::string& id, double x, graph::LampShape shape, double length,
                    double width) {
  graph::Lamp l;
  l.id = LampId(id);
  l.xyz = Eigen::Vector3d(x, 0, 2.7);
  l.shape = shape;
  l.length = length;
  l.width = width;
  return l;
}

// One kind gives both the shape and the size: five rectangles of two sizes and four discs make
// discs the commonest kind, not a rectangle the size of a disc.
TEST(CeilingPipeline, ShapeAndSizeComeFromOneKindOfLamp) {
  graph::TopologicalMap map("kinds");
  graph::Node n;
  n.id = NodeId(1);
  n.name = "H1";
  n.place = graph::Place::hall;
  const auto rect = graph::LampShape::rectangle, disc = graph::LampShape::disc;
  for (int i = 0; i < 3; ++i)
    n.lamps.push_back(lamp_at("R" + std::to_string(i), i, rect, 1.2, 0.3));
  for (int i = 0; i < 2; ++i)
    n.lamps.push_back(lamp_at("S" + std::to_string(i), 10 + i, rect, 0.6, 0.6));
  for (int i = 0; i < 4; ++i)
    n.lamps.push_back(lamp_at("D" + std::to_string(i), 20 + i, disc, 0.6, 0.6));
  map.add_node(n);
  const vision::LampShapePrior kind =
      shape_prior_for(map, *pioneer().find_camera("ceiling_camera"));
  EXPECT_FALSE(kind.rectangle);
  EXPECT_DOUBLE_EQ(kind.length, 0.6);
  EXPECT_TRUE(detects(kind, map.node(NodeId(1)).lamps.back()));
  EXPECT_FALSE(detects(kind, map.node(NodeId(1)).lamps.front()));
  EXPECT_FALSE(detects(kind, map.node(NodeId(1)).lamps[3]));  // a square rectangle is no disc
}

// A lamp the detector does not look for is not missing when it is not seen: under a room's round
// lamps, with the corridors' rectangles looked for, an empty frame misses nothing; it misses the
// round lamps when those are the ones looked for.
TEST(CeilingPipeline, LampsOfAnotherKindAreNotMissing) {
  sim::BuildingOptions b;
  b.nodes = 30;
  b.block_m = 14;
  b.seed = 7;
  const graph::TopologicalMap map =
      graph::parse_map(sim::generate_building(b).geojson, "building.geojson").map;
  const RobotDescription robot = pioneer();
  const CameraDescription& cam = *robot.find_camera("ceiling_camera");
  const vision::PinholeCamera model(cam);
  const CeilingGeometry geometry(cam);
  const vision::LampShapePrior corridors = shape_prior_for(map, cam);
  ASSERT_TRUE(corridors.rectangle);
  const graph::Lamp* round = nullptr;
  for (const auto& n : map.nodes())
    for (const auto& l : n.lamps)
      if (!round && n.place == graph::Place::room && l.shape == graph::LampShape::disc) round = &l;
  ASSERT_NE(round, nullptr);
  vision::LampShapePrior rooms = corridors;
  rooms.rectangle = false;
  rooms.length = rooms.width = round->length;
  const Pose2 under(round->xyz.x(), round->xyz.y(), 0.3);
  const Eigen::Matrix3d P = Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
  EXPECT_TRUE(unseen_lamps(map, model, geometry, corridors, {}, under, P).empty());
  EXPECT_FALSE(unseen_lamps(map, model, geometry, rooms, {}, under, P).empty());
}

}  // namespace
}  // namespace lampnav::fusion
