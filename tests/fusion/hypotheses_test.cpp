// Multi-hypothesis localization where it is hard: regular buildings whose corridors and lamps
// repeat, kidnaps into look-alike corridors, a perfectly symmetric building. Driven by the
// battery (tests/support/battery.hpp): ideal detections from both cameras, noisy odometry,
// frames late as on the robot. The rule under test: never a pose published as certain that is
// wrong; "it is one of these" is always allowed.

#include <iostream>

#include "battery.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

struct Building {
  sim::Building b;
  graph::TopologicalMap map;
  RobotDescription robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  explicit Building(const sim::BuildingOptions& o)
      : b(sim::generate_building(o)), map(graph::parse_map(b.geojson, "generated").map) {}
};

// The office: a 3 x 3 grid of junctions 12 m apart, one corridor missing (so no
// rotation maps it onto itself), identical 1.2 x 0.3 m lamps every 2.4 m and one over each
// junction.
sim::BuildingOptions grid_office() {
  sim::BuildingOptions o;
  o.nodes = 21;
  o.block_m = 12;
  o.lamp_spacing_m = 2.4;
  o.rooms = false;
  o.missing_corridors = 1;
  o.seed = 3;
  return o;
}

TEST(Hypotheses, GridOfficeFromAnUnknownStartIsNeverConfidentlyWrong) {
  const Building w(grid_office());
  test::Battery battery(w.map, w.robot);
  std::vector<test::EpisodeResult> rs;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    rs.push_back(battery.unknown_start(seed));
    const auto& r = rs.back();
    std::cout << "seed " << seed << ": fixed " << r.fixed << " error " << r.fix_error_m
              << " after " << r.latency_m << " m, wrong " << r.wrong_fixes << ", at most "
              << r.max_hypotheses << " hypotheses " << r.last_why << "\n";
  }
  std::cout << test::summarize(rs) << "\n";
  for (const auto& r : rs) {
    EXPECT_EQ(r.wrong_fixes, 0);
    EXPECT_TRUE(r.fixed);
    EXPECT_TRUE(r.fix_correct);
  }
}

TEST(Hypotheses, GridOfficeKidnapsIntoLookAlikeCorridors) {
  const Building w(grid_office());
  test::Battery battery(w.map, w.robot);
  std::vector<test::EpisodeResult> rs;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    rs.push_back(battery.kidnap(seed));
    const auto& r = rs.back();
    std::cout << "seed " << seed << ": detected " << r.detected << " fixed " << r.fixed
              << " error " << r.fix_error_m << " after " << r.latency_s << " s " << r.latency_m
              << " m, wrong " << r.wrong_fixes << ", at most " << r.max_hypotheses
              << " hypotheses " << r.last_why << "\n";
  }
  std::cout << test::summarize(rs) << "\n";
  for (const auto& r : rs) {
    EXPECT_EQ(r.wrong_fixes, 0);
    EXPECT_TRUE(r.detected);
    EXPECT_TRUE(r.fix_correct);
  }
}

}  // namespace
}  // namespace lampnav::fusion
