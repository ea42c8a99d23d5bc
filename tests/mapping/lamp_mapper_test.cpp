// Lamp SLAM from a drive on the office floor: the lamps come out where they are (after the best
// rigid alignment), each once, none that does not exist; a loop driven twice closes.

#include "lampnav/mapping/lamp_mapper.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <set>
#include <string>

#include "battery.hpp"
#include "drive.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/planner.hpp"
#include "lampnav/mapping/rigid_fit.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav_test.hpp"

namespace lampnav::mapping {
namespace {

using Eigen::Vector2d;

using test::Office;

struct Accuracy {
  std::size_t matched = 0, missing = 0, phantoms = 0, doubles = 0;
  double rms_m = 0, max_m = 0, max_height_m = 0;
};

// Compares the built lamps with the true ones the drive saw: each built lamp is paired with the
// nearest true lamp (the start pose puts them in the map frame), a rigid motion fitted to the
// pairs, then the errors taken after it.
Accuracy compare(const MappingResult& built, const graph::TopologicalMap& truth,
                 const test::DriveRecord& drive) {
  std::set<const graph::Lamp*> seen;
  for (const auto& f : drive.frames) {
    for (const auto& d : f.lamps) {
      if (d.view != vision::LampView::full) continue;
      // The true lamp nearest the point straight above the detection's ray is good enough to
      // name what the drive saw: lamps are metres apart.
      for (const graph::Lamp* l : truth.lamps_within(f.truth.translation(), 3.0)) seen.insert(l);
    }
  }
  Accuracy a;
  std::vector<std::pair<Vector2d, const graph::Lamp*>> pairs;
  std::set<const graph::Lamp*> used;
  // Paired twice: by the start pose, then by the best rigid motion of those pairs (a map's frame
  // is its first keyframe's, a fraction of a degree off the true start: at 100 m from the start
  // that is more than half of two rows' 1.2 m spacing).
  Pose2 fit = drive.start;
  for (int pass = 0; pass < 2; ++pass) {
    a = {};
    pairs.clear();
    used.clear();
    for (const auto& l : built.lamps) {
      const Vector2d in_map = fit.transform_from(l.xyz.head<2>());
      const auto near = truth.lamps_within(in_map, 0.6);
      if (near.empty()) {
        ++a.phantoms;
        continue;
      }
      if (!used.insert(near.front()).second) ++a.doubles;
      pairs.emplace_back(l.xyz.head<2>(), near.front());
    }
    std::vector<std::pair<Vector2d, Vector2d>> point_pairs;
    for (const auto& [p, l] : pairs) point_pairs.emplace_back(p, l->xyz.head<2>());
    fit = mapping::fit_rigid(point_pairs);
  }
  double sum = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Vector2d p = fit.transform_from(pairs[i].first);
    const double e = (p - pairs[i].second->xyz.head<2>()).norm();
    sum += e * e;
    a.max_m = std::max(a.max_m, e);
  }
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const MappedLamp* b = nullptr;
    for (const auto& l : built.lamps)
      if (l.xyz.head<2>() == pairs[i].first) b = &l;
    const double dz = std::abs(b->xyz.z() - pairs[i].second->xyz.z());
    a.max_height_m = std::max(a.max_height_m, dz);
  }
  a.matched = pairs.size();
  a.rms_m = pairs.empty() ? 0 : std::sqrt(sum / pairs.size());
  for (const graph::Lamp* l : seen) {
    if (!used.count(l)) {
      // Seen only at the edge of the view, perhaps never whole: not counted as missing then.
      bool whole = false;
      for (const auto& f : drive.frames)
        whole = whole || (f.truth.translation() - l->xyz.head<2>()).norm() < 1.0;
      if (whole) ++a.missing;
    }
  }
  return a;
}

MappingResult build(const test::DriveRecord& drive, const RobotDescription& robot,
                    const LampMapperOptions& o = {}) {
  return test::map_drive(drive, robot, o);
}

// The targets: every lamp once, none that does not exist; 2 cm RMS, 5 cm at most, heights
// within 3 cm.
void expect_targets(const Accuracy& a) {
  EXPECT_EQ(a.phantoms, 0u);
  EXPECT_EQ(a.doubles, 0u);
  EXPECT_EQ(a.missing, 0u);
  EXPECT_LE(a.rms_m, 0.02);
  EXPECT_LE(a.max_m, 0.05);
  EXPECT_LE(a.max_height_m, 0.03);
}

