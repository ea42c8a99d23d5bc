// The lamps the omni camera sees around a drive, and rows of lamps: the ways out a drive did not
// take (omni_ways.hpp, private to mapping/).

#include "omni_ways.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <random>

#include "drive.hpp"
#include "lampnav/core/pose2.hpp"

namespace lampnav::mapping {
namespace {

using Eigen::Vector2d;

// Along the office's north corridor from E1 to K1, past J1 (the middle corridor goes south from
// it): the lamps the omni camera's views show lie on lamps of the building, the first three of the
// middle corridor, which the drive never passed under, among them. A floor bump throws a far
// sighting a metre along its ray now and then, past its lamp's gate; enough of them start a lamp
// that is not there, within 1.5 m of the lamp (2 and 3 of 32 and 33 on this drive, each view's
// tilt fitted to the mapped lamps; 7 and 5 of 35 without the fit), mostly on a row's line, where it
// does not break the row. The omni camera is also mounted turned a quarter turn and off
// the robot's centre: its mount must be taken into account.
TEST(OmniWays, LampsSeenAroundLieOnTheBuildingsLamps) {
  test::Office office;
  for (const bool turned : {false, true}) {
    SCOPED_TRACE(turned ? "omni camera turned 90 degrees, 0.2 m forward" : "omni camera as given");
    RobotDescription robot = office.robot;
    CameraDescription* omni = nullptr;
    for (auto& c : robot.cameras)
      if (c.name == "omni_camera") omni = &c;
    ASSERT_NE(omni, nullptr);
    if (turned) {
      omni->mount.rpy.z() = M_PI / 2;
      omni->mount.xyz.x() = 0.2;
    }
    const sim::LampSensors sensors(office.map, robot);
    test::DriveOptions o;
    o.omni_rate = 3;
    const test::DriveRecord drive =
        test::drive_through({{1, 10}, {41, 10}}, 0.0, sensors, robot.semi_axis, o);
    const MappingResult mapped = test::map_drive(drive, robot);
    std::vector<OmniView> views;
    for (const auto& f : drive.omni) views.push_back({f.stamp, f.detection});
    const auto seen =
        lamps_seen_around(views, mapped.keyframes, *omni, 2.7, test::lamp_centres(mapped), {});
    ASSERT_GE(seen.size(), 20u);
    int on_a_lamp = 0;
    for (const Vector2d& p : seen) {
      const Vector2d at = drive.start.transform_from(p);
      double nearest = 1e9;
      for (const auto& n : office.map.nodes())
        for (const auto& l : n.lamps) nearest = std::min(nearest, (l.xyz.head<2>() - at).norm());
      if (nearest < 0.3) {
        ++on_a_lamp;
        continue;
      }
      EXPECT_LT(nearest, 1.5) << at.transpose();  // a lamp's sightings, thrown along the ray
    }
    EXPECT_GE(on_a_lamp, 0.85 * static_cast<double>(seen.size()));
    std::cout << on_a_lamp << " of " << seen.size() << " lamps seen lie on a lamp\n";
    for (const double y : {7.75, 5.5, 3.25}) {
      bool found = false;
      for (const Vector2d& p : seen)
        found = found || (drive.start.transform_from(p) - Vector2d(21, y)).norm() < 0.4;
      EXPECT_TRUE(found) << "the middle corridor's lamp at (21, " << y << ")";
    }
  }
}

// Two rows meeting at a corner, with noise, a lone lamp, a pair, and a row broken by a gap.
TEST(OmniWays, RowsOfLampsAreFoundWhole) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<Vector2d> lamps;
  auto add = [&](double x, double y) { lamps.emplace_back(x + noise(rng), y + noise(rng)); };
  for (int k = 0; k < 5; ++k) add(2.0 * k, 0);   // along x, from the corner (0, 0)
  for (int k = 1; k < 4; ++k) add(0, 2.25 * k);  // along y, from the corner
  add(6, 5);                                     // alone
  add(20, 0);                                    // with the next, a pair
  add(21.5, 1);
  for (int k = 0; k < 3; ++k) add(-20, 2.0 * k);       // a row ...
  for (int k = 0; k < 3; ++k) add(-20, 12 + 2.0 * k);  // ... and its other part, 8 m further
  const auto rows = lamp_rows(lamps, 3, 0.3, 5.0);
  int along_x = 0, along_y = 0, broken = 0;
  for (const LampRow& r : rows) {
    const Vector2d d = r.dir();
    if (r.first.x() > -15 && std::abs(d.y()) < 0.1) {
      ++along_x;
      EXPECT_EQ(r.lamps, 5);
      EXPECT_LT((r.first - Vector2d(0, 0)).norm() + (r.last - Vector2d(8, 0)).norm(), 0.3);
    } else if (r.first.x() > -15 && std::abs(d.x()) < 0.1) {
      ++along_y;
      EXPECT_EQ(r.lamps, 4);  // the corner's lamp is in both rows
    } else if (r.first.x() < -15) {
      ++broken;
      EXPECT_EQ(r.lamps, 3);
    } else {
      ADD_FAILURE() << "a row from (" << r.first.transpose() << ") to (" << r.last.transpose()
                    << ")";
    }
  }
  EXPECT_EQ(along_x, 1);
  EXPECT_EQ(along_y, 1);
  EXPECT_EQ(broken, 2);
}

}  // namespace
}  // namespace lampnav::mapping
