// The localizer on simulated missions, read back from their logs and fed in arrival order:
// accuracy on the corridor with the camera 1 s late (with and without half the frames dark),
// kidnaps detected (latency measured from the first frame after the kidnap that shows a lamp),
// no false alarm on kidnap-free runs, relocalization by a global fix.

#include <unistd.h>

#include <filesystem>
#include <limits>
#include <random>

#include "edited_map.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/fusion/localizer.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

struct Kidnapped {
  Stamp at;                    // lifted (log event)
  bool recovered = false;      // a correct fix from a frame after it, whether detected or not
  std::optional<Stamp> shown;  // capture of the first frame after it that shows a lamp
  std::optional<Stamp> lost;   // when the localizer declared it lost
  double latency() const { return to_seconds(*lost - *shown); }
};

struct Outcome {
  int wheel_steps = 0, ceiling_frames = 0, dark_frames = 0, scored = 0;
  double sum2_pos = 0, sum2_yaw = 0, max_pos = 0, max_yaw = 0;
  std::vector<Kidnapped> kidnaps;
  int false_alarms = 0, relocalizations = 0;
  double max_fix_error = 0;  // m, of the relocalizer's fixes when made
  int bad_fixes = 0, bad_fixes_caught = 0;
  bool recovered_at_end = true;                   // the last kidnap followed by a correct fix
  std::vector<std::pair<double, double>> p_norm;  // (s, |P|)
  double rms_pos() const { return std::sqrt(sum2_pos / scored); }
  double rms_yaw_deg() const { return std::sqrt(sum2_yaw / scored) * 180 / M_PI; }
  std::string summary() const {
    std::ostringstream s;
    s << scored << " estimates scored, " << ceiling_frames << " ceiling frames (" << dark_frames
      << " dark): position RMS " << rms_pos() * 100 << " cm (max " << max_pos * 100 << "), yaw RMS "
      << rms_yaw_deg() << " deg (max " << max_yaw * 180 / M_PI << "); " << kidnaps.size()
      << " kidnaps, " << false_alarms << " false alarms, " << relocalizations << " fixes ("
      << bad_fixes << " wrong, " << bad_fixes_caught << " caught)";
    for (const auto& k : kidnaps) {
      s << "\n  kidnap at " << to_seconds(k.at) << " s: ";
      if (k.recovered && !k.lost)
        s << "recovered by a fix from a frame after it before the loss was noticed";
      else if (!k.shown)
        s << "no lamp shown";
      else if (!k.lost)
        s << "NOT DETECTED";
      else
        s << "lamp shown at " << to_seconds(*k.shown) << " s, lost at " << to_seconds(*k.lost)
          << " s, latency " << k.latency() << " s";
    }
    return s.str();
  }
};

struct World {
  std::string geojson;
  graph::TopologicalMap map;
  RobotDescription robot = read_robot_description(test::source_path("maps/robots/pioneer.json"));
  explicit World(const std::string& map_file)
      : geojson(test::slurp(test::source_path(map_file))),
        map(graph::parse_map(geojson, map_file).map) {}
};

io::MissionLog record(const sim::Scenario& s) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("lampnav_localizer_" + std::to_string(::getpid()) + ".mcap"))
                               .string();
  sim::record_mission(s, path);
  io::MissionLog log = io::read_mission_log(path);
  std::filesystem::remove(path);
  return log;
}

