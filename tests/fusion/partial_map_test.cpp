// Global localization and the hypothesis set on a map of part of a building: the map that
// `lampnav map build` made of the drive Office 1 -> Lab 3 of the bundled office (seed 5, placed
// on the office by its lamps), the whole office rendered. Its first places hold two lamps, and
// the omni camera sees a dozen lamps there that the map lacks.

#include <random>

#include "hypothesis_weighing.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/hypothesis_set.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/sim/renderers.hpp"
#include "lampnav/vision/omni_detector.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

struct PartialOffice {
  graph::TopologicalMap building =
      graph::read_map(test::source_path("maps/office_floor.geojson")).map;
  graph::TopologicalMap built =
      graph::read_map(test::fixture("maps/built_office1_to_lab3.geojson")).map;
  RobotDescription robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  const CameraDescription& cam() const { return *robot.find_camera("omni_camera"); }

  vision::OmniDetection view(const Pose2& pose, std::uint64_t seed) const {
    std::vector<const graph::Lamp*> lamps;
    for (const auto& n : building.nodes())
      for (const auto& l : n.lamps) lamps.push_back(&l);
    std::mt19937_64 rng(seed);
    const Image8 img =
        sim::OmniRenderer(cam(), sim::OmniRenderOptions{}).render(pose, {}, lamps, rng);
    return vision::OmniLampDetector(cam()).detect(vision::ImageView::of(img));
  }
};

bool found(const GlobalLocalization& r, const Pose2& truth) {
  for (const PoseHypothesis& h : r.hypotheses)
    if ((h.pose.translation() - truth.translation()).norm() < 0.3 &&
        std::abs(wrap_angle(h.pose.yaw() - truth.yaw())) < 3 * M_PI / 180)
      return true;
  return false;
}

// Leaving Office 1 by its door, where the built map has two lamps (the office's and the
// corridor's over the door) and the omni camera sees a dozen it lacks: a search that calls itself
// complete holds the truth, but where the map itself fits another pose better. Two things lost
// it before, each shown here by switching it off:
// - a candidate's first refinement, its lamps matched within a cell, matched a lamp the map
//   lacks to one it has and ended a metre off, scoring as well as the truth; it is now refined
//   again from where it was (refine_moved_again);
// - with four seeds, two of them lamps beyond the map's places (the corridor past its end)
//   dropped the true pose before it was scored; they now say nothing (count_beyond_map).
TEST(PartialMap, ACompleteSearchHoldsTheTruthWhereTheMapHasFewLamps) {
  const PartialOffice o;
  // The drive's poses as the robot leaves the office (seed 6 of the same route).
  const std::vector<Pose2> path = {
      {10.4847, 7.0325, 1.8314}, {10.3558, 7.5156, 1.8314}, {10.2270, 7.9987, 1.8314},
      {10.0982, 8.4818, 1.8314}, {10.0189, 8.9100, 1.6671}, {10.0025, 9.1413, 1.6207},
      {9.9942, 9.3800, 1.5921},  {9.9916, 9.6223, 1.5722},  {9.9918, 9.7098, 1.3099},
      {9.9918, 9.7098, 0.9099},  {10.0133, 9.7234, 0.5116}, {10.1527, 9.7751, 0.2522}};
  GlobalLocalizerOptions once, counted;
  once.pairs.refine_moved_again = false;
  counted.pairs.count_beyond_map = true;
  const GlobalLocalizer global(o.built, o.cam()), refined_once(o.built, o.cam(), once),
      seeds_counted(o.built, o.cam(), counted);
  const double margin = -2 * std::log(1e-4);
  const auto lost = [&](const GlobalLocalizer& g, const vision::OmniDetection& d,
                        const Pose2& truth) {
    const GlobalLocalization r = g.enumerate(d, 512, margin);
    return r.complete && !found(r, truth);
  };
  int complete = 0, lost_now = 0, lost_once = 0, lost_counted = 0;
  for (std::size_t k = 0; k < path.size(); ++k)
    for (std::uint64_t seed = 0; seed < 4; ++seed) {
      const auto d = o.view(path[k], 100 * k + seed);
      complete += global.enumerate(d, 512, margin).complete;
      // The one pose where the map fits better 0.51 m and 7 degrees off (its lamps there are
      // few: the refined truth goes there, matching one more blob).
      const bool map_off = k == 2;
      const bool l = lost(global, d, path[k]);
      EXPECT_TRUE(!l || map_off) << "at " << path[k] << " (view " << seed << ")";
      lost_now += l;
      lost_once += lost(refined_once, d, path[k]);
      lost_counted += lost(seeds_counted, d, path[k]);
    }
  std::cout << complete << " of " << 4 * path.size() << " searches complete, " << lost_now
            << " without the truth; refined once " << lost_once << ", seeds beyond the map counted "
            << lost_counted << "\n";
  EXPECT_GE(complete, 30);
  EXPECT_LE(lost_now, 4);
  EXPECT_GE(lost_once, lost_now + 4) << "refining again changed nothing: the test shows nothing";
  EXPECT_GE(lost_counted, lost_now + 1) << "seeds beyond the map changed nothing";
}