// Builds `drive` of `office` with the default options and with `off` (what the test is about
// turned off), prints both, and expects the first to meet the targets and the second to miss
// them by far (a lamp 10 cm off, or one placed where no lamp is).
void expect_needed(const Office& office, const test::DriveRecord& drive,
                   const LampMapperOptions& off, const std::string& on_name,
                   const std::string& off_name) {
  const Accuracy a = compare(build(drive, office.robot), office.map, drive);
  const Accuracy b = compare(build(drive, office.robot, off), office.map, drive);
  std::cout << on_name << ": matched " << a.matched << ", rms " << a.rms_m * 100 << " cm, max "
            << a.max_m * 100 << " cm; " << off_name << ": matched " << b.matched << ", phantoms "
            << b.phantoms << ", rms " << b.rms_m * 100 << " cm, max " << b.max_m * 100 << " cm\n";
  expect_targets(a);
  EXPECT_GT(b.max_m + 0.1 * b.phantoms, 0.10);
}

std::vector<Vector2d> office_loop(int laps) {
  // E1, then around J1 - K1 - K2 - J2 - J1 (corridors C2, C3, C4, C5) `laps` times.
  std::vector<Vector2d> w = {{1, 10}, {21, 10}};
  for (int k = 0; k < laps; ++k) {
    for (const Vector2d& p :
         {Vector2d(41, 10), Vector2d(41, -8), Vector2d(21, -8), Vector2d(21, 10)})
      w.push_back(p);
  }
  return w;
}

TEST(LampMapper, OfficeLoopDrivenTwiceGivesEachLampOnce) {
  const Office office;
  const test::DriveRecord drive = office.drive(office_loop(2));
  const MappingResult built = build(drive, office.robot);
  const Accuracy a = compare(built, office.map, drive);
  std::cout << "drive " << drive.length_m << " m, " << built.keyframes.size() << " keyframes, "
            << built.sightings << " sightings, " << built.revisits << " revisits, " << built.solves
            << " solves in " << built.solve_seconds << " s, rms " << built.final_rms_px
            << " px; lamps " << built.lamps.size() << " (matched " << a.matched << ", missing "
            << a.missing << ", phantoms " << a.phantoms << ", doubles " << a.doubles << ", merged "
            << built.merged << ", dropped " << built.dropped << "); error rms " << a.rms_m * 100
            << " cm, max " << a.max_m * 100 << " cm, height max " << a.max_height_m * 100
            << " cm\n";
  expect_targets(a);
  EXPECT_GT(built.revisits, 0u);
}

// Without loop closure the second lap's lamps are new landmarks, drifted; with it, one each.
TEST(LampMapper, LoopClosureTakesOutTheDrift) {
  const Office office;
  test::DriveOptions dopt;
  dopt.seed = 2;
  const test::DriveRecord drive = office.drive(office_loop(2), dopt);
  LampMapperOptions open;
  open.close_loops = false;
  const Accuracy without = compare(build(drive, office.robot, open), office.map, drive);
  const Accuracy with = compare(build(drive, office.robot), office.map, drive);
  std::cout << "without loop closure: " << without.matched << " landmarks, " << without.doubles
            << " doubles, error rms " << without.rms_m * 100 << " cm, max " << without.max_m * 100
            << " cm; with: " << with.matched << " landmarks, " << with.doubles << " doubles, rms "
            << with.rms_m * 100 << " cm, max " << with.max_m * 100 << " cm\n";
  EXPECT_GT(without.doubles, 10u);
  EXPECT_EQ(with.doubles, 0u);
  EXPECT_LT(with.rms_m, without.rms_m);
  EXPECT_LE(with.rms_m, 0.02);
  EXPECT_LE(with.max_m, 0.05);
}

