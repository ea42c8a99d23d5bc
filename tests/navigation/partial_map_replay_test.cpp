// Replays with the start unknown on a map of part of a building: the map that `lampnav map
// build` made of the drive E1 -> Workshop of the bundled office (seed 5, placed on the office by
// its lamps' best rigid fit), and another drive of that route (seed 7) through the whole office.
// The map holds the corridors the drive took, two rows of identical lamps among them.

#include "lampnav/evaluation/replay.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav_test.hpp"

namespace lampnav {
namespace {

// While the set holds only wrong places, an omni image that contradicts every one of them is
// what starts it again. Starting again only after two such images in a row (tried on
// 2026-12-02, docs/hypotheses.md, "A map of part of a building") published three wrong poses
// on this drive, up to 33 m off: one image contradicted the wrong places and the next did not.
TEST(PartialMapReplay, ADriveWithoutItsStartIsNeverPublishedWrong) {
  const std::string geojson = test::slurp(test::source_path("maps/office_floor.geojson"));
  const graph::TopologicalMap office = graph::parse_map(geojson, "office_floor.geojson").map;
  const RobotDescription robot =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  sim::Scenario drive = sim::make_route_scenario(office, geojson, robot, "E1", "Workshop", 7);
  drive.bump_sigma_rad = 0.5 * M_PI / 180;  // as `lampnav sim` records it
  const std::string log_path = test::temp_path("partial_map_replay.mcap");
  sim::record_mission(drive, log_path);
  const io::MissionLog log = io::read_mission_log(log_path);
  std::filesystem::remove(log_path);
  const graph::TopologicalMap built =
      graph::read_map(test::fixture("maps/built_e1_to_workshop.geojson")).map;
  const evaluation::Metrics m =
      evaluation::score(evaluation::replay(log, built, robot, evaluation::ReplayOptions{}), log);
  std::cout << m.wrong_fixes << " wrong fixes; position RMS " << m.position_error_m.rms * 100
            << " cm over " << m.position_error_m.n << " poses; lost " << m.lost_s << " s\n";
  EXPECT_EQ(m.wrong_fixes, 0);
  // Found before the drive ends (a minute of look-alike corridors first), then tracked.
  EXPECT_GT(m.position_error_m.n, 0u);
  EXPECT_LE(m.position_error_m.rms, 0.05);
}

}  // namespace
}  // namespace lampnav
