// The omni check of the kidnap monitor: rendered omnidirectional views checked against the true
// pose (consistent) and against poses a kidnap away (inconsistent), on both bundled maps.

#include <random>

#include "lampnav/fusion/kidnap_monitor.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/sim/renderers.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

struct Tally {
  int consistent = 0, inconsistent = 0, inconclusive = 0;
};

// The pioneer's omni camera rendering a building's lamps, and its detector.
struct Camera {
  RobotDescription robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  const CameraDescription& cam = *robot.find_camera("omni_camera");
  const sim::OmniRenderer renderer{cam, sim::OmniRenderOptions{}};
  vision::OmniLampDetector detector{cam};
  std::vector<vision::OmniBlob> blobs(const graph::TopologicalMap& building, const Pose2& pose,
                                      const sim::CameraTilt& tilt, std::mt19937_64& rng) {
    std::vector<const graph::Lamp*> lamps;
    for (const auto& n : building.nodes())
      for (const auto& l : n.lamps) lamps.push_back(&l);
    const Image8 img = renderer.render(pose, tilt, lamps, rng);
    return detector.detect(vision::ImageView::of(img)).blobs;
  }
};

std::pair<Tally, Tally> check_map(const std::string& map_file, std::uint64_t seed) {
  const graph::TopologicalMap map = graph::read_map(test::source_path(map_file)).map;
  Camera camera;
  const OmniCheck check(map, camera.cam);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> bump(0, 0.5 * M_PI / 180);
  const Eigen::Matrix3d P = Eigen::Vector3d(4e-4, 4e-4, 1e-4).asDiagonal();
  Tally at_truth, kidnapped;
  auto tally = [](const OmniCheckResult& r, Tally& t) {
    if (!r.conclusive)
      ++t.inconclusive;
    else if (r.consistent)
      ++t.consistent;
    else
      ++t.inconsistent;
  };
  std::vector<const graph::Node*> lit;
  for (const auto& n : map.nodes())
    if (!n.lamps.empty()) lit.push_back(&n);
  int done = 0;
  while (done < 60) {
    const graph::Node& n = *lit[rng() % lit.size()];
    const Pose2 truth(n.point.x() + 0.5 * (u(rng) - 0.5), n.point.y() + 0.5 * (u(rng) - 0.5),
                      2 * M_PI * u(rng));
    const auto blobs = camera.blobs(map, truth, {bump(rng), bump(rng)}, rng);
    tally(check.check(truth, P, blobs), at_truth);
    const double a = 2 * M_PI * u(rng);
    const Pose2 away(truth.x() + 4 * std::cos(a), truth.y() + 4 * std::sin(a),
                     truth.yaw() + 0.35 * (u(rng) - 0.5));
    tally(check.check(away, P, blobs), kidnapped);
    ++done;
  }
  std::cout << map_file << ": at the true pose " << at_truth.consistent << " consistent, "
            << at_truth.inconsistent << " inconsistent, " << at_truth.inconclusive
            << " inconclusive; 4 m away " << kidnapped.consistent << " consistent, "
            << kidnapped.inconsistent << " inconsistent, " << kidnapped.inconclusive
            << " inconclusive\n";
  return {at_truth, kidnapped};
}

TEST(OmniCheck, MuseumTruthConsistentKidnapInconsistent) {
  const auto [truth, away] = check_map("maps/domus_museum.geojson", 3);
  EXPECT_EQ(truth.inconsistent, 0);
  EXPECT_GE(truth.consistent, 55);
  EXPECT_GE(away.inconsistent, 50);
}

// In the office the omni camera stands 0.9 m under the lamps: it sees few of them clearly, and
// corridors look alike. The check never contradicts the truth, and catches a 4 m kidnap in one
// frame of three; the ceiling camera's evidence does the rest there.
TEST(OmniCheck, OfficeTruthConsistentKidnapOftenInconsistent) {
  const auto [truth, away] = check_map("maps/office_floor.geojson", 4);
  EXPECT_EQ(truth.inconsistent, 0);
  EXPECT_GE(truth.consistent, 45);
  EXPECT_GE(away.inconsistent, 15);
}

// A map of part of the building (one drive's corridors: `map build`) against the view of the
// whole building: the lamps of the corridors the map lacks are most of the blobs at a junction
// or a corner. Blobs whose rays meet the ceiling beyond every place of the map say nothing, so
// the robot is not called lost where it truly is (it was, at such a junction, and then fixed on
// a wrong place 17 m off: docs/hypotheses.md). The price: on such a map the omni check alone
// seldom catches a kidnap (the estimate turned a quarter: printed), the ceiling camera must.
TEST(OmniCheck, LampsBeyondAMapOfPartOfTheBuildingDoNotCallTheTruthLost) {
  const graph::TopologicalMap whole =
      graph::read_map(test::source_path("maps/office_floor.geojson")).map;
  graph::TopologicalMap part("part");
  for (const char* name : {"J1", "C5", "J2"}) part.add_node(*whole.find_node(name));
  Camera camera;
  const OmniCheck check(part, camera.cam);
  OmniCheckOptions counting;
  counting.count_beyond_map = true;
  const OmniCheck counts_them(part, camera.cam, counting);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::Matrix3d P = Eigen::Vector3d(4e-4, 4e-4, 1e-4).asDiagonal();
  int truth_lost = 0, truth_lost_counting = 0, truth_beyond = 0, away_lost = 0;
  for (int k = 0; k < 30; ++k) {
    const graph::Node& n = *part.find_node(k % 3 == 1 ? "C5" : k % 3 == 0 ? "J1" : "J2");
    const Eigen::Vector2d at = n.axis ? n.axis->point_at(u(rng) * n.axis->length()) : n.point;
    const Pose2 truth(at.x(), at.y(), 2 * M_PI * u(rng));
    const auto blobs = camera.blobs(whole, truth, {0.0, 0.0}, rng);
    const OmniCheckResult r = check.check(truth, P, blobs);
    truth_lost += r.conclusive && !r.consistent;
    truth_beyond += r.beyond_map > 0;
    const OmniCheckResult c = counts_them.check(truth, P, blobs);
    truth_lost_counting += c.conclusive && !c.consistent;
    // Kidnapped: the estimate turned a quarter (in a corridor, its lamps then cross the view).
    const Pose2 away(truth.x(), truth.y(), truth.yaw() + M_PI / 2);
    const OmniCheckResult a = check.check(away, P, blobs);
    away_lost += a.conclusive && !a.consistent;
  }
  EXPECT_EQ(truth_lost, 0);
  EXPECT_GE(truth_beyond, 10);
  std::cout << "at the truth: " << truth_lost << " lost (" << truth_lost_counting
            << " counting the blobs beyond the map); turned a quarter: " << away_lost << " lost\n";
  EXPECT_GE(truth_lost_counting, 3) << "no view is lost counting them: the test shows nothing";
}

}  // namespace
}  // namespace lampnav::fusion