// Feeds the log in arrival order, starting from the true pose. When lost, the localizer
// relocalizes itself from the omni frames; each fix is scored against the truth.
// Without `start_known` the localizer is not told where the robot starts.
Outcome replay(const sim::Scenario& s, const io::MissionLog& log, const graph::TopologicalMap& map,
               bool start_known = true, const LocalizerOptions& options = {}) {
  Localizer loc(map, s.robot, options);
  const io::TruthTrack truth(log.truth);
  enum Kind { wheels, ceiling, omni };
  struct Item {
    Stamp arrival;
    Kind kind;
    std::size_t index;
  };
  std::vector<Item> items;
  for (std::size_t i = 0; i < log.wheels.size(); ++i)
    items.push_back({log.wheels[i].log_time, wheels, i});
  for (std::size_t i = 0; i < log.ceiling_images.size(); ++i)
    items.push_back({log.ceiling_images[i].log_time, ceiling, i});
  for (std::size_t i = 0; i < log.omni_images.size(); ++i)
    items.push_back({log.omni_images[i].log_time, omni, i});
  std::stable_sort(items.begin(), items.end(),
                   [](const Item& a, const Item& b) { return a.arrival < b.arrival; });
  Outcome run;
  for (const auto& e : log.events)
    if (e.value.type() == io::EventKind::kidnap)
      run.kidnaps.push_back({e.value.stamp, false, {}, {}});
  // Scored only while the estimate should be right: tracking, and not between a kidnap and the
  // relocalization that follows it.
  bool unsure = false;
  std::size_t next_kidnap = 0, events_seen = start_known ? 1 : 0;  // after "initialized"
  if (start_known)
    loc.initialize(log.wheels.front().value.stamp, truth.at(log.wheels.front().value.stamp),
                   Vector3d(1e-4, 1e-4, 3e-4).asDiagonal());
  else
    unsure = true;
  for (const Item& it : items) {
    const Stamp now = it.arrival;
    while (next_kidnap < run.kidnaps.size() && run.kidnaps[next_kidnap].at <= now) {
      unsure = true;
      ++next_kidnap;
    }
    if (it.kind == wheels) {
      const auto& w = log.wheels[it.index].value;
      loc.wheels(w.stamp, w.left, w.right);
      ++run.wheel_steps;
      const LocalizerEstimate e = loc.estimate();
      if (!unsure && e.mode == LocalizerMode::tracking) {
        const Pose2 t = truth.at(e.stamp);
        const double ep = (e.pose.translation() - t.translation()).norm();
        const double ey = std::fabs(wrap_angle(e.pose.yaw() - t.yaw()));
        ++run.scored;
        run.sum2_pos += ep * ep;
        run.sum2_yaw += ey * ey;
        run.max_pos = std::max(run.max_pos, ep);
        run.max_yaw = std::max(run.max_yaw, ey);
      }
      if (run.wheel_steps % 10 == 0)
        run.p_norm.emplace_back(to_seconds(e.stamp), covariance_norm(e.covariance));
    } else if (it.kind == ceiling) {
      const auto& f = log.ceiling_images[it.index].value;
      const Image8 img = io::decode_image(f.data, "frame");
      const CeilingObservation& ob = loc.ceiling_frame(f.stamp, vision::ImageView::of(img));
      ++run.ceiling_frames;
      int full = 0;
      for (const auto& l : ob.lamps) full += l.detection.view != vision::LampView::partial;
      if (full == 0) ++run.dark_frames;
      for (auto& k : run.kidnaps)
        if (!k.shown && f.stamp >= k.at && !ob.lamps.empty()) k.shown = f.stamp;
    } else {
      const auto& f = log.omni_images[it.index].value;
      const Image8 img = io::decode_image(f.data, "omni frame");
      const vision::OmniDetection& d = loc.omni_frame(f.stamp, vision::ImageView::of(img));
      for (auto& k : run.kidnaps)
        if (!k.shown && f.stamp >= k.at && !d.blobs.empty()) k.shown = f.stamp;
    }
    // New mode changes: a loss is the detection of the latest kidnap, or a false alarm.
    for (; events_seen < loc.events().size(); ++events_seen) {
      const LocalizerEvent& ev = loc.events()[events_seen];
      // The cause agrees with the mode: fixes relocalize, evidence loses, a start initializes.
      if (ev.mode == LocalizerMode::relocalized) {
        EXPECT_EQ(ev.cause, ModeCause::global_fix);
      }
      if (ev.mode == LocalizerMode::lost) {
        EXPECT_NE(ev.cause, ModeCause::global_fix);
        EXPECT_NE(ev.cause, ModeCause::confirmed);
        EXPECT_NE(ev.cause, ModeCause::initialized);
      }
      if (ev.mode == LocalizerMode::relocalized) {
        // The omni relocalizer's fix, scored against the truth when it is made.
        const LocalizerEstimate e = loc.estimate();
        const Pose2 t = truth.at(e.stamp);
        const double ep = (e.pose.translation() - t.translation()).norm();
        run.max_fix_error = std::max(run.max_fix_error, ep);
        ++run.relocalizations;
        if (ep < 0.5) {
          unsure = false;
          for (auto& k : run.kidnaps)
            if (k.at <= e.stamp) k.recovered = true;
        } else {
          ++run.bad_fixes;
        }
        std::cout << "relocalized at " << to_seconds(now) << " s, " << ep * 100
                  << " cm from the truth: " << ev.reason << "\n";
      }
      if (ev.mode != LocalizerMode::lost) continue;
      Kidnapped* k = nullptr;
      for (auto& c : run.kidnaps)
        if (c.at <= now && !c.lost) k = &c;
      if (k) {
        k->lost = now;
        if (!k->shown) k->shown = now;  // lost before any lamp showed (dark place)
      } else if (unsure) {
        ++run.bad_fixes_caught;  // a wrong fix found out
        std::cout << "lost again at " << to_seconds(now) << " s: " << ev.reason << "\n";
      } else {
        ++run.false_alarms;
        std::cout << "false alarm at " << to_seconds(now) << " s: " << ev.reason << "\n";
      }
    }
  }
  run.recovered_at_end = !unsure;
  std::cout << "odometry calibration: " << loc.calibration().pairs() << " pairs, drift "
            << loc.calibration().yaw_drift_per_m() * 180 / M_PI << " deg/m, turn scale "
            << loc.calibration().turn_scale() << ", travel scale "
            << loc.calibration().travel_scale() << "\n";
  return run;
}