// A drive of more than ten minutes on a generated 100-node building (rooms, a missing corridor,
// a wing with another lamp spacing, a lobby): over every corridor, closing loops.
void ten_minute_drive(int rows) {
  sim::BuildingOptions bo = test::asymmetric_building(100);
  bo.rows = rows;
  const graph::TopologicalMap map = graph::parse_map(sim::generate_building(bo).geojson, "b").map;
  const RobotDescription robot =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  const std::vector<Vector2d> waypoints = test::every_corridor_twice(map);
  const sim::LampSensors sensors(map, robot);
  const Vector2d d0 = waypoints[1] - waypoints[0];
  // Wheels whose mean scale was calibrated (one 0.35 % larger, the other as much smaller): the
  // map's scale is the wheels' (docs/mapping.md), so a mean scale error would scale the map.
  test::DriveOptions dopt;
  dopt.scale_error_left = 0.0035;
  dopt.scale_error_right = -0.0035;
  const test::DriveRecord drive =
      test::drive_through(waypoints, std::atan2(d0.y(), d0.x()), sensors, robot.semi_axis, dopt);
  const auto t0 = std::chrono::steady_clock::now();
  const MappingResult built = build(drive, robot);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Accuracy a = compare(built, map, drive);
  std::cout << "drive " << drive.length_m << " m (" << drive.length_m / 0.5 / 60
            << " min at 0.5 m/s), built in " << took << " s (" << built.solves << " solves, "
            << built.solve_seconds << " s in Ceres); lamps " << built.lamps.size() << " (matched "
            << a.matched << ", missing " << a.missing << ", phantoms " << a.phantoms << ", doubles "
            << a.doubles << "); error rms " << a.rms_m * 100 << " cm, max " << a.max_m * 100
            << " cm, height max " << a.max_height_m * 100 << " cm\n";
  EXPECT_GE(drive.length_m, 300.0);
  expect_targets(a);
}

TEST(LampMapper, TenMinuteDriveOnAGeneratedBuilding) { ten_minute_drive(1); }
// Its corridors with two rows of lamps 1.2 m apart: a lamp beside each, as alike as the next.
TEST(LampMapper, TenMinuteDriveOnAGeneratedBuildingOfTwoRows) { ten_minute_drive(2); }

// Ceilings of other heights than the 2.7 m new lamps are first placed at: the office with its
// lamps hung from 2.4 to 8 m. Before lamps were followed across the image and new ones placed at
// their kind's solved height, a 5 m ceiling gave 28 phantom lamps (each lamp moved across the
// ceiling as the robot passed under it, at the wrong height, and was taken for others) and an
// 8 m one 294.
TEST(LampMapper, CeilingsFrom2Point4To8MetresHighMapAlike) {
  const Office office;
  for (const double height : {2.4, 4.0, 5.0, 8.0}) {
    SCOPED_TRACE("lamps " + std::to_string(height) + " m above the floor");
    Office hung = office;
    hung.map = test::edited(office.map, [&](graph::Node& c) {
      for (auto& l : c.lamps) l.xyz.z() = height;
    });
    const test::DriveRecord drive = hung.drive(office_loop(2));
    const MappingResult built = build(drive, hung.robot);
    const Accuracy a = compare(built, hung.map, drive);
    std::cout << height << " m: lamps " << built.lamps.size() << " (matched " << a.matched
              << ", phantoms " << a.phantoms << ", doubles " << a.doubles << ", merged "
              << built.merged << ", dropped " << built.dropped << "); error rms " << a.rms_m * 100
              << " cm, max " << a.max_m * 100 << " cm, height max " << a.max_height_m * 100
              << " cm\n";
    expect_targets(a);
  }
}

// A corridor under a higher ceiling: the office's C3 (K1 to K2) with its lamps hung 0.5 m above
// the others', the loop driven once. Held to their kind's one height (the building prior, 1 cm),
// C3's lamps are pulled down and the views of them misfit; tried at a height of their own they
// fit, and are kept there. Held (height_release_m = 0): heights off by more than 10 cm
// (2026-12-06; on grids whose every corridor has its own height, docs/mapping.md, up to 45 cm).
TEST(LampMapper, ACorridorUnderAHigherCeilingKeepsItsHeight) {
  Office raised;
  raised.map = test::edited(raised.map, [](graph::Node& n) {
    if (n.name != "C3") return;
    for (auto& l : n.lamps) l.xyz.z() += 0.5;
  });
  const test::DriveRecord drive = raised.drive(office_loop(1));
  const Accuracy a = compare(build(drive, raised.robot), raised.map, drive);
  LampMapperOptions held;
  held.height_release_m = 0;
  const Accuracy b = compare(build(drive, raised.robot, held), raised.map, drive);
  std::cout << "released: rms " << a.rms_m * 100 << " cm, max " << a.max_m * 100
            << " cm, height max " << a.max_height_m * 100 << " cm; held: rms " << b.rms_m * 100
            << " cm, max " << b.max_m * 100 << " cm, height max " << b.max_height_m * 100
            << " cm\n";
  expect_targets(a);
  EXPECT_GT(b.max_height_m, 0.10);
}