// At the corridor over Office 1's door, where the built map ends (the office's corridor goes on
// 8 m west beyond it): the omni camera sees lamps there that the map cannot have. The hypothesis
// at the truth is charged for them in the far account, bounded over all frames, not a spot each
// as for a lamp seen inside the map's places (count_beyond_map).
TEST(PartialMap, LampsBeyondTheMapCostTheTruthOneBoundedAccount) {
  const PartialOffice o;
  const GlobalLocalizer omni(o.built, o.cam());
  const Pose2 truth(9.9942, 9.3800, 1.5921);
  struct Charged {
    bool found = false;
    std::size_t spots = 0;
    double total = 0, far = 0;
  };
  const auto charged = [&](bool count_beyond_map) {
    HypothesisSetOptions opt;
    opt.count_beyond_map = count_beyond_map;
    HypothesisSet set(o.built, nullptr, &omni, CeilingPipelineOptions{}, opt);
    OdometryTrack odometry(0.2);
    Stamp t{};
    for (int k = 0; k < 6; ++k) {
      t += std::chrono::seconds(1);
      odometry.add(t, 0, 0);
      set.omni(t, o.view(truth, 600 + k), odometry);
    }
    Charged c;
    for (const Hypothesis& h : set.hypotheses())
      if ((h.pose.translation() - truth.translation()).norm() < 0.3) {
        c.found = true;
        c.spots = h.map_costs.strays.size();
        c.far = h.map_costs.far_strays;
        c.total = c.far;
        for (const auto& s : h.map_costs.strays) c.total += s.spent;
      }
    return c;
  };
  const Charged beyond_far = charged(false), each_a_spot = charged(true);
  std::cout << "lamps beyond the map: " << beyond_far.spots << " spots, " << beyond_far.total
            << " in all (far " << beyond_far.far << "); counted as spots: " << each_a_spot.spots
            << " spots, " << each_a_spot.total << " in all\n";
  ASSERT_TRUE(beyond_far.found && each_a_spot.found);
  EXPECT_LE(beyond_far.far, HypothesisSetOptions{}.far_stray_cost_max);
  EXPECT_EQ(beyond_far.spots, 0u);
  EXPECT_GE(each_a_spot.spots, 2u);
  // More than one lamp the map lacks costs (unmapped_lamp_cost) saved.
  EXPECT_GT(each_a_spot.total - beyond_far.total, HypothesisSetOptions{}.unmapped_lamp_cost);
}

// Where the blobs no lamp explains are charged (HypothesisWeigher): a lamp placed well within a
// place of the map, to a spot of its own; placed well beyond every place, to the far account and
// never less than beyond_map_blob_cost an image, the account spent or not (a twin that left the
// truth's blobs beyond the map's end paid nothing for them once its account was spent, and was
// published 48 m off: FailedLampsAndCarries.BlobsLeftBeyondTheMapAreNeverFree); placed loosely
// (a lamp the map lacks, seen far off), to the far account alone, at most far_stray_cost_max in
// all.
TEST(PartialMap, BlobsPlacedBeyondTheMapAreChargedInEveryImage) {
  using detail::HypothesisWeigher;
  const PartialOffice o;
  const GlobalLocalizer omni(o.built, o.cam());
  const HypothesisSetOptions opt;
  const HypothesisWeigher w(o.built, nullptr, &omni, CeilingPipelineOptions{}, opt);
  const Eigen::Vector2d in_a_place = (*o.built.nodes().begin()).point;
  const Eigen::Vector2d nowhere = in_a_place + Eigen::Vector2d(200, 200);
  ASSERT_EQ(o.built.node_near(nowhere, 5.0), nullptr);
  EXPECT_EQ(w.kind({in_a_place, 0.3}), HypothesisWeigher::StrayKind::spot);
  EXPECT_EQ(w.kind({nowhere, 0.3}), HypothesisWeigher::StrayKind::beyond);
  EXPECT_EQ(w.kind({nowhere, opt.stray_reach_max_m + 0.5}), HypothesisWeigher::StrayKind::far);
  const auto n = w.count_strays({{in_a_place, 0.3}, {nowhere, 0.3}, {nowhere, 0.2}, {nowhere, 3}});
  EXPECT_EQ(n.spots, 1);
  EXPECT_EQ(n.beyond, 2);

  // Three far blobs an image, two of them placed beyond the map: the account first, up to its
  // bound, then the floor on the two.
  double spent = 0;
  double charged = 0;
  for (int image = 0; image < 5; ++image) {
    const double c = w.far_charge(spent, w.far_cost(3, 0), 2);
    EXPECT_GE(c, 2 * opt.beyond_map_blob_cost - 1e-12) << "image " << image;
    charged += c;
  }
  EXPECT_DOUBLE_EQ(spent, opt.far_stray_cost_max);
  EXPECT_NEAR(charged, opt.far_stray_cost_max + 4 * 2 * opt.beyond_map_blob_cost, 1e-9);
  // Loosely placed blobs alone cost nothing more once the account is spent.
  EXPECT_EQ(w.far_charge(spent, w.far_cost(3, 0), 0), 0.0);

  HypothesisSetOptions whole = opt;
  whole.count_beyond_map = true;
  const HypothesisWeigher counted(o.built, nullptr, &omni, CeilingPipelineOptions{}, whole);
  EXPECT_EQ(counted.kind({nowhere, 0.3}), HypothesisWeigher::StrayKind::spot);
}

}  // namespace
}  // namespace lampnav::fusion