sim::Scenario corridor(const World& w, std::uint64_t seed) {
  sim::Scenario s = sim::make_named_scenario("corridor", w.map, w.geojson, w.robot, seed);
  s.ceiling_delay_s = 1.0;
  return s;
}

TEST(Localizer, CorridorWithTheCameraOneSecondLate) {
  const World w("maps/office_floor.geojson");
  const sim::Scenario s = corridor(w, 21);
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  std::cout << r.summary() << "\n";
  EXPECT_LE(r.rms_pos(), 0.03);
  EXPECT_LE(r.rms_yaw_deg(), 0.5);
  EXPECT_LE(r.max_pos, 0.15);  // never diverging
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_GT(r.scored, r.wheel_steps * 95 / 100);
}

// Wheels that read every metre 3 % long (left) and 2.5 % long (right), as soft tyres or a wheel
// radius mistaken in robot.json do. The estimate the robot drives on is a second of wheels past
// the last frame, and the EKF keeps it behind or ahead of the truth by a share of that: 3.7 cm
// RMS along the way on four office routes (2.75 % long on average), 0.7 cm with wheels right. The
// calibration learns the travel's scale from the measured positions and takes that away.
TEST(Localizer, WheelsThatReadLongAreCalibratedByTheLamps) {
  const World w("maps/office_floor.geojson");
  sim::Scenario s = corridor(w, 23);
  s.odometry.left_scale = 0.03;
  s.odometry.right_scale = 0.025;
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  LocalizerOptions as_read;
  as_read.calibration.learn_travel = false;
  const Outcome kept = replay(s, log, w.map, true, as_read);
  std::cout << "learnt: " << r.summary() << "\nas the wheels read: " << kept.summary() << "\n";
  EXPECT_LE(r.rms_pos(), 0.02);     // 1.4 cm, the metres before the fit holds 20 pairs with it
  EXPECT_GE(kept.rms_pos(), 0.03);  // 3.9 cm: what the calibration takes away
  EXPECT_LE(r.max_pos, 0.06);
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_GT(r.scored, r.wheel_steps * 95 / 100);
}

// A rough floor or a loose mount: the cameras swung by 1.5 degrees from frame to frame, three
// times what the localizer's models assume. Weighed as if steady, the lamps' measurements do not
// fit and the localizer loses itself again and again; the ceiling frames measure the swing
// (CeilingContinuity) and the models take it.
TEST(Localizer, ARoughFloorIsWeighedForWhatItIs) {
  const World w("maps/office_floor.geojson");
  sim::Scenario s = corridor(w, 24);
  s.bump_sigma_rad = 1.5 * M_PI / 180;
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  LocalizerOptions steady;
  steady.continuity.learn_tilt = false;
  const Outcome as_configured = replay(s, log, w.map, true, steady);
  std::cout << "swing learnt: " << r.summary() << "\nas configured: " << as_configured.summary()
            << "\n";
  // Two false alarms, at 1.3 and 6.2 s: the first 50 lamps seen twice (5.3 s of frames, which
  // arrive a second late) measure the swing; none after. Lost for 6 s of the 77 with the margins
  // to publish as configured; with them raised to the swing (publish_follows_swing) the set
  // waits longer after each alarm.
  EXPECT_LE(r.false_alarms, 2);
  EXPECT_EQ(r.bad_fixes, 0);
  EXPECT_LE(r.rms_pos(), 0.02);                   // 1.4 cm
  EXPECT_GT(r.scored, r.wheel_steps * 80 / 100);  // 84.5 % (90 % with the configured margins)
  EXPECT_GE(as_configured.false_alarms, 10);      // 25, and 16 % of the drive tracked
  EXPECT_LT(as_configured.scored, r.scored / 2);
}