// Lamps not square to the building: the office's C3 (K1 to K2) with its lamps hung 40 degrees off
// the grid, driven once, E1 - J1 - K1 - K2 - J2. Each lamp joins the axis it is first placed
// square to, or starts one: C3's lamps get an axis of their own. With a gate that lets every lamp
// join the first axis and no lamp tried off it after a solve (the one axis of the building before
// 2026-12-02), C3's lamps are pulled 40 degrees onto the grid, the poses with them, and the map
// beyond C3 bends (a generated building with corridors at 40 to 65 degrees to each other mapped 6
// of 24 lamps so, the rest bent out of every place). With that gate alone, the lamps a solve
// leaves off the axis are tried off it and the map is the same as with the gate.
TEST(LampMapper, LampsAtAnAngleToTheGridKeepTheirAngle) {
  Office askew;
  askew.map = test::edited(askew.map, [](graph::Node& n) {
    if (n.name != "C3") return;
    for (auto& l : n.lamps) l.yaw += 40 * M_PI / 180;
  });
  const std::vector<Vector2d> route = {{1, 10}, {21, 10}, {41, 10}, {41, -8}, {21, -8}};
  LampMapperOptions one_axis;
  one_axis.square_gate_rad = M_PI / 4 - 1e-6;
  one_axis.square_release_rad = M_PI / 4;
  expect_needed(askew, askew.drive(route), one_axis, "axes of their own", "one axis");
}

// A corridor a few degrees off the grid, inside the gate: C3 turned 6 degrees about its north end
// (its lamps and their yaws), driven first, from its south end up to J2 and west along C2 and C1.
// C3's first lamp starts the axis, and the grid's first lamp joins it (its yaw from the wheels is
// within the gate); the prior pulls one corridor's lamps towards the other's and the camera's
// sightings turn the poses with them, so the drive bends. The lamps a solve leaves off their axis
// are tried on an axis of their own, which fits the drive better by far: the grid's first two
// lamps, J2's and C2's first (chi-square 498 -> 407).
// Held on one axis: 11 of 26 lamps placed, 15 more than 0.6 m off, 36 cm at worst. On a
// generated building with a corridor 10 degrees off its junction's axis, driven first, the two
// lamps at its end were 20 and 43 cm off.
TEST(LampMapper, ACorridorAFewDegreesOffTheGridLeavesItsAxis) {
  const double turn = 6 * M_PI / 180;
  const Vector2d north(41, 10);
  const Pose2 about =
      Pose2(north.x(), north.y(), 0) * Pose2(0, 0, turn) * Pose2(-north.x(), -north.y(), 0);
  Office askew;
  askew.map = test::edited(askew.map, [&](graph::Node& n) {
    if (n.name != "C3") return;
    for (auto& l : n.lamps) {
      l.xyz.head<2>() = about.transform_from(l.xyz.head<2>());
      l.yaw += turn;
    }
  });
  const std::vector<Vector2d> route = {
      about.transform_from(Vector2d(41, -8)), north, {21, 10}, {1, 10}};
  LampMapperOptions held;
  held.square_release_rad = M_PI / 4;
  expect_needed(askew, askew.drive(route), held, "tried off the axis", "held on it");
}

// Round lamps along the corridors: the office with every rectangular lamp made a 0.5 m disc,
// driven E1 - J1 - J2 - E2 once. A disc has no axis; two placed one after the other along the
// drive are a row, whose direction holds the heading as a rectangular lamp's axis does. Without
// rows (2026-12-02, the simulated `E1 -> E2`): 16 of 27 lamps in no place and 14.5 cm RMS, the
// corridors bent by the wheels' difference.
TEST(LampMapper, RowsOfRoundLampsHoldTheHeading) {
  Office round;
  round.map = test::edited(round.map, test::make_round);
  const std::vector<Vector2d> route = {{1, 10}, {21, 10}, {21, -8}, {1, -8}};
  LampMapperOptions no_rows;
  no_rows.row_max_m = 0.5;  // no two lamps are that close: no rows
  expect_needed(round, round.drive(route), no_rows, "rows", "without");
}

