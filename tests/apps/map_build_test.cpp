// `lampnav map build` end to end: a drive recorded by `lampnav sim` (rendered frames, the real
// detector) becomes a valid map whose lamps are where the true ones are, without the log's map.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "edited_map.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/mapping/rigid_fit.hpp"
#include "lampnav_test.hpp"
#include "map_build_support.hpp"

namespace lampnav {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;
using test::lamp_errors;
using test::LampErrors;
using test::Recorded;

// The true lamps of the places the drive E1 -> K2 passes under: C1, C5 and C4 and the places
// between them (E1, J1, J2, K2).
std::size_t lamps_under_the_drive(const graph::TopologicalMap& truth) {
  std::size_t under = 0;
  for (const char* name : {"E1", "C1", "J1", "C5", "J2", "C4", "K2"})
    under += truth.find_node(name)->lamps.size();
  return under;
}

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
  const graph::TopologicalMap truth =
      graph::read_map(test::source_path("maps/office_floor.geojson")).map;
  const io::MissionLog log = io::read_mission_log(rec.log);
  ASSERT_FALSE(log.truth.empty());
  const LampErrors e = lamp_errors(graph::read_map(out).map, truth, log.truth.front().value.pose);
  EXPECT_EQ(e.matched.size(), lamps_under_the_drive(truth));
  std::cout << e.matched.size() << " lamps, error rms " << e.rms * 100 << " cm, max "
            << e.worst * 100 << " cm\n";
  // The targets, met on one pass with no loop to close.
  EXPECT_LE(e.rms, 0.02);
  EXPECT_LE(e.worst, 0.05);

  // The same drive surveyed against the true map: the office is symmetric under a half turn
  // along this drive, so without the start the survey says so; with it, every lamp is there.
  const std::string office = test::quoted_source("maps/office_floor.geojson");
  const auto twins = test::run_lampnav("map survey " + office + " '" + rec.log + "' --quiet");
  EXPECT_EQ(twins.status, 1) << twins.out;
  EXPECT_THAT(twins.err, HasSubstr("several places"));
  const auto same = test::run_lampnav("map survey " + office + " '" + rec.log +
                                      "' --quiet --initial-pose 1,10,0");
  ASSERT_EQ(same.status, 0) << same.err;
  EXPECT_THAT(same.out, HasSubstr("0 failed, 0 moved, 0 new"));
  // Against a map that lacks a lamp and has one too many: one new, one failed, named by place.
  nlohmann::json doc =
      nlohmann::json::parse(test::slurp(test::source_path("maps/office_floor.geojson")));
  for (auto& f : doc["features"]) {
    if (!f["properties"].contains("lampnav")) continue;
    auto& lamps = f["properties"]["lampnav"]["lamps"];
    for (std::size_t i = 0; i < lamps.size(); ++i) {
      if (lamps[i]["id"] == "C1-L3") lamps.erase(i--);
    }
    if (f["properties"]["metadata"]["name"] == "C4") {
      auto extra = lamps[1];
      extra["id"] = "C4-GHOST";
      extra["xyz"][0] = 0.5 * (lamps[1]["xyz"][0].get<double>() + lamps[2]["xyz"][0].get<double>());
      lamps.insert(lamps.begin() + 2, extra);
    }
  }
  const std::string edited = (rec.dir / "edited.geojson").string();
  std::ofstream(edited) << doc.dump();
  const auto js = test::run_lampnav("map survey '" + edited + "' '" + rec.log +
                                    "' --quiet --json --initial-pose 1,10,0 --update '" +
                                    (rec.dir / "fixed.geojson").string() + "'");
  ASSERT_EQ(js.status, 0) << js.err;
  const auto report = nlohmann::json::parse(js.out);
  EXPECT_EQ(report["failed"], 1);
  EXPECT_EQ(report["new"], 1);
  EXPECT_EQ(report["moved"], 0);
  for (const auto& l : report["lamps"]) {
    if (l["status"] == "failed") {
      EXPECT_EQ(l["id"], "C4-GHOST");
    }
    if (l["status"] == "new") {
      EXPECT_EQ(l["place"], "C1");
      EXPECT_THAT(l["where"].get<std::string>(), HasSubstr("C1, "));
    }
  }
  EXPECT_EQ(test::run_lampnav("map check '" + (rec.dir / "fixed.geojson").string() + "'").status,
            0);
}