// Two lamps of every three failed along C1 and C2: more than half the frames are dark, in runs
// of about 3 m. Over a dark run the wheels alone (0.002 m per sqrt(m) per wheel of random error)
// would lose 0.7 degrees of heading; the omni frames, matched near the estimate, hold it.
TEST(Localizer, CorridorWithHalfTheFramesDark) {
  const World w("maps/office_floor.geojson");
  sim::Scenario s = corridor(w, 22);
  s.failed_lamps = {"C1-L2", "C1-L3", "C1-L5", "C1-L6", "C1-L8", "C2-L1",
                    "C2-L2", "C2-L4", "C2-L5", "C2-L7", "C2-L8"};
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  std::cout << r.summary() << "\n";
  EXPECT_GE(r.dark_frames * 2, r.ceiling_frames);
  EXPECT_LE(r.rms_pos(), 0.03);
  EXPECT_LE(r.rms_yaw_deg(), 0.5);
  EXPECT_LE(r.max_pos, 0.15);
  EXPECT_EQ(r.false_alarms, 0);
}

// Round lamps far apart: the office's corridor lamps made 0.5 m discs and every other one taken
// down, 4.5 m apart, driven from E2 to E1. The ceiling camera sees one disc at a time, which
// places the robot but not its heading. Until 2026-12-03 a lone round lamp gave no measurement:
// between omni frames the wheels alone carried the pose, their difference (the simulated 0.7 %)
// turned the heading 1.2 degrees a metre, and an omni frame 8 degrees off matched far lamps of
// the regular ceiling to their neighbours and was applied: a wrong fix, 72 cm off while certain
// (`lampnav replay`; here, without the lone disc's measurement, `refused` below).
TEST(Localizer, RoundLampsFarApartPlaceTheRobotBetweenOmniFrames) {
  World w("maps/office_floor.geojson");
  w.map = test::edited(w.map, test::sparse_round);
  const sim::Scenario s = sim::make_route_scenario(w.map, w.geojson, w.robot, "E2", "E1", 6);
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  std::cout << r.summary() << "\n";
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_EQ(r.relocalizations, 0);
  EXPECT_LE(r.rms_pos(), 0.03);
  EXPECT_LE(r.max_pos, 0.2);
  EXPECT_GT(r.scored, r.wheel_steps * 95 / 100);
  // Without the lone disc's measurement, and without the omni updates where the omni check
  // cannot judge (since 2026-12-03 they hold this drive too: 1.8 cm at worst with them alone).
  LocalizerOptions refused;
  refused.ceiling.measurement.round_lamp_position = false;
  refused.omni_update_unchecked = false;
  const Outcome before = replay(s, log, w.map, true, refused);
  std::cout << "without the lone disc's measurement: " << before.summary() << "\n";
  EXPECT_GT(before.max_pos, 0.5);
}

// The same floor, E1 to K2 with two discs out (C1-L3, C4-L5), carried at 40 s, start not given.
// From 66 s the wheels alone held the heading over the 9 m where C4-L5 is out, and it drifted 8
// degrees: the omni check, with fewer than three lamps within its 75 degrees, could not judge the
// frames, and no omni update was made. 54 cm off at 79 s, published as tracking. The refinement
// matches lamps out to 88 degrees; applied where the check cannot judge, it holds the heading.
TEST(Localizer, OmniUpdatesHoldTheHeadingWhereDiscsAreOut) {
  World w("maps/office_floor.geojson");
  w.map = test::edited(w.map, test::sparse_round);
  sim::Scenario s = sim::make_route_scenario(w.map, w.geojson, w.robot, "E1", "K2", 21);
  s.failed_lamps = {"C1-L3", "C4-L5"};
  s.kidnaps.push_back({40.0, std::nullopt});
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map, false);
  std::cout << r.summary() << "\n";
  EXPECT_EQ(r.bad_fixes, 0);
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_LE(r.max_pos, 0.1);
  LocalizerOptions checked_only;
  checked_only.omni_update_unchecked = false;
  const Outcome before = replay(s, log, w.map, false, checked_only);
  std::cout << "omni updates only where the check judged: " << before.summary() << "\n";
  EXPECT_GT(before.max_pos, 0.3);
}