// Round lamps further apart: the office's discs with every other corridor lamp taken down (4.5 m
// apart, as under a higher ceiling or with every other lamp failed), driven as above. Until
// 2026-12-02 two lamps made a row only within 4 m: no row formed, and the simulated `E1 -> E2`
// on that floor gave no map at all (no straight stretch left), `E2 -> E1` 12.4 cm RMS.
TEST(LampMapper, RowsOfRoundLampsFourAndAHalfMetresApartHoldTheHeading) {
  Office sparse;
  sparse.map = test::edited(sparse.map, test::sparse_round);
  const std::vector<Vector2d> route = {{1, 10}, {21, 10}, {21, -8}, {1, -8}};
  LampMapperOptions near_only;
  near_only.row_max_m = 4.0;
  expect_needed(sparse, sparse.drive(route), near_only, "rows up to 8 m", "up to 4 m");
}

// Round lamps off the grid: 0.5 m discs 2.25 m apart along C1, then along a corridor 40 degrees
// off it for 16 m, then along one parallel to C1 again (the office's other lamps taken down),
// six drives. Each corridor's row of discs gets an axis; the last corridor joins C1's only when
// its first lamps are placed within the gate of it, and with discs nothing but the wheels holds
// the heading between two solves. The wheels' difference (the simulated 0.7 %: 1.2 degrees a
// metre) is estimated by whole solves, and the estimate between solves moves by the wheels
// corrected with it. Before (2026-12-02), only the end's solve was whole over a drive that
// closed no loop, and the estimate curved with the raw wheels: one drive put 7 lamps more than
// 0.6 m from any lamp and another had a lamp 14.4 cm off. Now 1.2 to 6.9 cm RMS and 2.8 to 10.4 cm
// at worst: what is left is the heading through each turn, which with one disc in view at a
// time rests on the wheels for a metre or two (docs/mapping.md).
TEST(LampMapper, RoundLampsOffTheGridJoinTheirAxisAgain) {
  const double off = 40 * M_PI / 180;
  const Vector2d j1(21, 10), along(std::cos(off), -std::sin(off));
  const Vector2d bend = j1 + 16.0 * along;
  Office zigzag;
  zigzag.map = test::edited(zigzag.map, [&](graph::Node& n) {
    if (n.name == "C5") {
      n.lamps.resize(6);
      for (std::size_t k = 0; k < n.lamps.size(); ++k)
        n.lamps[k].xyz.head<2>() = j1 + 2.25 * static_cast<double>(k + 1) * along;
    } else if (n.name == "J2") {
      n.lamps.front().xyz.head<2>() = bend;
    } else if (n.name == "C4") {
      for (std::size_t k = 0; k < n.lamps.size(); ++k)
        n.lamps[k].xyz.head<2>() = bend + Vector2d(2.25 * static_cast<double>(k + 1), 0);
    } else if (n.name != "E1" && n.name != "C1" && n.name != "J1") {
      n.lamps.clear();
    }
    test::make_round(n);
  });
  const std::vector<Vector2d> route = {{1, 10}, j1, bend, bend + Vector2d(19, 0)};
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    test::DriveOptions options;
    options.seed = seed;
    const test::DriveRecord drive = zigzag.drive(route, options);
    const Accuracy a = compare(build(drive, zigzag.robot), zigzag.map, drive);
    std::cout << "seed " << seed << ": matched " << a.matched << ", phantoms " << a.phantoms
              << ", rms " << a.rms_m * 100 << " cm, max " << a.max_m * 100 << " cm\n";
    EXPECT_EQ(a.phantoms, 0u) << "seed " << seed;
    EXPECT_EQ(a.doubles, 0u) << "seed " << seed;
    EXPECT_EQ(a.missing, 0u) << "seed " << seed;
    EXPECT_LE(a.max_m, 0.12) << "seed " << seed;
  }
}

}  // namespace
}  // namespace lampnav::mapping
