// Tracking lamps frame to frame along a simulated corridor drive.

#include <map>
#include <random>
#include <set>

#include "lampnav/graph/geojson.hpp"
#include "lampnav/sim/renderers.hpp"
#include "lampnav/vision/lamp_tracker.hpp"
#include "lampnav_test.hpp"
#include "office_world.hpp"

namespace lampnav::vision {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

using World = test::OfficeWorld;

// The lamp whose projected centre is nearest a detection: lamps are hundreds of pixels apart.
std::string lamp_under(const sim::CeilingRenderer& r, const Pose2& pose,
                       const std::vector<const graph::Lamp*>& lamps, const LampDetection& d) {
  std::string best;
  double best_d = 1e18;
  for (const auto* l : lamps) {
    const auto p = r.project(pose, {}, l->xyz);
    if (!p) continue;
    const double dist = (*p - d.centre_px).norm();
    if (dist < best_d) {
      best_d = dist;
      best = l->id.value;
    }
  }
  return best;
}

TEST(LampTracker, OneTrackPerLampWhileInView) {
  const World w;
  const sim::CeilingRenderer renderer(w.camera(), {});
  LampTracker tracker(w.camera(), LampShapePrior{});
  const graph::Node& c1 = *w.map.find_node("C1");
  const Vector2d dir = c1.axis->direction();
  const double yaw = std::atan2(dir.y(), dir.x());
  std::mt19937_64 rng(5);
  std::map<int, std::string> lamp_of_track;
  std::map<std::string, std::set<int>> tracks_of_lamp;
  std::set<int> live, ended;
  int frames_with_lamps = 0;
  // 0.5 m/s at 10 Hz: 5 cm a frame, 40 px on the ceiling.
  for (double s = 0.5; s < c1.axis->length() - 0.5; s += 0.05) {
    const Pose2 pose(c1.axis->point_at(s) + Vector2d(-dir.y(), dir.x()) * 0.2 * std::sin(s), yaw);
    const auto lamps = w.map.lamps_within(pose.translation(), 5.0);
    const TrackedFrame f = tracker.process(renderer.render(pose, {}, lamps, rng));
    if (!f.lamps.empty()) ++frames_with_lamps;
    for (int id : f.ended) {
      EXPECT_TRUE(live.count(id)) << "track " << id << " ended without being live";
      live.erase(id);
      EXPECT_TRUE(ended.insert(id).second) << "track " << id << " ended twice";
    }
    for (const auto& t : f.lamps) {
      EXPECT_FALSE(ended.count(t.track_id)) << "ended track " << t.track_id << " came back";
      EXPECT_EQ(t.is_new, !live.count(t.track_id));
      live.insert(t.track_id);
      const std::string lamp = lamp_under(renderer, pose, lamps, t.detection);
      auto [it, inserted] = lamp_of_track.emplace(t.track_id, lamp);
      EXPECT_EQ(it->second, lamp) << "track " << t.track_id << " jumped to another lamp";
      tracks_of_lamp[lamp].insert(t.track_id);
    }
  }
  EXPECT_GT(frames_with_lamps, 100);
  // Each lamp passed over was followed by exactly one track from entering to leaving the view.
  ASSERT_GE(tracks_of_lamp.size(), 5u);
  for (const auto& [lamp, ids] : tracks_of_lamp) EXPECT_EQ(ids.size(), 1u) << lamp;
}

TEST(LampTracker, ResetEndsEveryTrackAndBadFramesLeaveTracksAlone) {
  const World w;
  const sim::CeilingRenderer renderer(w.camera(), {});
  LampTracker tracker(w.camera(), LampShapePrior{});
  std::mt19937_64 rng(8);
  const Pose2 pose(w.map.find_node("C1")->axis->point_at(3.0), 0.0);
  const Image8 img = renderer.render(pose, {}, w.map.lamps_within(pose.translation(), 5), rng);
  const auto first = tracker.process(img);
  ASSERT_FALSE(first.lamps.empty());
  EXPECT_THROW(tracker.process(Image8(100, 100)), InputError);
  EXPECT_EQ(tracker.live_tracks(), static_cast<int>(first.lamps.size()));
  const auto second = tracker.process(img);
  ASSERT_EQ(second.lamps.size(), first.lamps.size());
  EXPECT_EQ(second.lamps[0].track_id, first.lamps[0].track_id);
  EXPECT_EQ(second.lamps[0].age, 2);
  tracker.reset();
  const auto third = tracker.process(img);
  EXPECT_EQ(third.ended.size(), first.lamps.size());
  ASSERT_FALSE(third.lamps.empty());
  EXPECT_TRUE(third.lamps[0].is_new);
  EXPECT_GT(third.lamps[0].track_id, second.lamps.back().track_id);
  // A black frame ends them all.
  const auto dark = tracker.process(Image8(352, 288, 0));
  EXPECT_TRUE(dark.lamps.empty());
  EXPECT_EQ(dark.ended.size(), third.lamps.size());
}

}  // namespace
}  // namespace lampnav::vision