// Carried away while lost: the same floor from E2 to E1, lifted at 30 s (the loss found) and
// again at 60 s, while the localizer still looks for the robot among the places its drive allows.
// The wheels do not see a lift, so those places are stale. Until 2026-12-03 the images were
// enumerated within them only: the image at 73 s scored 102 at the best of them and 2.4 at the
// truth, and the set published a place 8 m off (caught a second later). Now such an image starts
// the places again; and since 2026-12-04 an image whose lamps misfit every hypothesis past
// odd_image_misfit contradicts them all, which starts the set again too (`stale`, below, is the
// old behaviour: both off, and the check of 2026-12-05 that also keeps that place from being
// published, its ceiling frames showing lamps where it has none, off too; with that check on, the
// stale set publishes nothing wrong either). Far blobs are uncapped in `stale` as they were then:
// capped (LampPairOptions::far_blob_cost_max), the stale set chose no twin on this drive, but
// published a place 50.3 cm off at 77.5 s, the robot turning near (20.5, 10.0), and 5.5 cm off
// at 80.5 s.
TEST(Localizer, CarriedAwayWhileLostStartsThePlacesAgain) {
  World w("maps/office_floor.geojson");
  w.map = test::edited(w.map, test::sparse_round);
  sim::Scenario s = sim::make_route_scenario(w.map, w.geojson, w.robot, "E2", "E1", 4);
  s.kidnaps.push_back({30.0, std::nullopt});
  s.kidnaps.push_back({60.0, std::nullopt});
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  std::cout << r.summary() << "\n";
  ASSERT_EQ(r.kidnaps.size(), 2u);
  EXPECT_TRUE(r.kidnaps[0].lost);
  EXPECT_EQ(r.bad_fixes, 0);
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_TRUE(r.recovered_at_end);
  LocalizerOptions stale;
  stale.hypotheses.stale_places_cost = 1e9;
  stale.hypotheses.odd_image_misfit = 1e9;
  stale.global.pairs.far_blob_cost_max = std::numeric_limits<double>::infinity();
  LocalizerOptions stale_checked = stale;
  stale.hypotheses.publish_unexplained_frames = 0;
  const Outcome before = replay(s, log, w.map, true, stale);
  std::cout << "kept to the drive's places: " << before.summary() << "\n";
  EXPECT_GE(before.bad_fixes, 1);
  const Outcome checked = replay(s, log, w.map, true, stale_checked);
  std::cout << "kept to them, lamps where the map has none checked: " << checked.summary() << "\n";
  EXPECT_EQ(checked.bad_fixes, 0);
}

// The office's own lamps, three of them out, the start not given: carried at 30 s while the set
// still held 62 places from the drive. Put down at (32.55, -8.00), the images fit the truth and
// its twin under the half turn about (31, 1) alike, and the drive's places allowed the twin only:
// kept to them, the set published it, 18.6 to 26.7 m off until the log ends. The ceiling camera
// saw the move (its lamp gone from where the wheels put it, another where they put none, in two
// frames that agree), and the places went: the robot is "one of these" instead.
TEST(Localizer, CarriedWhileLookingIsSeenByTheCeilingCamera) {
  World w("maps/office_floor.geojson");
  sim::Scenario s = sim::make_route_scenario(w.map, w.geojson, w.robot, "E1", "K2", 25);
  s.failed_lamps = {"C1-L2", "C4-L6", "C2-L3"};
  s.kidnaps.push_back({30.0, std::nullopt});
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map, false);
  std::cout << r.summary() << "\n";
  EXPECT_EQ(r.bad_fixes, 0);
  LocalizerOptions unwatched;
  unwatched.continuity.enabled = false;
  const Outcome before = replay(s, log, w.map, false, unwatched);
  std::cout << "ceiling frames not held against one another: " << before.summary() << "\n";
  EXPECT_GE(before.bad_fixes, 1);
}

TEST(Localizer, OfficeMissionKidnapDetectedAndRelocalized) {
  const World w("maps/office_floor.geojson");
  const sim::Scenario s = sim::make_named_scenario("office-mission", w.map, w.geojson, w.robot, 1);
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  std::cout << r.summary() << "\n";
  ASSERT_EQ(r.kidnaps.size(), 1u);
  ASSERT_TRUE(r.kidnaps[0].lost);
  EXPECT_LE(r.kidnaps[0].latency(), 2.0);
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_EQ(r.relocalizations, 1);
  EXPECT_EQ(r.bad_fixes, 0);
  EXPECT_LE(r.max_fix_error, 0.1);
  EXPECT_LE(r.rms_pos(), 0.05);
}

