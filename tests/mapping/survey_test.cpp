// A drive against the map after the building changed: 3 lamps failed, 2 moved 20 cm, 1 added.
// The survey finds exactly those, says where each is, and writes the corrected map.

#include "lampnav/mapping/survey.hpp"

#include <gtest/gtest.h>

#include <iostream>

#include "drive.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav_test.hpp"

namespace lampnav::mapping {
namespace {

using Eigen::Vector2d;

// The office as it is now: two lamps moved, one added (the failed ones are the sensors').
graph::TopologicalMap changed_office(const graph::TopologicalMap& map) {
  return test::edited(map, [](graph::Node& c) {
    for (auto& l : c.lamps) {
      if (l.id.value == "C5-L2") l.xyz.y() += 0.2;  // along the corridor
      if (l.id.value == "C4-L3") l.xyz.y() += 0.2;  // across it
    }
    if (c.name == "C6") {
      graph::Lamp added = c.lamps[1];
      added.id = LampId("C6-NEW");
      added.xyz.x() = 0.5 * (c.lamps[1].xyz.x() + c.lamps[2].xyz.x());
      c.lamps.insert(c.lamps.begin() + 2, added);
    }
  });
}

// The changed office driven down every corridor with `wheels`, surveyed against the map as it
// was: exactly the six changes found, each where it is, and the corrected map right.
SurveyResult survey_of_the_changed_office(const test::DriveOptions& wheels) {
  const graph::TopologicalMap map =
      graph::read_map(test::source_path("maps/office_floor.geojson")).map;
  const RobotDescription robot =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  const graph::TopologicalMap world = changed_office(map);
  sim::LampSensorOptions so;
  so.failed_lamps = {"C1-L3", "C2-L2", "C3-L4"};
  const sim::LampSensors sensors(world, robot, so);
  const test::DriveRecord drive =
      test::drive_through(test::office_every_corridor(), 0.0, sensors, robot.semi_axis, wheels);
  const SurveyResult s = survey(map, test::map_drive(drive, robot), robot);
  std::map<std::string, std::string> found;  // lamp -> status
  for (const auto& f : s.findings) {
    std::cout << to_string(f.status) << " " << f.lamp << " (" << f.where << ")"
              << (f.status == LampStatus::moved ? " by " + std::to_string(f.offset_m) + " m" : "")
              << "\n";
    found[f.lamp] = to_string(f.status);
  }
  std::cout << s.judged << " judged, " << s.ok << " ok; aligned on " << s.agreeing << " lamps, rms "
            << s.alignment_rms_m * 100 << " cm\n";
  const std::map<std::string, std::string> want = {{"C1-L3", "failed"}, {"C2-L2", "failed"},
                                                   {"C3-L4", "failed"}, {"C5-L2", "moved"},
                                                   {"C4-L3", "moved"},  {"C6-N1", "new"}};
  EXPECT_EQ(found, want);
  for (const auto& f : s.findings) {
    if (f.status == LampStatus::moved) {
      EXPECT_NEAR(f.offset_m, 0.2, 0.03) << f.lamp;
    }
    EXPECT_FALSE(f.where.empty());
  }
  // The corrected map reads back, without the failed lamps, with the moved and new ones where
  // they are now.
  const graph::TopologicalMap up = graph::parse_map(graph::write_map(s.updated), "updated").map;
  EXPECT_EQ(up.find_lamp(LampId("C1-L3")), nullptr);
  const graph::Lamp* added = up.find_lamp(LampId("C6-N1"));
  EXPECT_NE(added, nullptr);
  if (added) {
    EXPECT_NEAR(added->xyz.x(), 15.5, 0.05);
  }
  EXPECT_NEAR(up.find_lamp(LampId("C5-L2"))->xyz.y(), 5.7714, 0.05);
  EXPECT_EQ(up.lamp_count(), map.lamp_count() - 3 + 1);
  return s;
}

TEST(Survey, FindsTheFailedMovedAndNewLampsAndNothingElse) {
  const SurveyResult s = survey_of_the_changed_office({});
  // The simulated wheels read +0.4 % and -0.3 %: the drive's scale is the map's within 0.1 %.
  EXPECT_NEAR(s.drive_scale, 1.0, 1e-3);
}

// A corridor of two rows: facility staff are told which row, left or right as they walk from the
// place named, and the lamp's place in that row ("the 7th lamp" counting both rows would send
// them to the wrong one). C1 runs from E1 to J1; its lamps 2 (a: north) and 7 (b: south) failed.
TEST(Survey, SaysWhichRowOfACorridorOfTwoRows) {
  const graph::TopologicalMap map =
      test::edited(graph::read_map(test::source_path("maps/office_floor.geojson")).map,
                   [](graph::Node& n) { test::two_rows(n, 0.6); });
  const RobotDescription robot =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  sim::LampSensorOptions so;
  so.failed_lamps = {"C1-L2a", "C1-L7b"};
  const sim::LampSensors sensors(map, robot, so);
  const test::DriveRecord drive =
      test::drive_through({{1, 10}, {21, 10}}, 0.0, sensors, robot.semi_axis);
  SurveyOptions o;
  o.start = drive.start;  // a drive along one corridor fits each of its lamps alike
  const SurveyResult s = survey(map, test::map_drive(drive, robot), robot, o);
  std::map<std::string, std::string> where;
  for (const auto& f : s.findings) {
    std::cout << to_string(f.status) << " " << f.lamp << " (" << f.where << ")\n";
    where[f.lamp] = f.where;
  }
  const std::map<std::string, std::string> want = {
      {"C1-L2a", "C1, 2nd lamp of the left row from E1"},   // walking east: north is left
      {"C1-L7b", "C1, 2nd lamp of the left row from J1"}};  // walking west: south is left
  EXPECT_EQ(where, want);
}

// One lamp beside a corridor's row (an exit sign's light, a crossing corridor's first lamp in the
// region) makes no second row: the row's lamps keep their plain order.
TEST(Survey, ALampAloneBesideTheRowMakesNoSecondRow) {
  const graph::TopologicalMap map = test::edited(
      graph::read_map(test::source_path("maps/office_floor.geojson")).map, [](graph::Node& n) {
        if (n.name != "C1") return;
        graph::Lamp beside = n.lamps[4];
        beside.id = LampId("C1-BESIDE");
        beside.xyz.y() += 0.9;
        n.lamps.insert(n.lamps.begin() + 5, beside);
      });
  const RobotDescription robot =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  sim::LampSensorOptions so;
  so.failed_lamps = {"C1-L3"};
  const sim::LampSensors sensors(map, robot, so);
  const test::DriveRecord drive =
      test::drive_through({{1, 10}, {21, 10}}, 0.0, sensors, robot.semi_axis);
  SurveyOptions o;
  o.start = drive.start;
  const SurveyResult s = survey(map, test::map_drive(drive, robot), robot, o);
  ASSERT_EQ(s.findings.size(), 1u);
  EXPECT_EQ(s.findings[0].lamp, "C1-L3");
  EXPECT_EQ(s.findings[0].where, "C1, 3rd lamp from E1");
}

// Wheels that read 1 % long (not calibrated): the drive's lamps 40 m from where the survey
// anchors them are 40 cm off, and before the drive was scaled to the map, 16 of the 27 lamps of
// a drive E1 -> K2 were reported moved. The map holds the scale: the same six changes and
// nothing else.
TEST(Survey, ADriveWhoseWheelsReadLongFindsTheSameChanges) {
  test::DriveOptions wheels;
  wheels.scale_error_left = wheels.scale_error_right = 0.01;
  const SurveyResult s = survey_of_the_changed_office(wheels);
  EXPECT_NEAR(1 / s.drive_scale - 1, 0.01, 0.002);
}

// The drive's detector looks for one kind of lamp (the office's long ones): a round lamp the map
// has in a corridor is not judged. Before, it was reported failed, and --update took it out of
// the map.
TEST(Survey, LampsOfAKindTheDriveDoesNotSeeAreNotJudged) {
  const graph::TopologicalMap world =
      graph::read_map(test::source_path("maps/office_floor.geojson")).map;
  const graph::TopologicalMap map = test::edited(world, [](graph::Node& c) {
    if (c.name != "C6") return;
    graph::Lamp round = c.lamps[1];
    round.id = LampId("C6-ROUND");
    round.shape = graph::LampShape::disc;
    round.length = round.width = 0.6;
    round.xyz.x() = 0.5 * (c.lamps[1].xyz.x() + c.lamps[2].xyz.x());
    c.lamps.insert(c.lamps.begin() + 2, round);
  });
  const RobotDescription robot =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  // Sensors of the world without the round lamp: a detector that does not look for it.
  const sim::LampSensors sensors(world, robot);
  const test::DriveRecord drive =
      test::drive_through(test::office_every_corridor(), 0.0, sensors, robot.semi_axis);
  const SurveyResult s = survey(map, test::map_drive(drive, robot), robot);
  for (const auto& f : s.findings) ADD_FAILURE() << to_string(f.status) << " " << f.lamp;
  EXPECT_GT(s.judged, 40);
  EXPECT_EQ(s.ok, s.judged);
  EXPECT_NE(s.updated.find_lamp(LampId("C6-ROUND")), nullptr);
}

}  // namespace
}  // namespace lampnav::mapping