// Wheels that read 1 % long make a map 1 % too large, and no camera looking up can tell (a
// smaller building with a lower ceiling looks the same): the far end of E1 -> K2 is 20 cm off.
// One distance measured between two lamps gives the map its scale back; distances that cannot
// be right are refused, and no map is written.
TEST(MapBuild, AMeasuredDistanceGivesTheMapItsScale) {
  const Recorded rec(test::source_path("maps/office_floor.geojson"), "--wheel-scale 0.01,0.01");
  const graph::TopologicalMap truth =
      graph::read_map(test::source_path("maps/office_floor.geojson")).map;
  const Pose2 start = io::read_mission_log(rec.log).truth.front().value.pose;
  const std::string out = (rec.dir / "built.geojson").string();
  // The built lamps against the true ones (the nearest within a metre, placed by the start).
  auto errors = [&](const std::string& path) {
    return lamp_errors(graph::read_map(path).map, truth, start, 1.0);
  };
  const std::string build = "map build '" + rec.log + "' -o '" + out + "' --quiet";
  const auto plain = test::run_lampnav(build);
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_THAT(plain.err, HasSubstr("scale is the wheels' calibration"));
  const LampErrors before = errors(out);
  std::cout << "wheels 1 % long: error rms " << before.rms * 100 << " cm, max "
            << before.worst * 100 << " cm\n";
  EXPECT_GT(before.worst, 0.1);
  ASSERT_EQ(before.built.count("E1-L1"), 1u);
  ASSERT_EQ(before.built.count("K2-L1"), 1u);
  const std::string first = before.built.at("E1-L1"), last = before.built.at("K2-L1");
  // Measured with a laser meter, 3 mm long.
  const double true_m =
      (truth.find_lamp(LampId("E1-L1"))->xyz - truth.find_lamp(LampId("K2-L1"))->xyz).norm();
  char metres[32];
  std::snprintf(metres, sizeof metres, "%.3f", true_m + 0.003);
  const std::string pair = first + "," + last + ",";
  fs::remove(out);
  const auto r = test::run_lampnav(build + " --distance " + pair + metres);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("scaled by 1 measured distance"));
  EXPECT_THAT(r.err, HasSubstr("larger than the building"));
  const LampErrors after = errors(out);
  std::cout << "with the distance: error rms " << after.rms * 100 << " cm, max "
            << after.worst * 100 << " cm\n";
  EXPECT_LE(after.rms, 0.02);
  EXPECT_LE(after.worst, 0.05);
  EXPECT_EQ(test::run_lampnav("map check '" + out + "'").status, 0);

  // Refused, naming the flag, and no map written.
  fs::remove(out);
  const std::pair<std::string, std::string> refused[] = {
      {first + ",NOPE,10", "no lamp \"NOPE\""},
      {pair + "48", "are these the lamps measured"},
      {pair + "4x", "not a number of metres"},
      {first + ",10", "expected FROM,TO,METRES"},
      {pair + metres + " --distance " + first + "," + first + ",5", "names one lamp twice"},
  };
  for (const auto& [flag, says] : refused) {
    const auto bad = test::run_lampnav(build + " --distance " + flag);
    EXPECT_EQ(bad.status, 2) << flag;
    EXPECT_THAT(bad.err, HasSubstr("--distance")) << flag;
    EXPECT_THAT(bad.err, HasSubstr(says)) << flag;
    EXPECT_FALSE(fs::exists(out)) << flag;
  }
  // Two distances between the same lamps 0.7 % apart (30 cm): each within what the wheels allow,
  // but not both right.
  std::snprintf(metres, sizeof metres, "%.3f", 0.993 * true_m);
  const auto two = test::run_lampnav(build + " --distance " + pair + std::to_string(true_m) +
                                     " --distance " + last + "," + first + "," + metres);
  EXPECT_EQ(two.status, 2);
  EXPECT_THAT(two.err, HasSubstr("disagrees with the other measured distances"));
  EXPECT_FALSE(fs::exists(out));
}