// The same mission put down 2 m further along C2, where the view aliases the one the estimate
// expects: same corridor lamps at the same place in the image, heading along the corridor. No
// sensor can tell until the corridors differ; the loss is found late, but found. Relocalizing
// from the omni camera here (lamps 1.8 m above it, evenly spaced) may land a lamp spacing off;
// the ceiling camera contradicts such a fix within a second and the next omni frame tries again.
TEST(Localizer, AliasedKidnapIsFoundWhenTheCorridorsDiffer) {
  const World w("maps/office_floor.geojson");
  sim::Scenario s = sim::make_named_scenario("office-mission", w.map, w.geojson, w.robot, 1);
  const graph::Node& c2 = *w.map.find_node("C2");
  s.kidnaps[0].to = Pose2(c2.axis->point_at(0.6 * c2.axis->length()), M_PI);
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  std::cout << r.summary() << "\n";
  ASSERT_EQ(r.kidnaps.size(), 1u);
  ASSERT_TRUE(r.kidnaps[0].lost);
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_GE(r.relocalizations, 1);
  EXPECT_EQ(r.bad_fixes, r.bad_fixes_caught);
  EXPECT_TRUE(r.recovered_at_end);
}

// Put down at the east end of the office (41, -0.5), whose half-turn twin (21, 2.5) the omni views
// there favour by 9 to 15 an image, the robot turns on the spot. Each image of the turn once added
// its cost to the true place again, and the fourth dropped it: the twin was then the only place,
// and published as certain (a wrong fix, 27 m off). Images from one spot now count once. A
// robot with a VGA ceiling camera, whose frames drew the omni noise that showed it.
TEST(Localizer, KidnapOntoASpotWhoseTwinTheViewFavoursTurningThere) {
  World w("maps/office_floor.geojson");
  for (CameraDescription& c : w.robot.cameras) {
    if (c.name != "ceiling_camera") continue;
    c.width = 640;
    c.height = 480;
    c.pinhole = {420.0, 421.0, 322.0, 236.0, {-0.2, 0.05, 0.001, -0.001, 0.0}};
  }
  sim::Scenario s = sim::make_route_scenario(w.map, w.geojson, w.robot, "E1", "K2", 4);
  s.kidnaps.push_back({30.0, std::nullopt});
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  std::cout << r.summary() << "\n";
  ASSERT_EQ(r.kidnaps.size(), 1u);
  ASSERT_TRUE(r.kidnaps[0].lost);
  EXPECT_EQ(r.bad_fixes, 0);
  EXPECT_TRUE(r.recovered_at_end);
}

// A Kannala-Brandt omni camera (OpenCV's fisheye model, as `robot import` writes it), 800 x 800:
// the robot finds where it starts, then the kidnap, from its images. Before the simulator drew
// its lamps by this model's own radius, they were dots no detector takes for lamps, and such a
// robot never localized.
TEST(Localizer, KannalaBrandtOmniCameraFindsTheStartAndTheKidnap) {
  World w("maps/office_floor.geojson");
  w.robot = test::with_kannala_brandt_omni(w.robot);
  sim::Scenario s = sim::make_route_scenario(w.map, w.geojson, w.robot, "E1", "K2", 4);
  s.kidnaps.push_back({30.0, std::nullopt});
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map, false);
  std::cout << r.summary() << "\n";
  ASSERT_EQ(r.kidnaps.size(), 1u);
  EXPECT_TRUE(r.kidnaps[0].lost);
  EXPECT_GE(r.relocalizations, 2);  // the start, and after the kidnap
  EXPECT_EQ(r.bad_fixes, 0);
  EXPECT_TRUE(r.recovered_at_end);
  EXPECT_LE(r.rms_pos(), 0.05);
}

// Paper 1's runs, omnidirectional camera only: the kidnap-free run raises no alarm and the omni
// frames keep the estimate; in the carried run every jump is a kidnap, found by the omni check,
// and the same image relocalizes the robot.
TEST(Localizer, DomusGlobalRunRaisesNoAlarm) {
  const World w("maps/domus_museum.geojson");
  const sim::Scenario s = sim::make_named_scenario("domus-global", w.map, w.geojson, w.robot, 1);
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  std::cout << r.summary() << "\n";
  // The omni frames, matched near the estimate, correct the odometry once a second.
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_LE(r.rms_pos(), 0.05);
  EXPECT_LE(r.rms_yaw_deg(), 1.0);
}

// Not told where it starts, the robot finds itself from its first omni frame, and the odometry
// read since that frame's capture carries the fix to the present.
TEST(Localizer, StartsFromTheOmniCameraWhenNotToldWhereItIs) {
  const World w("maps/domus_museum.geojson");
  const sim::Scenario s = sim::make_named_scenario("domus-global", w.map, w.geojson, w.robot, 2);
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map, false);
  std::cout << r.summary() << "\n";
  EXPECT_EQ(r.relocalizations, 1);
  EXPECT_LE(r.max_fix_error, 0.15);
  EXPECT_TRUE(r.recovered_at_end);
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_LE(r.rms_pos(), 0.05);
}

