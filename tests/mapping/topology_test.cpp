// Places and connections from a mapped drive: on the office floor, driven down every corridor,
// the built map has the true map's corridors, junctions, corners and ends, connected the same way,
// each lamp in the right place's sequence (up to names, and leaving out the rooms and doors the
// drive never entered).

#include "lampnav/mapping/topology.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <set>

#include "drive.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/map_checks.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav_test.hpp"

namespace lampnav::mapping {
namespace {

using Eigen::Vector2d;

// Each built node, moved into the true map's frame by `start`, lies in a true node of the same
// kind, holds the same lamps in the same order (either way along a corridor), and the built map
// links the same places as the true one's corridors, junctions, corners and ends (rooms and doors,
// which a drive down the corridors never enters, left out).
void expect_same_topology(const graph::TopologicalMap& built, const graph::TopologicalMap& truth,
                          const Pose2& start) {
  // Each built node, moved into the true map's frame, lies in a true node of the same kind.
  std::map<std::int64_t, const graph::Node*> match;
  std::map<graph::Place, int> kinds_built, kinds_true;
  for (const auto& n : built.nodes()) {
    ++kinds_built[n.place];
    const graph::Node* t = truth.node_containing(start.transform_from(n.point));
    ASSERT_NE(t, nullptr) << n.name;
    EXPECT_EQ(t->place, n.place) << n.name << " is " << t->name;
    match[n.id.value] = t;
    // Its lamps, in order, are the true node's (a corridor may be walked the other way).
    std::vector<std::string> ids, rev;
    for (const auto& l : n.lamps) {
      const auto near = truth.lamps_within(start.transform_from(l.xyz.head<2>()), 0.3);
      ASSERT_FALSE(near.empty()) << l.id.value;
      ids.push_back(near.front()->id.value);
    }
    std::vector<std::string> want;
    for (const auto& l : t->lamps) want.push_back(l.id.value);
    rev.assign(want.rbegin(), want.rend());
    EXPECT_TRUE(ids == want || ids == rev) << n.name << " (" << t->name << ")";
  }
  for (const auto& n : truth.nodes())
    if (n.place != graph::Place::door && n.place != graph::Place::room) ++kinds_true[n.place];
  EXPECT_EQ(kinds_built, kinds_true);
  // Connected the same way.
  std::set<std::pair<std::int64_t, std::int64_t>> built_links, true_links;
  for (const auto& e : built.edges())
    built_links.insert({match.at(e.start.value)->id.value, match.at(e.end.value)->id.value});
  for (const auto& e : truth.edges()) {
    const auto& a = truth.node(e.start);
    const auto& b = truth.node(e.end);
    if (a.place == graph::Place::door || b.place == graph::Place::door ||
        a.place == graph::Place::room || b.place == graph::Place::room)
      continue;
    true_links.insert({a.id.value, b.id.value});
  }
  EXPECT_EQ(built_links, true_links);
}

TEST(Topology, OfficeDrivenDownEveryCorridorHasTheTrueTopology) {
  const test::Office office;
  const graph::TopologicalMap& truth = office.map;
  const test::DriveRecord drive = office.drive(test::office_every_corridor());
  const MappingResult mapped = test::map_drive(drive, office.robot);
  TopologyReport rep;
  const graph::TopologicalMap built = build_topology(mapped, {}, {}, &rep);
  // It is a valid map: written and read back by the map reader's rules.
  const graph::LoadedMap reread = graph::parse_map(graph::write_map(built), "built");
  EXPECT_TRUE(reread.warnings.empty()) << reread.warnings.front().text();
  EXPECT_EQ(rep.lamps_outside, 0u);

  expect_same_topology(built, truth, drive.start);
  std::cout << built.node_count() << " places, " << built.edge_count() << " edges, "
            << built.lamp_count() << " lamps\n";
}

// A generated 100-node building (rooms off some corridors, a wing with another lamp spacing),
// driven down every corridor row by row and then column by column.
TEST(Topology, GeneratedBuildingDrivenDownEveryCorridorHasTheTrueTopology) {
  sim::BuildingOptions bo;
  bo.nodes = 100;
  bo.wing_lamp_spacing_m = 2.7;
  bo.seed = 5;
  const graph::TopologicalMap truth =
      graph::parse_map(sim::generate_building(bo).geojson, "generated").map;
  const test::Office office;  // for the robot
  const sim::LampSensors sensors(truth, office.robot);
  const auto waypoints = test::every_corridor_twice(truth);
  const Vector2d d0 = waypoints[1] - waypoints[0];
  const test::DriveRecord drive =
      test::drive_through(waypoints, std::atan2(d0.y(), d0.x()), sensors, office.robot.semi_axis);
  TopologyReport rep;
  const graph::TopologicalMap built =
      build_topology(test::map_drive(drive, office.robot), {}, {}, &rep);
  EXPECT_NO_THROW(graph::parse_map(graph::write_map(built), "built"));
  EXPECT_EQ(rep.lamps_outside, 0u);
  expect_same_topology(built, truth, drive.start);
  std::cout << built.node_count() << " places, " << built.edge_count() << " edges, "
            << built.lamp_count() << " lamps\n";
}

// A drive that leaves a corridor at 45 degrees and back (through walls, as a drive with a kidnap
// in it would look): regions that would overlap give way, and the map still reads back.
TEST(Topology, RegionsMetAtAnAngleGiveWay) {
  const test::Office office;
  const test::DriveRecord drive = office.drive({{1, 10}, {21, 10}, {28, 3}, {21, 10}, {41, 10}});
  TopologyReport rep;
  const graph::TopologicalMap built =
      build_topology(test::map_drive(drive, office.robot), {}, {}, &rep);
  EXPECT_GT(built.node_count(), 2u);
  EXPECT_NO_THROW(graph::parse_map(graph::write_map(built), "built"));
  for (const auto& note : rep.notes) std::cout << note << "\n";
}

}  // namespace
}  // namespace lampnav::mapping
