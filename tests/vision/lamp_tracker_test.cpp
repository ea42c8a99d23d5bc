// Tracking lamps frame to frame along a simulated corridor drive.

#include <algorithm>
#include <iostream>
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

// A drive with what windows must survive: speed changes, a sway, turns in place at both ends of a
// corridor, a dark stretch, a lamp that fails and comes back. Frames in driving order.
struct Drive {
  std::vector<Image8> frames;
  std::vector<int> relit;  // frames where the failed lamp comes back on, in the middle of the view
};

Drive hard_drive(const World& w, const CameraDescription& camera) {
  const sim::CeilingRenderer renderer(camera, {});
  const graph::Node& c1 = *w.map.find_node("C1");
  const Vector2d dir = c1.axis->direction();
  const double yaw = std::atan2(dir.y(), dir.x());
  std::mt19937_64 rng(11);
  std::normal_distribution<double> bump(0, 0.5 * M_PI / 180);
  std::uniform_real_distribution<double> speed(0.02, 0.07);  // m a frame (0.2 to 0.7 m/s at 10 Hz)
  Drive d;
  auto shoot = [&](const Pose2& pose, bool failed_off) {
    auto lamps = w.map.lamps_within(pose.translation(), 5.0);
    if (failed_off && !lamps.empty()) {
      // The lamp nearest the robot is out.
      const auto nearest = std::min_element(
          lamps.begin(), lamps.end(), [&](const graph::Lamp* a, const graph::Lamp* b) {
            return (Vector2d(a->xyz.x(), a->xyz.y()) - pose.translation()).norm() <
                   (Vector2d(b->xyz.x(), b->xyz.y()) - pose.translation()).norm();
          });
      lamps.erase(nearest);
    }
    d.frames.push_back(renderer.render(pose, {bump(rng), bump(rng)}, lamps, rng));
  };
  // Turn in place at the start, 90 degrees in 18 frames.
  const Vector2d start = c1.axis->point_at(0.6);
  for (int k = 0; k <= 18; ++k) shoot(Pose2(start, yaw - M_PI / 2 + k * M_PI / 36), false);
  double s = 0.6;
  int frame = 0;
  while (s < c1.axis->length() - 0.6) {
    s += speed(rng);
    ++frame;
    const Pose2 pose(c1.axis->point_at(s) + Vector2d(-dir.y(), dir.x()) * 0.25 * std::sin(2 * s),
                     yaw + 0.08 * std::sin(s));
    // Frames 40 to 52: the nearest lamp is out; then it comes back on in mid view.
    const bool off = frame >= 40 && frame < 52;
    if (frame == 52) d.relit.push_back(static_cast<int>(d.frames.size()));
    if (frame >= 80 && frame < 85) {
      d.frames.emplace_back(camera.width, camera.height, 0);  // dark: the lights are off
      continue;
    }
    shoot(pose, off);
  }
  const Vector2d end = c1.axis->point_at(s);
  for (int k = 0; k <= 18; ++k) shoot(Pose2(end, yaw + k * M_PI / 36), false);
  return d;
}

// Windowed frames report exactly the lamps a detection of the whole frame reports, with the same
// tracks, except for a lamp that appears away from the border: it waits for the next whole frame.
void expect_windows_match_whole_frames(const CameraDescription& camera) {
  const World w;
  const Drive drive = hard_drive(w, camera);
  LampTrackerOptions whole_options;
  whole_options.full_detection_every = 1;
  LampTracker whole(camera, LampShapePrior{}, {}, whole_options);
  LampTrackerOptions windowed_options;
  LampTracker windowed(camera, LampShapePrior{}, {}, windowed_options);
  std::map<int, int> track_of;  // whole's track id -> windowed's
  int windowed_frames = 0, lamps = 0, late = 0;
  long pixels = 0;
  int since_relit = 1000;
  for (std::size_t i = 0; i < drive.frames.size(); ++i) {
    if (std::count(drive.relit.begin(), drive.relit.end(), static_cast<int>(i))) since_relit = 0;
    const TrackedFrame a = whole.process(drive.frames[i]);
    const TrackedFrame b = windowed.process(drive.frames[i]);
    ASSERT_TRUE(a.whole);
    windowed_frames += b.whole ? 0 : 1;
    pixels += b.pixels_read;
    lamps += static_cast<int>(a.lamps.size());
    const bool relit_window = since_relit++ < windowed_options.full_detection_every;
    if (relit_window && a.lamps.size() > b.lamps.size()) {
      ++late;  // the relit lamp, not read yet: both sides are compared from its next whole frame
      continue;
    }
    ASSERT_EQ(a.lamps.size(), b.lamps.size()) << "frame " << i << (b.whole ? " (whole)" : "");
    for (std::size_t k = 0; k < a.lamps.size(); ++k) {
      const TrackedLamp& x = a.lamps[k];
      // Tracks are numbered alike while both see the same lamps; match by the lamp seen.
      const auto y = std::find_if(b.lamps.begin(), b.lamps.end(), [&](const TrackedLamp& t) {
        return t.detection.centre_px == x.detection.centre_px;
      });
      ASSERT_NE(y, b.lamps.end()) << "frame " << i << ": lamp at "
                                  << x.detection.centre_px.transpose() << " not found";
      EXPECT_EQ(y->detection.view, x.detection.view);
      EXPECT_EQ(y->detection.orientation, x.detection.orientation);
      const auto [it, fresh] = track_of.emplace(x.track_id, y->track_id);
      EXPECT_EQ(it->second, y->track_id) << "frame " << i << ": the lamp changed track";
      if (!relit_window) {
        EXPECT_EQ(fresh, x.is_new) << "frame " << i;
      }
    }
  }
  EXPECT_LT(late, windowed_options.full_detection_every);  // found by the next whole frame
  EXPECT_GT(lamps, 300);
  // Most frames were windowed, and they read a small part of the image.
  EXPECT_GT(windowed_frames, static_cast<int>(drive.frames.size()) / 2) << drive.frames.size();
  EXPECT_LT(static_cast<double>(pixels) / (drive.frames.size() * camera.width * camera.height),
            0.5);
  std::cout << drive.frames.size() << " frames, " << windowed_frames << " windowed, "
            << 100.0 * pixels /
                   (static_cast<double>(drive.frames.size()) * camera.width * camera.height)
            << " % of the pixels read, " << late << " frames late for the relit lamp\n";
}

TEST(LampTracker, WindowedFramesReportTheLampsOfWholeFrames) {
  const World w;
  expect_windows_match_whole_frames(w.camera());
}

TEST(LampTracker, WindowedFramesReportTheLampsOfWholeFramesAt640) {
  const World w;
  expect_windows_match_whole_frames(w.camera_640());
}

TEST(LampTracker, OptionsAreChecked) {
  const World w;
  LampTrackerOptions o;
  o.full_detection_every = 0;
  EXPECT_THROW(LampTracker(w.camera(), LampShapePrior{}, {}, o), InputError);
  o = {};
  o.window_margin_px = 0;
  EXPECT_THROW(LampTracker(w.camera(), LampShapePrior{}, {}, o), InputError);
}

}  // namespace
}  // namespace lampnav::vision
