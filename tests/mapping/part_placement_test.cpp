// Placing a part of a drive the robot was carried to onto the map of the drive before it: only
// where its lamps fit one place. Two drives on the office floor, each mapped on its own with the
// ideal lamp detections (the second in its own frame, as after a carry).

#include "part_placement.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "drive.hpp"
#include "lampnav/sim/lamp_sensors.hpp"
#include "lampnav_test.hpp"

namespace lampnav::mapping {
namespace {

using Eigen::Vector2d;

struct Mapped {
  test::DriveRecord drive;
  MappingResult map;
  DrivePart part() const { return {&map.lamps, &map.keyframes}; }
};

// The office with C1's fourth lamp failed (taken out of the world the drives see).
graph::TopologicalMap office_with_a_failed_lamp(const graph::TopologicalMap& office) {
  return test::edited(office, [](graph::Node& n) {
    if (n.name != "C1") return;
    n.lamps.erase(n.lamps.begin() + 3);
  });
}

Mapped drive(const graph::TopologicalMap& world, const RobotDescription& robot,
             const std::vector<Vector2d>& waypoints, std::uint64_t seed) {
  const sim::LampSensors sensors(world, robot);
  test::DriveOptions o;
  o.seed = seed;
  const Vector2d d = waypoints[1] - waypoints[0];
  Mapped m;
  m.drive = test::drive_through(waypoints, std::atan2(d.y(), d.x()), sensors, robot.semi_axis, o);
  m.map = test::map_drive(m.drive, robot);
  return m;
}

// Where the placement puts the part's start, in the world (the map's frame is its drive's start).
Pose2 start_in_world(const Mapped& map, const Mapped& part, const Pose2& motion) {
  return map.drive.start * motion * part.map.keyframes.front().pose;
}

// A corridor whose lamps are spaced unevenly (2.1 to 2.7 m), as in most real buildings: the map's
// drive went along it from -2 to 16 m; the part, carried back to 3 m, went on to 20 m. Its lamps
// and path are given in its own frame (its start), turned and moved from the world's.
TEST(PartPlacement, APartThatReDrivesUnevenlySpacedLampsIsPlacedWhereItWas) {
  auto lamps_from = [](const std::vector<double>& xs, double x0, double x1, const Pose2& frame) {
    std::vector<MappedLamp> out;
    for (const double x : xs) {
      if (x < x0 || x > x1) continue;
      MappedLamp l;
      l.xyz = Eigen::Vector3d(x, 0, 2.7);
      l.xyz.head<2>() = frame.transform_to(l.xyz.head<2>());
      l.yaw = wrap_angle(-frame.yaw());
      l.length = 1.2;
      l.width = 0.3;
      l.sightings = 10;
      out.push_back(l);
    }
    return out;
  };
  auto path_from = [](double x0, double x1, const Pose2& frame) {
    std::vector<KeyframePose> out;
    for (double x = x0; x <= x1 + 1e-9; x += 0.1) {
      KeyframePose k;
      k.pose = frame.inverse() * Pose2(x, 0, 0);
      out.push_back(k);
    }
    return out;
  };
  const Pose2 map_frame(-2, 0, 0), part_frame(3, 0, 0);
  const std::vector<double> uneven = {0, 2.2, 4.7, 6.5, 9.4, 11.7, 14.4, 16.4, 18.8};
  const std::vector<MappedLamp> map_lamps = lamps_from(uneven, -2, 16, map_frame),
                                part_lamps = lamps_from(uneven, 3, 20, part_frame);
  const std::vector<KeyframePose> map_path = path_from(-2, 16, map_frame),
                                  part_path = path_from(3, 20, part_frame);
  const Placement p = place_part({&map_lamps, &map_path}, {&part_lamps, &part_path});
  ASSERT_TRUE(p.motion) << p.fitting << " places fit";
  EXPECT_EQ(p.fitting, 1);
  EXPECT_EQ(p.shared, 5);                                // 4.5 to 13.9 m
  const Pose2 truth = map_frame.inverse() * part_frame;  // part frame -> map frame
  EXPECT_LT((p.motion->translation() - truth.translation()).norm(), 1e-6);
  EXPECT_LT(std::abs(wrap_angle(p.motion->yaw() - truth.yaw())), 1e-6);

  // A lamp a failed solve put a thousand kilometres up would surely have been seen from as far:
  // the map's path passes within that everywhere, so it rules every place out. Finding that once
  // walked every half-metre cell within the reach (10^12 of them): two carried drives of the
  // localization sweep took 250 and 777 s to build instead of 2 (docs/mapping.md).
  std::vector<MappedLamp> absurd = part_lamps;
  absurd.back().xyz.z() = 1e6;
  const Placement r = place_part({&map_lamps, &map_path}, {&absurd, &part_path});
  EXPECT_FALSE(r.motion);
  EXPECT_EQ(r.fitting, 0);
  // One put 10^300 m away is near nothing and rules nothing out: the part is placed as before.
  absurd.back().xyz = Eigen::Vector3d(1e300, -1e300, 2.7);
  const Placement far = place_part({&map_lamps, &map_path}, {&absurd, &part_path});
  ASSERT_TRUE(far.motion);
  EXPECT_LT((far.motion->translation() - truth.translation()).norm(), 1e-6);

  // Evenly spaced, the same corridor fits the part a lamp or two further along as well (its lamps
  // beyond the map's end unseen by the map), or turned end for end: not placed.
  const std::vector<double> even = {0, 2.25, 4.5, 6.75, 9.0, 11.25, 13.5, 15.75, 18.0};
  const std::vector<MappedLamp> map_even = lamps_from(even, -2, 16, map_frame),
                                part_even = lamps_from(even, 3, 20, part_frame);
  const Placement q = place_part({&map_even, &map_path}, {&part_even, &part_path});
  EXPECT_FALSE(q.motion);
  EXPECT_GT(q.fitting, 1);
  bool truth_among = false;
  for (const PlacementFit& f : q.fits)
    truth_among |= (f.motion.translation() - truth.translation()).norm() < 1e-6;
  EXPECT_TRUE(truth_among);
}

TEST(PartPlacement, APartInACorridorTheMapNeverSawIsNotPlacedOntoOneLikeIt) {
  const test::Office office;
  // The map: E1 along C1 to J1. The part: along C4 (the same lamps, 18 m south), never seen.
  const Mapped map = drive(office.map, office.robot, {{1, 10}, {21, 10}}, 1);
  const Mapped part = drive(office.map, office.robot, {{38, -8}, {24, -8}}, 2);
  const Placement p = place_part(map.part(), part.part());
  EXPECT_FALSE(p.motion);
  EXPECT_GT(p.fitting, 1) << "C4's lamps look like C1's at several places along it";
}

// A lamp of one drive where the other passed right under and saw none contradicts a place: here
// a lamp that failed between the two drives (in one drive with a carry, the two parts see the
// same lamps; the rule is what rules out a corridor's twin a lamp further along, or its ends).
TEST(PartPlacement, ALampWhereTheOtherDrivePassedAndSawNoneRulesAPlaceOut) {
  const test::Office office;
  const graph::TopologicalMap world = office_with_a_failed_lamp(office.map);
  const Mapped map = drive(world, office.robot, {{1, 10}, {21, 10}}, 1);
  const Mapped part = drive(office.map, office.robot, {{3, 10}, {19, 10}}, 2);
  const Placement p = place_part(map.part(), part.part());
  EXPECT_FALSE(p.motion);
  for (const PlacementFit& f : p.fits) {
    const Pose2 at = start_in_world(map, part, f.motion);
    EXPECT_GT((at.translation() - part.drive.start.translation()).norm(), 1.0)
        << "the place where the part's lamp falls on the map's gap fits";
  }
  // It fits but for that one lamp: it is among the places the omni views weigh the fits against
  // (a lamp failed or missed by one drive must not alone decide where a part goes).
  bool near = false;
  for (const PlacementFit& f : p.near_fits) {
    const Pose2 at = start_in_world(map, part, f.motion);
    near |= (at.translation() - part.drive.start.translation()).norm() < 0.05;
  }
  EXPECT_TRUE(near) << p.near_fits.size() << " places fit but for one lamp";
  // The same part in the office the map saw fits there (among its twins along C1).
  const Mapped healthy = drive(office.map, office.robot, {{1, 10}, {21, 10}}, 1);
  const Placement q = place_part(healthy.part(), part.part());
  bool there = false;
  for (const PlacementFit& f : q.fits)
    there |=
        (start_in_world(healthy, part, f.motion).translation() - part.drive.start.translation())
            .norm() < 0.05;
  EXPECT_TRUE(there);
}

}  // namespace
}  // namespace lampnav::mapping