TEST(Localizer, DomusKidnapEveryJumpDetected) {
  const World w("maps/domus_museum.geojson");
  const sim::Scenario s = sim::make_named_scenario("domus-kidnap", w.map, w.geojson, w.robot, 1);
  const io::MissionLog log = record(s);
  const Outcome r = replay(s, log, w.map);
  std::cout << r.summary() << "\n";
  EXPECT_GE(r.kidnaps.size(), 10u);
  int detected = 0, recovered = 0;
  double worst = 0;
  for (const auto& k : r.kidnaps) {
    recovered += k.recovered;
    if (!k.lost || !k.shown) continue;
    ++detected;
    worst = std::max(worst, k.latency());
  }
  std::cout << detected << " of " << r.kidnaps.size() << " jumps detected, worst latency " << worst
            << " s; " << recovered << " recovered, worst fix " << r.max_fix_error * 100 << " cm\n";
  // The image that shows a jump relocalizes the robot: every jump is recovered, with a fix
  // within the global localizer's accuracy.
  EXPECT_GE(detected, static_cast<int>(r.kidnaps.size()) - 1);
  EXPECT_EQ(recovered, static_cast<int>(r.kidnaps.size()));
  EXPECT_EQ(r.bad_fixes, 0);
  EXPECT_LE(r.max_fix_error, 0.3);
  EXPECT_LE(worst, 2.0);
  EXPECT_EQ(r.false_alarms, 0);
}

// Audits (LocalizerOptions::audit_period): one omni frame in 5 s (here; 2 s by default) while the
// estimate is certain, the first of a certain stretch only starting the schedule. The search waits
// for audit(), so that the frame's pose goes out first, or for the next input.
TEST(Localizer, AuditsRunOnScheduleOnceThePoseIsOut) {
  const World w("maps/office_floor.geojson");
  // Omni frames at 1, 2, ..., 12 s with nothing in them, audit() called after each but the 11th;
  // what audit() said and how many audits ran by then.
  const auto drive = [&](LocalizerOptions o) {
    o.omni_check_period = std::chrono::milliseconds(500);  // every frame checked
    Localizer loc(w.map, w.robot, o);
    loc.initialize(stamp_from_seconds(0), Pose2(1, 10, 0), Vector3d(1e-4, 1e-4, 1e-4).asDiagonal());
    std::vector<bool> ran;
    std::vector<std::uint64_t> audits;
    for (int k = 0; k <= 1200; ++k) {
      const double t = 0.01 * k;
      loc.wheels(stamp_from_seconds(t), 0.005 * k, 0.005 * k);
      if (k == 0 || k % 100 != 0) continue;
      loc.omni_detection(stamp_from_seconds(t - 0.005), vision::OmniDetection{});
      if (k == 1100) continue;  // left to the next wheel reading
      ran.push_back(loc.audit());
      audits.push_back(loc.counts().audits);
    }
    EXPECT_EQ(loc.counts().audit_losses, 0u);  // an empty frame puts the robot nowhere else
    EXPECT_EQ(loc.mode(), LocalizerMode::tracking);
    return std::pair{ran, audits};
  };
  // The frame at 1 s starts the schedule; those at 6 s and 11 s are audited, the second by the
  // wheel reading after it.
  LocalizerOptions every5;
  every5.audit_period = std::chrono::seconds(5);
  const auto [ran, audits] = drive(every5);
  EXPECT_EQ(ran, (std::vector<bool>{0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0}));
  EXPECT_EQ(audits, (std::vector<std::uint64_t>{0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 2}));
  // By default every 2 s: 3, 5, 7, 9 and 11 s (the last by the wheel reading after it).
  const auto [ran2, audits2] = drive({});
  EXPECT_EQ(ran2, (std::vector<bool>{0, 0, 1, 0, 1, 0, 1, 0, 1, 0, 0}));
  EXPECT_EQ(audits2, (std::vector<std::uint64_t>{0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5}));
  LocalizerOptions off;
  off.audit_period = Duration::zero();
  EXPECT_EQ(drive(off).second, std::vector<std::uint64_t>(11, 0));
  // Bad options are refused, naming the field.
  const auto refused = [&](const auto& set, const char* field) {
    LocalizerOptions bad_options;
    set(bad_options);
    try {
      const Localizer bad(w.map, w.robot, bad_options);
      ADD_FAILURE() << "a bad " << field << " was taken";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), testing::HasSubstr(field));
    }
  };
  refused([](LocalizerOptions& o) { o.audit_period = -std::chrono::seconds(1); }, "audit_period");
  refused([](LocalizerOptions& o) { o.audit_ratio = 0.5; }, "audit_ratio");
  refused([](LocalizerOptions& o) { o.audit_step_ratio = 2 * o.audit_ratio; }, "audit_step_ratio");
  refused([](LocalizerOptions& o) { o.audit_challenge_frames = 0; }, "audit_challenge_frames");
  refused([](LocalizerOptions& o) { o.audit_look_alikes = -1; }, "audit_look_alikes");
  refused([](LocalizerOptions& o) { o.audit_look_alike_fraction = 0; },
          "audit_look_alike_fraction");
  refused([](LocalizerOptions& o) { o.audit_look_alike_fraction = 1.5; },
          "audit_look_alike_fraction");
  refused([](LocalizerOptions& o) { o.hypotheses.partial_view_travel_m = -1; },
          "partial_view_travel_m");
}

}  // namespace
}  // namespace lampnav::fusion

