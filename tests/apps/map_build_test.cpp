// `lampnav map build` end to end: a drive recorded by `lampnav sim` (rendered frames, the real
// detector) becomes a valid map whose lamps are where the true ones are, without the log's map.

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "alignment.hpp"
#include "cli_support.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav_test.hpp"

namespace lampnav {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

struct Recorded {
  fs::path dir = fs::temp_directory_path() / ("lampnav_map_build_" + std::to_string(::getpid()));
  std::string log = (dir / "drive.mcap").string();
  Recorded() {
    fs::create_directories(dir);
    const auto r = test::run_lampnav(
        "sim --route 'E1 -> K2' --map " + test::quoted_source("maps/office_floor.geojson") +
        " --robot " + test::quoted_source("maps/robots/pioneer.json") + " -o '" + log + "'");
    EXPECT_EQ(r.status, 0) << r.err;
  }
  ~Recorded() { fs::remove_all(dir); }
};

TEST(MapBuild, ADriveBecomesAValidMapWithTheLampsWhereTheyAre) {
  const Recorded rec;
  const std::string out = (rec.dir / "built.geojson").string();
  const auto r = test::run_lampnav("map build '" + rec.log + "' -o '" + out + "' --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  std::cout << r.out << r.err;
  EXPECT_THAT(r.out, HasSubstr("lamps"));
  // The drive turned twice and never came back: it says the loop was never closed.
  EXPECT_THAT(r.err, HasSubstr("no loop closed"));
  const auto check = test::run_lampnav("map check '" + out + "'");
  EXPECT_EQ(check.status, 0) << check.err;
  EXPECT_THAT(check.out, HasSubstr("valid"));

  // The lamps, moved into the true map's frame by the drive's first true pose, lie on the true
  // lamps; every lamp the drive passed under is there once.
  const graph::TopologicalMap built = graph::read_map(out).map;
  const graph::TopologicalMap truth =
      graph::read_map(test::source_path("maps/office_floor.geojson")).map;
  const io::MissionLog log = io::read_mission_log(rec.log);
  ASSERT_FALSE(log.truth.empty());
  const Pose2 start = log.truth.front().value.pose;
  std::set<std::string> matched;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> pairs;
  for (const auto& n : built.nodes()) {
    for (const auto& l : n.lamps) {
      const Eigen::Vector2d at = start.transform_from(l.xyz.head<2>());
      const auto near = truth.lamps_within(at, 0.3);
      ASSERT_FALSE(near.empty()) << l.id.value << " at " << at.transpose();
      EXPECT_TRUE(matched.insert(near.front()->id.value).second) << "twice: " << l.id.value;
      pairs.emplace_back(l.xyz.head<2>(), near.front()->xyz.head<2>());
    }
  }
  // After the best rigid alignment (the map's frame is the drive's start).
  const test::RigidFit fit = test::fit_rigid(pairs);
  double worst = 0, sum = 0;
  for (const auto& [b, t] : pairs) {
    const double e = (fit.apply(b) - t).norm();
    worst = std::max(worst, e);
    sum += e * e;
  }
  // Under the drive: C1, C5 and C4 and the places between them (E1, J1, J2, K2).
  std::size_t under = 0;
  for (const char* name : {"E1", "C1", "J1", "C5", "J2", "C4", "K2"})
    under += truth.find_node(name)->lamps.size();
  EXPECT_EQ(matched.size(), under);
  const double rms = std::sqrt(sum / std::max<std::size_t>(1, matched.size()));
  std::cout << matched.size() << " lamps, error rms " << rms * 100 << " cm, max " << worst * 100
            << " cm\n";
  // The targets, met on one pass with no loop to close.
  EXPECT_LE(rms, 0.02);
  EXPECT_LE(worst, 0.05);
}

TEST(MapBuild, RefusesWhatCannotMakeAMap) {
  // A log without ceiling frames: the domus scenario records the omni camera only.
  const fs::path dir =
      fs::temp_directory_path() / ("lampnav_map_refuse_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string log = (dir / "omni.mcap").string();
  ASSERT_EQ(test::run_lampnav("sim --scenario domus-global -o '" + log + "'").status, 0);
  const auto r = test::run_lampnav("map build '" + log + "' -o '" + (dir / "m.geojson").string() +
                                   "' --quiet");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("/ceiling_camera/image"));
  EXPECT_THAT(r.err, HasSubstr("no ceiling camera frames"));
  EXPECT_FALSE(fs::exists(dir / "m.geojson"));
  // Not a log at all, and a bad names file.
  const auto bad =
      test::run_lampnav("map build " + test::quoted_source("maps/office_floor.geojson") + " -o '" +
                        (dir / "m.geojson").string() + "'");
  EXPECT_EQ(bad.status, 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lampnav