// Where the built map's frame starts: the drive's first true pose, or, when the drive after a
// carry mapped more lamps than the drive before it and the two could not be joined (map build's
// note says so), the true pose at the ceiling frame the robot was put down at.
Pose2 map_origin(const io::MissionLog& log, const std::string& notes) {
  const std::string restart = "the map is built from the drive after it";
  const std::size_t at = notes.rfind(restart);
  if (at == std::string::npos) return log.truth.front().value.pose;
  const std::string jumped = "jumped ";
  const std::size_t j = notes.rfind(jumped, at);
  EXPECT_NE(j, std::string::npos);
  const double s = std::stod(notes.substr(j + jumped.size()));
  // The note gives the time from the first ceiling frame to a tenth of a second: the frame
  // nearest to it.
  const Stamp first = log.ceiling_images.front().value.stamp;
  Stamp frame = first;
  for (const auto& f : log.ceiling_images)
    if (std::abs(to_seconds(f.value.stamp - first) - s) < std::abs(to_seconds(frame - first) - s))
      frame = f.value.stamp;
  return io::TruthTrack(log.truth).at(frame);
}

// The true lamps the drive passed right under (within half a metre of its path, not in its first
// or last 3 s, where it starts or stops under a lamp and sees it from too few places): each one
// the map must hold.
std::set<std::string> lamps_passed_under(const graph::TopologicalMap& truth,
                                         const io::MissionLog& log) {
  std::set<std::string> out;
  const Stamp from = log.truth.front().value.stamp + std::chrono::seconds(3);
  const Stamp to = log.truth.back().value.stamp - std::chrono::seconds(3);
  for (const auto& t : log.truth) {
    if (t.value.stamp < from || t.value.stamp > to) continue;
    for (const graph::Lamp* l : truth.lamps_within(t.value.pose.translation(), 0.5))
      out.insert(l->id.value);
  }
  return out;
}