namespace lampnav::fusion {
namespace {

TEST(Localizer, RefusesBadInputAndStaysHealthy) {
  const World w("maps/office_floor.geojson");
  Localizer loc(w.map, w.robot);
  const Matrix3d P0 = Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
  loc.initialize(stamp_from_seconds(0), Pose2(1, 10, 0), P0);
  ASSERT_FALSE(loc.wheels(stamp_from_seconds(0), 0, 0));
  ASSERT_FALSE(loc.wheels(stamp_from_seconds(0.02), 0.01, 0.01));
  const LocalizerEstimate before = loc.estimate();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(loc.wheels(stamp_from_seconds(0.04), nan, 0.02), Refusal::non_finite);
  EXPECT_EQ(loc.wheels(stamp_from_seconds(0.01), 0.02, 0.02), Refusal::time_backwards);
  // An encoder that jumps by 50 m: refused, and the next readings count from the new value.
  EXPECT_EQ(loc.wheels(stamp_from_seconds(0.04), 50.02, 0.02), Refusal::wheel_jump);
  EXPECT_EQ(loc.counts().wheel_rebaselined, 1u);
  EXPECT_EQ(loc.estimate().pose.x(), before.pose.x());
  EXPECT_FALSE(loc.wheels(stamp_from_seconds(0.06), 50.03, 0.03));
  EXPECT_NEAR(loc.estimate().pose.x(), before.pose.x() + 0.01, 1e-3);
  // A frame that is not an image of the camera: InputError, nothing else changes.
  Image8 small;
  small.width = 10;
  small.height = 10;
  small.pixels.assign(100, 0);
  EXPECT_THROW(loc.ceiling_frame(stamp_from_seconds(0.05), vision::ImageView::of(small)),
               InputError);
  EXPECT_THROW(loc.omni_frame(stamp_from_seconds(0.05), vision::ImageView::of(small)), InputError);
  EXPECT_EQ(loc.mode(), LocalizerMode::tracking);
  // Fixes that are not finite, or older than the history, are refused and counted.
  EXPECT_FALSE(loc.global_fix({stamp_from_seconds(0.05), Pose2(nan, 0, 0), P0, "test"}));
  EXPECT_FALSE(loc.global_fix({stamp_from_seconds(-10), Pose2(1, 10, 0), P0, "test"}));
  EXPECT_EQ(loc.counts().fixes_refused, 2u);
  EXPECT_TRUE(is_covariance(loc.estimate().covariance));
  // A good fix re-initializes at its capture time and re-applies the odometry since.
  EXPECT_TRUE(loc.global_fix({stamp_from_seconds(0.04), Pose2(5, 10, 0), P0, "test"}));
  EXPECT_EQ(loc.mode(), LocalizerMode::relocalized);
  EXPECT_NEAR(loc.estimate().pose.x(), 5.005, 1e-6);  // half of the 0.02 s -> 0.06 s step
  ASSERT_NE(loc.estimate().node, nullptr);
  // Robots without an omni camera simply have no omni input.
  RobotDescription ceiling_only = w.robot;
  ceiling_only.cameras.erase(ceiling_only.cameras.begin() + 1);
  const Localizer c(w.map, ceiling_only);
  EXPECT_TRUE(c.has_ceiling_camera());
  EXPECT_FALSE(c.has_omni_camera());
}

}  // namespace
}  // namespace lampnav::fusion