// The office mission is carried 52 s in, from C5 into the middle of C2 facing west: the drive
// after it comes back through J1 and down C5, where the drive before it went, then along C4.
// Its lamps fit many places of the first part's alike (a corridor onto its twin, a lamp further
// along, turned at a corner); the omni camera's views must tell them apart, or the part stays
// out. The office's corridor lamps are symmetric under a half turn about (21, 1): the twin
// place misses no more lamps than the true one, so the parts stay apart, and the map is the
// larger, the drive after the carry (18 lamps against 12), in the frame where the robot was put
// down. A survey given the drive's start keeps the drive before the carry instead, whose frame
// that start places. With one lamp of C4 failed, the twin is ruled out and the omni views fit
// one place; without the omni camera, the larger part again. Before parts were joined
// (`04751ec`) the map held the drive up to the carry; before carries were found (`1beb1c9`), 30
// lamps, 18 of them 0.5 to 2 m from any lamp.
TEST(MapBuild, ADriveInWhichTheRobotIsCarriedIsJoinedOnlyWhereItFitsOnePlace) {
  const fs::path dir =
      fs::temp_directory_path() / ("lampnav_map_carried_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  nlohmann::json doc =
      nlohmann::json::parse(test::slurp(test::source_path("maps/office_floor.geojson")));
  for (auto& f : doc["features"]) {
    if (!f["properties"].contains("lampnav")) continue;
    auto& lamps = f["properties"]["lampnav"]["lamps"];
    lamps.erase(std::remove_if(lamps.begin(), lamps.end(),
                               [](const nlohmann::json& l) { return l["id"] == "C4-L6"; }),
                lamps.end());
  }
  const std::string failed = (dir / "failed.geojson").string();
  std::ofstream(failed) << doc.dump();
  struct Case {
    std::string map;
    bool joined;
  };
  for (const Case& c :
       {Case{test::source_path("maps/office_floor.geojson"), false}, Case{failed, true}}) {
    SCOPED_TRACE(c.map);
    const std::string log = (dir / "mission.mcap").string(), out = (dir / "m.geojson").string();
    ASSERT_EQ(
        test::run_lampnav("sim --scenario office-mission --map '" + c.map + "' -o '" + log + "'")
            .status,
        0);
    const auto r = test::run_lampnav("map build '" + log + "' -o '" + out + "' --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
    std::cout << r.err;
    EXPECT_THAT(r.err, HasSubstr("the robot was carried"));
    // Not joined, the part after the carry maps more lamps than the part before: it is the map.
    EXPECT_THAT(r.err,
                HasSubstr(c.joined ? "is in the map" : "the map is built from the drive after it"));
    EXPECT_THAT(r.err, HasSubstr("the omni camera's"));
    const graph::TopologicalMap truth = graph::read_map(c.map).map;
    const io::MissionLog recorded = io::read_mission_log(log);
    const Pose2 start = recorded.truth.front().value.pose;
    const graph::TopologicalMap built = graph::read_map(out).map;
    const LampErrors e = lamp_errors(built, truth, map_origin(recorded, r.err));  // none false
    std::cout << e.matched.size() << " lamps, error rms " << e.rms * 100 << " cm, max "
              << e.worst * 100 << " cm\n";
    EXPECT_EQ(built.lamp_count(), e.matched.size());  // each lamp once
    EXPECT_LE(e.rms, 0.02);
    EXPECT_LE(e.worst, 0.05);
    const std::set<std::string> under = lamps_passed_under(truth, recorded);
    if (c.joined) {
      for (const std::string& id : under)
        EXPECT_TRUE(e.matched.count(id)) << id << " was passed under and is not in the map";
    } else {
      EXPECT_GE(e.matched.size(), 15u);  // the drive after the carry
      EXPECT_LT(e.matched.size(), under.size());
    }
    const auto s = test::run_lampnav("map survey '" + c.map + "' '" + log +
                                     "' --quiet --initial-pose " + std::to_string(start.x()) + "," +
                                     std::to_string(start.y()) + "," + std::to_string(start.yaw()));
    ASSERT_EQ(s.status, 0) << s.err;
    EXPECT_THAT(s.out, HasSubstr("0 failed, 0 moved, 0 new"));
    if (!c.joined) continue;

    // Without the omni camera the places alike stay alike: the drive after the carry is left out.
    nlohmann::json robot =
        nlohmann::json::parse(test::slurp(test::source_path("maps/robots/pioneer.json")));
    auto& cameras = robot["cameras"];
    cameras.erase(
        std::remove_if(cameras.begin(), cameras.end(),
                       [](const nlohmann::json& k) { return k["name"] == "omni_camera"; }),
        cameras.end());
    const std::string ceiling_only = (dir / "ceiling_only.json").string();
    std::ofstream(ceiling_only) << robot.dump();
    const auto alone = test::run_lampnav("map build '" + log + "' --robot '" + ceiling_only +
                                         "' -o '" + out + "' --quiet");
    ASSERT_EQ(alone.status, 0) << alone.err;
    EXPECT_THAT(alone.err, HasSubstr("places alike of the"));
    EXPECT_THAT(alone.err, HasSubstr("the map is built from the drive after it"));
    const LampErrors after =
        lamp_errors(graph::read_map(out).map, truth, map_origin(recorded, alone.err));
    EXPECT_LT(after.matched.size(), e.matched.size());
    EXPECT_LE(after.worst, 0.05);
  }
  fs::remove_all(dir);
}

// Carried and put down 0.7 to 1 m from lamps that the ceiling camera sees cut by the border
// (41 s into E1 -> Workshop), or whole, but where a lamp of the view before would have gone
// within the disc its travel allowed (17 s into E2 -> E1). Both went unseen before `2447f36`,
// and their maps held lamps 0.1 to 26 m from any true lamp.
TEST(MapBuild, ACarryPutDownBesideALampCutByTheBorderIsFound) {
  const fs::path dir =
      fs::temp_directory_path() / ("lampnav_map_carried_cut_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  struct Case {
    std::string route, seed, kidnap, jumped;
  };
  for (const Case& c : {Case{"E1 -> Workshop", "13", "41", "jumped 41.1 s"},
                        Case{"E2 -> E1", "11", "17", "jumped 17.1 s"}}) {
    SCOPED_TRACE(c.route);
    const std::string log = (dir / "drive.mcap").string(), out = (dir / "m.geojson").string();
    const std::string map = test::source_path("maps/office_floor.geojson");
    ASSERT_EQ(test::run_lampnav("sim --route '" + c.route + "' --map '" + map + "' --robot " +
                                test::quoted_source("maps/robots/pioneer.json") + " --seed " +
                                c.seed + " --kidnap " + c.kidnap + " -o '" + log + "'")
                  .status,
              0);
    const auto r = test::run_lampnav("map build '" + log + "' -o '" + out + "' --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr(c.jumped));
    EXPECT_THAT(r.err, HasSubstr("the robot was carried"));
    const io::MissionLog recorded = io::read_mission_log(log);
    const graph::TopologicalMap built = graph::read_map(out).map;
    const LampErrors e = lamp_errors(built, graph::read_map(map).map, map_origin(recorded, r.err));
    EXPECT_EQ(built.lamp_count(), e.matched.size());  // none false, each once
    EXPECT_GE(e.matched.size(), 5u);
    // The workshop's round lamp, of another kind than the corridors', is mapped too. Seen only
    // from the drive's last two metres, after the turn through the door, its place rests on the
    // wheels' heading through that turn: 7.4 cm off on seed 13 (2.4 cm on seed 1), past the 5 cm
    // the corridors' lamps keep (docs/mapping.md, "Lamps of several kinds").
    double corridors = 0;
    for (const auto& [id, err] : e.error)
      if (id.rfind("Workshop", 0) != 0) corridors = std::max(corridors, err);
    EXPECT_LE(corridors, 0.05);
    if (c.route == "E1 -> Workshop") {
      ASSERT_EQ(e.error.count("Workshop-L1"), 1u);
      EXPECT_LE(e.error.at("Workshop-L1"), 0.10);
    }
  }
  fs::remove_all(dir);
}

// A carry in a regular building (docs/mapping.md, "Carried parts in regular buildings"): the
// localization sweep's lobby grid (tests/fixtures/maps/grid_25m_lobby.geojson: `make_building
// nodes=21 block_m=25 lamp_spacing_m=2.5 ceiling_m=3.2 rooms=0 missing_corridors=1 rows=2
// row_spacing_m=1.2 seed=132 lobby=1`), J0_1 -> J2_1 carried at 20, 45 and 70 s on a floor
// swinging 0.8 degrees, one lamp in twelve failed (scripts/localization_sweep.py, seed 131).
// After the first carry the robot drives where the drive before it never went, yet its lamps
// fit 14 places of the first part's map alike. The omni views chose one, and the map held 20
// lamps, 9 of them half a metre or more from any lamp. Then that place was checked against what
// the views show: they miss 17 lamps more there than each part's own lamps alone, so the part
// was not joined, and the map is the larger part, each lamp where a lamp is. Since the places
// that fit but for one lamp are weighed too (14 more here), the views do not tell the likeliest
// from the next: not joined either way.
TEST(MapBuild, APartPutDownWhereTheDriveBeforeNeverWentIsNotJoinedToALookAlike) {
  const std::string map = test::source_path("tests/fixtures/maps/grid_25m_lobby.geojson");
  const std::vector<std::string> failed = {
      "H1_1-L5a", "H1_2-L3b", "V2_0-L3b", "Lobby-L2", "H0_1-L3a", "H1_2-L6a", "H1_1-L1b",
      "H0_0-L3a", "H1_2-L5b", "V2_0-L4b", "H0_1-L7b", "H1_1-L9b", "V0_0-L4a", "V0_0-L8a",
      "H0_1-L4b", "V1_1-L4b", "H0_2-L4b", "H1_0-L2a", "V1_1-L3a"};
  std::string flags =
      "--route 'J0_1 -> J2_1' --seed 131 --bumps 0.8 --kidnap 20 --kidnap 45 "
      "--kidnap 70 -q";
  for (const std::string& id : failed) flags += " --fail-lamp " + id;
  const Recorded rec(map, flags);
  const std::string out = (rec.dir / "m.geojson").string();
  const auto r = test::run_lampnav("map build '" + rec.log + "' -o '" + out + "' --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  std::cout << r.err;
  EXPECT_THAT(r.err, HasSubstr("jumped 20.1 s"));
  EXPECT_THAT(r.err, HasSubstr("the map is built from the drive after it"));
  const io::MissionLog recorded = io::read_mission_log(rec.log);
  const graph::TopologicalMap built = graph::read_map(out).map;
  const LampErrors e = lamp_errors(built, graph::read_map(map).map, map_origin(recorded, r.err));
  EXPECT_EQ(built.lamp_count(), e.matched.size());  // none false, each once
  EXPECT_GE(e.matched.size(), 8u);
  for (const std::string& id : failed) EXPECT_EQ(e.matched.count(id), 0u) << id << " is dark";
  EXPECT_LE(e.rms, 0.03);
}

// A wide-angle webcam calibrated as Kannala-Brandt (cv::fisheye, ROS's equidistant) as the ceiling
// camera: 352 x 288 at fx 200, its corners 64 degrees off the axis (the pinhole's, 39). The drive
// E1 -> K2 replays as well as with the pinhole webcam (0.56 cm RMS), never lost once found, and
// maps every lamp it passed under. Before the ceiling pipeline took the model it was refused;
// then, with candidates for a label only from the place and its neighbours, the replay was lost 6
// times for 11.6 s (lamps two places away labelled none), and with a pixel's and a floor bump's
// error taken alike across the image, twice for 13.4 s (lamps far off the axis disagreeing with
// the middle ones).
TEST(MapBuild, AWideAngleCeilingCameraCalibratedAsKannalaBrandtTracksAndMaps) {
  nlohmann::json robot =
      nlohmann::json::parse(test::slurp(test::source_path("maps/robots/pioneer.json")));
  for (auto& c : robot["cameras"]) {
    if (c["name"] != "ceiling_camera") continue;
    c.erase("distortion");
    c["model"] = "kannala_brandt";
    c["fx"] = 200.0;
    c["fy"] = 200.0;
    c["k"] = {0.02, -0.005, 0.0, 0.0};
  }
  const fs::path robot_path =
      fs::temp_directory_path() / ("lampnav_wide_" + std::to_string(::getpid()) + ".json");
  std::ofstream(robot_path) << robot.dump();
  const std::string map = test::source_path("maps/office_floor.geojson");
  const Recorded rec(map, "", robot_path.string());
  fs::remove(robot_path);
  const std::string out = (rec.dir / "replay").string();
  const auto r = test::run_lampnav("replay '" + rec.log + "' --out '" + out + "' --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto m = nlohmann::json::parse(test::slurp(out + "/metrics.json"));
  std::cout << r.out;
  EXPECT_LE(m["position_error_m"]["rms"].get<double>(), 0.01);
  EXPECT_EQ(m["wrong_fixes"].get<int>(), 0);
  EXPECT_LE(m["lost_s"].get<double>(), 9.0);  // only until the omni camera first finds it
  const std::string built = (rec.dir / "built.geojson").string();
  const auto b = test::run_lampnav("map build '" + rec.log + "' -o '" + built + "' --quiet");
  ASSERT_EQ(b.status, 0) << b.err;
  const graph::TopologicalMap truth = graph::read_map(map).map;
  const io::MissionLog log = io::read_mission_log(rec.log);
  const LampErrors e = lamp_errors(graph::read_map(built).map, truth, log.truth.front().value.pose);
  std::cout << e.matched.size() << " lamps, error rms " << e.rms * 100 << " cm, max "
            << e.worst * 100 << " cm\n";
  EXPECT_EQ(e.matched.size(), lamps_under_the_drive(truth));
  EXPECT_LE(e.rms, 0.02);
  EXPECT_LE(e.worst, 0.05);
}

// Carried out of the kitchen 12 s into Kitchen -> Lab 4: the drive before the carry saw only the
// kitchen's lamp, too few to join the rest to, so the drive's lamps start where the robot was put
// down. A survey given where the drive started cannot use that start (it would put the drive
// where it never was): it says so and places the drive by its lamps, which find the office as
// it is.
TEST(MapBuild, ASurveyGivenTheStartOfADriveWhoseFirstPartMapsNoLampPlacesItByItsLamps) {
  const fs::path dir =
      fs::temp_directory_path() / ("lampnav_survey_carried_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string log = (dir / "drive.mcap").string();
  const std::string map = test::source_path("maps/office_floor.geojson");
  ASSERT_EQ(test::run_lampnav("sim --route 'Kitchen -> Lab 4' --map '" + map + "' --robot " +
                              test::quoted_source("maps/robots/pioneer.json") +
                              " --seed 35 --kidnap 12 -o '" + log + "'")
                .status,
            0);
  const Pose2 start = io::read_mission_log(log).truth.front().value.pose;
  const auto s = test::run_lampnav("map survey '" + map + "' '" + log +
                                   "' --quiet --initial-pose " + std::to_string(start.x()) + "," +
                                   std::to_string(start.y()) + "," + std::to_string(start.yaw()));
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_THAT(s.err, HasSubstr("the drive before it mapped 1 lamp, too few to join the rest to"));
  EXPECT_THAT(s.err, HasSubstr("--initial-pose is where the drive started, which is not in the "
                               "drive's map"));
  EXPECT_THAT(s.out, HasSubstr("0 failed, 0 moved, 0 new"));
  fs::remove_all(dir);
}

// A building whose lamps hang 8 m up (a hall, a warehouse): map build does not assume the
// office's 2.7 m. Before the lamps' look was learnt from blobs down to a thirtieth of a radian
// (a 1.2 x 0.3 m lamp 7.7 m above the camera is 0.16 x 0.04 rad), it found no lamp; before lamps
// were followed across the image, at 5 m it mapped 42 lamps for 27, 12 of them nowhere.
TEST(MapBuild, LampsEightMetresUpAreMappedAsWell) {
  nlohmann::json doc =
      nlohmann::json::parse(test::slurp(test::source_path("maps/office_floor.geojson")));
  for (auto& f : doc["features"]) {
    if (!f["properties"].contains("lampnav")) continue;
    for (auto& l : f["properties"]["lampnav"]["lamps"]) l["xyz"][2] = 8.0;
  }
  const fs::path map = fs::temp_directory_path() /
                       ("lampnav_high_office_" + std::to_string(::getpid()) + ".geojson");
  std::ofstream(map) << doc.dump();
  const Recorded rec(map.string());
  const std::string out = (rec.dir / "built.geojson").string();
  const auto r = test::run_lampnav("map build '" + rec.log + "' -o '" + out + "' --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  std::cout << r.out;
  const graph::TopologicalMap truth = graph::read_map(map.string()).map;
  fs::remove(map);
  const io::MissionLog log = io::read_mission_log(rec.log);
  ASSERT_FALSE(log.truth.empty());
  const graph::TopologicalMap built = graph::read_map(out).map;
  const LampErrors e = lamp_errors(built, truth, log.truth.front().value.pose);
  EXPECT_EQ(e.matched.size(), lamps_under_the_drive(truth));
  std::cout << e.matched.size() << " lamps, error rms " << e.rms * 100 << " cm, max "
            << e.worst * 100 << " cm\n";
  EXPECT_LE(e.rms, 0.02);
  EXPECT_LE(e.worst, 0.05);
  for (const auto& n : built.nodes())
    for (const auto& l : n.lamps) EXPECT_NEAR(l.xyz.z(), 8.0, 0.03) << l.id.value;
}

// A map built from one drive along C1 and C2 (anchored at the drive's true start), then another
// drive of the same corridors replayed on it and on the true map: the same accuracy within 1 cm.
TEST(MapBuild, ReplayOnTheBuiltMapIsAsGoodAsOnTheTrueMap) {
  const fs::path dir =
      fs::temp_directory_path() / ("lampnav_map_replay_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string drive = (dir / "drive.mcap").string(),
                    mission = (dir / "mission.mcap").string();
  ASSERT_EQ(test::run_lampnav("sim --scenario corridor --seed 1 -o '" + drive + "'").status, 0);
  ASSERT_EQ(test::run_lampnav("sim --scenario corridor --seed 2 -o '" + mission + "'").status, 0);
  auto start_of = [](const std::string& log) {
    const Pose2 p = io::read_mission_log(log).truth.front().value.pose;
    return std::to_string(p.x()) + "," + std::to_string(p.y()) + "," + std::to_string(p.yaw());
  };
  // Built in the drive's own frame, then again placed by the best rigid alignment of its lamps
  // onto the true ones (how the accuracy is defined), so that the replays' errors compare.
  const std::string built = (dir / "built.geojson").string();
  auto b = test::run_lampnav("map build '" + drive + "' -o '" + built + "' --quiet");
  ASSERT_EQ(b.status, 0) << b.err;
  const graph::TopologicalMap truth =
      graph::read_map(test::source_path("maps/office_floor.geojson")).map;
  const Pose2 start = io::read_mission_log(drive).truth.front().value.pose;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> pairs;
  // (The map kept in a variable: a range over a temporary's nodes outlives the map. Found by
  // AddressSanitizer.)
  const graph::TopologicalMap built_map = graph::read_map(built).map;
  for (const auto& n : built_map.nodes()) {
    for (const auto& l : n.lamps) {
      const auto near = truth.lamps_within(start.transform_from(l.xyz.head<2>()), 0.3);
      if (!near.empty()) pairs.emplace_back(l.xyz.head<2>(), near.front()->xyz.head<2>());
    }
  }
  const Pose2 fit = mapping::fit_rigid(pairs);
  b = test::run_lampnav("map build '" + drive + "' -o '" + built + "' --quiet --initial-pose " +
                        std::to_string(fit.x()) + "," + std::to_string(fit.y()) + "," +
                        std::to_string(fit.yaw()));
  ASSERT_EQ(b.status, 0) << b.err;
  double rms[2] = {0, 0};
  const std::string maps[2] = {built, test::source_path("maps/office_floor.geojson")};
  for (int k = 0; k < 2; ++k) {
    const std::string out = (dir / ("replay" + std::to_string(k))).string();
    const auto r = test::run_lampnav("replay '" + mission + "' --map '" + maps[k] + "' --out '" +
                                     out + "' -q --initial-pose " + start_of(mission));
    ASSERT_EQ(r.status, 0) << r.err;
    const auto metrics = nlohmann::json::parse(test::slurp(out + "/metrics.json"));
    rms[k] = metrics["position_error_m"]["rms"].get<double>();
    EXPECT_EQ(metrics["wrong_fixes"], 0) << maps[k];
  }
  std::cout << "replay position RMS: built map " << rms[0] * 100 << " cm, true map " << rms[1] * 100
            << " cm\n";
  EXPECT_LE(std::abs(rms[0] - rms[1]), 0.01);
  fs::remove_all(dir);
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
