// Regular generated buildings with lamps failed (lit in the map, dark in the building), floors
// that swing the cameras and robots carried twice, replayed without their start: the drives of a
// sweep of 24 (docs/hypotheses.md, "Failed lamps and carries") that published a wrong pose as
// certain before the changes these tests keep.

#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "lampnav/evaluation/replay.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav/sim/scenario.hpp"
#include "lampnav_test.hpp"
#include "recorded_drive.hpp"

namespace lampnav {
namespace {

// A generated grid: about `nodes` nodes, junctions `block_m` apart, lamps `spacing_m` apart
// `ceiling_m` up, rooms (sim::BuildingOptions for the rest).
sim::BuildingOptions grid(int nodes, double block_m, double spacing_m, double ceiling_m,
                          std::uint64_t seed) {
  sim::BuildingOptions b;
  b.nodes = nodes;
  b.block_m = block_m;
  b.lamp_spacing_m = spacing_m;
  b.ceiling_m = ceiling_m;
  b.seed = seed;
  return b;
}

// The sweeps' grid of two rows (`grid_two_rows`): 4 x 4 junctions 15 m apart, two rows of lamps
// 1.5 m apart across every corridor, lamps 2.5 m apart 3 m up, rooms, a corridor missing; about
// `nodes` nodes.
sim::BuildingOptions two_rows_grid(int nodes) {
  sim::BuildingOptions b = grid(nodes, 15, 2.5, 3.0, 93);
  b.missing_corridors = 1;
  b.rows = 2;
  b.row_spacing_m = 1.5;
  return b;
}

// `lampnav sim --map B --route 'FROM -> TO' --seed S --kidnap 25 --kidnap 60 --fail-lamp ...
// --bumps 1.0` on the building (its GeoJSON), with what `more` changes, replayed without its
// start.
evaluation::Metrics replayed_on(const std::string& geojson, const std::string& from,
                                const std::string& to, std::uint64_t seed,
                                const std::vector<std::string>& failed, const std::string& log_name,
                                const std::function<void(sim::Scenario&)>& more,
                                const evaluation::ReplayOptions& options = {}) {
  const graph::TopologicalMap map = graph::parse_map(geojson, "building.geojson").map;
  const RobotDescription robot =
      read_robot_description(test::source_path("maps/robots/pioneer.json"));
  sim::Scenario s = sim::make_route_scenario(map, geojson, robot, from, to, seed);
  s.kidnaps = {{25, std::nullopt}, {60, std::nullopt}};
  s.failed_lamps.insert(failed.begin(), failed.end());
  s.bump_sigma_rad = 1.0 * M_PI / 180;
  more(s);
  const io::MissionLog log = test::recorded_drive(s, log_name);

  const evaluation::ReplayResult r = evaluation::replay(log, map, robot, options);
  for (const auto& e : r.events)
    std::cout << to_seconds(e.stamp) << " s: " << fusion::to_string(e.mode) << ", " << e.reason
              << "\n";
  return evaluation::score(r, log);
}

// The same on a generated building.
evaluation::Metrics replayed(const sim::BuildingOptions& building, const std::string& from,
                             const std::string& to, std::uint64_t seed,
                             const std::vector<std::string>& failed, const std::string& log_name,
                             const std::function<void(sim::Scenario&)>& more,
                             const evaluation::ReplayOptions& options = {}) {
  return replayed_on(sim::generate_building(building).geojson, from, to, seed, failed, log_name,
                     more, options);
}

// The fourth sweep's drives of seed 86: the floor swings the cameras 0.8 degrees, the wheels
// read 1.0 % short and 0.8 % long, the ceiling frames come 1.5 s late; replayed to
// `max_duration_s`.
void as_seed_86_drove(sim::Scenario& s, double max_duration_s) {
  s.bump_sigma_rad = 0.8 * M_PI / 180;
  s.odometry.left_scale = -0.01;
  s.odometry.right_scale = 0.008;
  s.ceiling_delay_s = 1.5;
  s.max_duration_s = max_duration_s;
}

// The eighth sweep's drives of seed 96: carried at 20, 45 and 70 s, as seed 86 drove
// (as_seed_86_drove) but on a floor swinging the cameras 1.2 degrees; replayed to
// `max_duration_s`.
void as_seed_96_drove(sim::Scenario& s, double max_duration_s) {
  s.kidnaps = {{20, std::nullopt}, {45, std::nullopt}, {70, std::nullopt}};
  as_seed_86_drove(s, max_duration_s);
  s.bump_sigma_rad = 1.2 * M_PI / 180;
}

// The thirteenth sweep's drives (`make sweep`): carried at 20, 45 and 70 s, the floor swinging
// the cameras 0.8 degrees (its seeds 131, 141, 151).
void as_the_thirteenth_sweep_drove(sim::Scenario& s) {
  s.kidnaps = {{20, std::nullopt}, {45, std::nullopt}, {70, std::nullopt}};
  s.bump_sigma_rad = 0.8 * M_PI / 180;
}

// Its drives on the rough floor (seeds 132, 142, 152): 1.5 degrees, the wheels reading 1.0 % long
// and 0.8 % short, the ceiling frames 1.2 s late.
void as_the_thirteenth_sweep_drove_on_the_rough_floor(sim::Scenario& s) {
  as_the_thirteenth_sweep_drove(s);
  s.bump_sigma_rad = 1.5 * M_PI / 180;
  s.odometry.left_scale = 0.01;
  s.odometry.right_scale = -0.008;
  s.ceiling_delay_s = 1.2;
}

// That sweep's `grid_10m_low` (5 x 5 junctions 10 m apart, lamps 2 m apart 2.6 m up, 0.8 m above
// the omni camera, two corridors missing) driven `J2_0 -> J2_4` as the sweep drove it (or the
// route and floor given).
evaluation::Metrics replayed_on_grid_10m_low(
    std::uint64_t seed, const std::vector<std::string>& failed, const std::string& log_name,
    const evaluation::ReplayOptions& options, const std::string& from = "J2_0",
    const std::string& to = "J2_4",
    const std::function<void(sim::Scenario&)>& drove = as_the_thirteenth_sweep_drove) {
  sim::BuildingOptions b = grid(75, 10, 2.0, 2.6, 131);
  b.missing_corridors = 2;
  return replayed(b, from, to, seed, failed, log_name, drove, options);
}

// A drive a change mended: `drive(false)` replays it without the change (a wrong fix),
// `drive(true)` as it is (none, after its `kidnaps` carries).
void expect_mended(const std::function<evaluation::Metrics(bool with_change)>& drive,
                   int kidnaps = 2) {
  EXPECT_GE(drive(false).wrong_fixes, 1);
  const evaluation::Metrics m = drive(true);
  ASSERT_EQ(m.kidnaps, kidnaps);
  EXPECT_EQ(m.wrong_fixes, 0);
}

// A drive of `grid_10m_low` (replayed_on_grid_10m_low) that a change mended, carried three times
// (expect_mended): `change` sets the options with the change or without it.
void expect_mended_on_grid_10m_low(
    std::uint64_t seed, const std::vector<std::string>& failed, const std::string& log_name,
    const std::function<void(evaluation::ReplayOptions&, bool with_change)>& change,
    const std::string& from = "J2_0", const std::string& to = "J2_4",
    const std::function<void(sim::Scenario&)>& drove = as_the_thirteenth_sweep_drove) {
  expect_mended(
      [&](bool with_change) {
        evaluation::ReplayOptions o;
        change(o, with_change);
        return replayed_on_grid_10m_low(seed, failed, log_name, o, from, to, drove);
      },
      3);
}

// The fourth sweep's office-like grid: 4 x 4 junctions 24 m apart, lamps 2.25 m apart 2.7 m up,
// rooms, a corridor missing; one lamp in twelve failed, carried at 20, 45 and 70 s.
evaluation::Metrics replayed_on_the_office_grid(const std::string& from, const std::string& to,
                                                std::uint64_t seed,
                                                const std::vector<std::string>& failed,
                                                const std::string& log_name,
                                                const std::function<void(sim::Scenario&)>& more) {
  sim::BuildingOptions b = grid(40, 24, 2.25, 2.7, 75);
  b.missing_corridors = 1;
  const evaluation::Metrics m =
      replayed(b, from, to, seed, failed, log_name, [&](sim::Scenario& s) {
        s.kidnaps = {{20, std::nullopt}, {45, std::nullopt}, {70, std::nullopt}};
        more(s);
      });
  EXPECT_EQ(m.kidnaps, 3);
  return m;
}

// A drive of seed 86 on the office-like grid (as_seed_86_drove), replayed to `max_duration_s`:
// it publishes no wrong pose.
void expect_no_wrong_fix_on_the_office_grid(const std::string& from, const std::string& to,
                                            const std::vector<std::string>& failed,
                                            const std::string& log_name, double max_duration_s) {
  const evaluation::Metrics m =
      replayed_on_the_office_grid(from, to, 86, failed, log_name,
                                  [&](sim::Scenario& s) { as_seed_86_drove(s, max_duration_s); });
  EXPECT_EQ(m.wrong_fixes, 0);
}

// A 3 x 3 grid of junctions 12 m apart, lamps 2 m apart 2.5 m up, a lobby, two corridors missing.
// Carried at 25 s, the robot was not found again by 60 s; its set's leader, the place it stood
// at 60 s, was carried away with it. The first omni image after the carry contradicted the
// leader (9.2, the cap), and every hypothesis but one far behind; the ceiling frame captured
// before that image, weighed after it (the ceiling camera's frames come a second late), said
// nothing and cleared the contradiction, and the leader, 4.9 m off, was published at once (for
// 2.7 s). Only an omni image judges a contradiction now; the next one must clear it.
TEST(FailedLampsAndCarries, AContradictionHoldsUntilTheNextOmniImage) {
  sim::BuildingOptions b = grid(25, 12, 2.0, 2.5, 72);
  b.rooms = false;
  b.missing_corridors = 2;
  b.lobby = true;
  const evaluation::Metrics m =
      replayed(b, "J0_1", "J2_1", 81, {"V2_1-L5", "V1_0-L4", "H0_1-L4", "H1_2-L5"},
               "failed_lamps_contradiction.mcap",
               [](sim::Scenario& s) { s.max_duration_s = 66; });  // published at 61.6 s
  ASSERT_EQ(m.kidnaps, 2);
  EXPECT_EQ(m.wrong_fixes, 0);
}

// A 4 x 4 grid of junctions 15 m apart, lamps 2.5 m apart 3 m up (3 m apart east of the middle),
// rooms; the floor swings the cameras 1.5 degrees and the wheels read 1.2 % long and 0.9 % short.
// After the second carry an audit found the robot gone, and one omni image gave nine places.
// The truth was born 30 cm to the side of its corridor's axis, its position sigma 12 cm, and the
// lamps its ceiling camera saw overhead fell outside its gate: each was charged as a lamp the map
// lacks, frame after frame. Its quarter-turn twin 35 m away, born off along its corridor, took
// its lamps and was pulled onto them; two seconds later the twin was published. Until a
// hypothesis is fitted to ceiling lamps, its lamps are now labelled with at least the position
// uncertainty an omni image leaves (20 cm).
TEST(FailedLampsAndCarries, ARightPlaceBornBesideItsLampsLabelsThem) {
  sim::BuildingOptions b = grid(40, 15, 2.5, 3.0, 71);
  b.wing_lamp_spacing_m = 3.0;
  const evaluation::Metrics m =
      replayed(b, "J3_0", "J0_3", 82, {"V1_2-L3", "V1_0-L2", "H0_2-L4", "V0_0-L3"},
               "failed_lamps_born_beside.mcap", [](sim::Scenario& s) {
                 s.bump_sigma_rad = 1.5 * M_PI / 180;
                 s.odometry.left_scale = 0.012;
                 s.odometry.right_scale = -0.009;
                 s.max_duration_s = 70;  // the twin was published at 65.5 s
               });
  ASSERT_EQ(m.kidnaps, 2);
  EXPECT_EQ(m.wrong_fixes, 0);
}

// The office-like grid, 18 lamps of 223 failed, the omni frames 0.9 s late. Lost
// on the west side (the truth driving north at x = 0), the set started again from one image:
// its half-turn twin on the east side and the truth tie after the search's first round (52.98
// each, with six more turned places), the first of them by the order of its cell was refined in
// full (17.35), and the others, judged against that, were left out. One place, the twin 73 m
// off, was born as the whole set and published for 80 s. Every place tied after the first round
// is refined in full now (lamp_pairs.cpp, exhaustive()).
TEST(FailedLampsAndCarries, TwinsTiedAfterTheSearchsFirstRoundAreRefinedAlike) {
  const evaluation::Metrics m = replayed_on_the_office_grid(
      "J3_0", "J0_3", 85,
      {"H2_0-L4", "V0_0-L4", "V2_0-L5", "V1_2-L3", "H2_0-L2", "H2_1-L3", "V1_2-L5", "H1_1-L9",
       "V0_1-L5", "H1_0-L2", "H0_1-L1", "H2_1-L9", "H0_2-L3", "V2_2-L5", "V3_0-L2", "H0_3-L3",
       "V3_0-L4", "V3_2-L3"},
      "failed_lamps_twins_refined.mcap", [](sim::Scenario& s) {
        s.bump_sigma_rad = 1.2 * M_PI / 180;
        s.omni_delay_s = 0.9;
        s.max_duration_s = 130;  // the twin was published at 122.9 s
      });
  EXPECT_EQ(m.wrong_fixes, 0);
}

// The same building, seed 86: the ceiling frames 1.5 s late, the wheels 1.0 % short and 0.8 %
// long. Three wrong fixes, each taken back within 3 s: at 130 s the truth 0.5 m off along its
// corridor, at 172 s a place 26 m off, after omni images that cost every hypothesis 42 to 140 (a
// right place's pays 0 to 5) and so raised the least wrong above the rest, a frame's costs being
// relative. A hypothesis whose image misfits it past odd_image_misfit is contradicted by it now:
// an image that fits none of them starts the set again instead of deciding it.
TEST(FailedLampsAndCarries, AnImageThatFitsNoHypothesisDecidesNone) {
  expect_no_wrong_fix_on_the_office_grid(
      "J0_2", "J3_1",
      {"H0_1-L5", "V3_2-L9", "V1_1-L8", "V1_0-L8", "H2_2-L1", "H0_3-L2", "V2_1-L1", "H2_3-L2",
       "V2_0-L4", "H2_3-L3", "V1_1-L9", "H2_2-L2", "H1_1-L4", "H2_2-L5", "V3_1-L8", "H0_1-L6",
       "V2_2-L6", "V0_0-L7"},
      "failed_lamps_odd_images.mcap", 180);  // the last wrong fix was published at 172.5 s
}

// The same building, seed 86, from J3_0 to J0_3. Lost after the third carry, the set held the
// truth at the north end of the west corridor and its twin 48 m south in the same corridor,
// facing the same way. The twin left up to 23 blobs of each image unexplained, lamps the truth
// matched, whose lamps it placed beyond the map's south end: once its far account was spent
// (9.2 in all) they cost it nothing, while the truth paid for their directions. Over the 36
// images from 97 s it fell behind by 35.1 and the twin was published at 135 s, 48 m off. Such a
// blob costs at least beyond_map_blob_cost (2) an image now.
TEST(FailedLampsAndCarries, BlobsLeftBeyondTheMapAreNeverFree) {
  expect_no_wrong_fix_on_the_office_grid(
      "J3_0", "J0_3",
      {"H1_0-L7", "V3_1-L5", "V3_2-L1", "H0_2-L9", "H2_1-L6", "V2_2-L6", "J1_0-L1", "H0_2-L7",
       "H0_1-L8", "H0_2-L8", "V1_2-L8", "H2_3-L7", "V1_2-L1", "H2_0-L6", "V1_0-L6", "V0_1-L3",
       "J2_3-L1", "H2_2-L1"},
      "failed_lamps_beyond_the_map.mcap", 138);  // the twin was published at 135 s
}

// A 4 x 4 grid of junctions 20 m apart, lamps 2.5 m apart 2.6 m up (2 m apart east of the middle),
// three corridors missing, no rooms: the fourth sweep's third building, its drives of seed 86.
// Replayed to `max_duration_s`, the drive meets `kidnaps` carries and publishes no wrong pose.
void expect_no_wrong_fix_on_the_bare_grid(const std::string& from, const std::string& to,
                                          const std::vector<std::string>& failed,
                                          const std::string& log_name, double max_duration_s,
                                          int kidnaps) {
  sim::BuildingOptions b = grid(40, 20, 2.5, 2.6, 77);
  b.rooms = false;
  b.missing_corridors = 3;
  b.wing_lamp_spacing_m = 2.0;
  const evaluation::Metrics m = replayed(b, from, to, 86, failed, log_name, [&](sim::Scenario& s) {
    s.kidnaps = {{20, std::nullopt}, {45, std::nullopt}, {70, std::nullopt}};
    as_seed_86_drove(s, max_duration_s);
  });
  EXPECT_EQ(m.kidnaps, kidnaps);
  EXPECT_EQ(m.wrong_fixes, 0);
}

// Lost after the third carry, the set held the truth and its twin 40 m off, the same corridor
// turned half round. Every image cost both about alike, but 13 of the 19 images since the set
// started contradicted the twin and none the truth: the twin left up to 29 blobs of an image
// unexplained (more than half of them in most), their lamps beyond the map's places, which its
// far account charges at most 9.2 in all. The twin was published at 119 s, 40 m off. A
// contradiction is charged as evidence now (HypothesisSetOptions::contradiction_cost).
TEST(FailedLampsAndCarries, ATwinTheImagesKeepContradictingLoses) {
  expect_no_wrong_fix_on_the_bare_grid(
      "J0_2", "J3_1",
      {"V3_2-L4", "V1_0-L3", "H2_1-L2", "V1_1-L3", "H2_3-L4", "H1_3-L5", "V3_0-L8", "H1_3-L1",
       "V2_2-L2", "H2_0-L3", "H0_1-L7", "H1_1-L6", "J1_3-L1", "V3_2-L5"},
      "failed_lamps_contradicted_twin.mcap", 122, 3);
}

// Carried 22 m at 45 s while its set's leader was the truth (0.995): the first omni image after
// cost every hypothesis 54 to 139 (2 of 2,003 images at the truth cost more than 45) and, the costs
// of a frame being relative, raised the least wrong to 0.9993: the robot's place before the carry,
// published for 0.8 s. An image that costs a hypothesis past odd_image_cost (45) contradicts it
// now, so one that fits none of them starts the set again.
TEST(FailedLampsAndCarries, AnImageNoHypothesisExplainsStartsTheSetAgain) {
  expect_no_wrong_fix_on_the_bare_grid(
      "J1_0", "J2_3",
      {"V1_2-L1", "V3_0-L9", "H1_2-L4", "H2_3-L5", "H0_1-L2", "V1_0-L5", "H2_0-L3", "H1_0-L1",
       "J3_0-L1", "H2_0-L7", "J3_1-L1", "H2_1-L2", "V1_0-L3", "V2_2-L3"},
      "failed_lamps_odd_image_cost.mcap", 52, 2);
}

// Two rows of lamps 1.5 m apart across every corridor: a 4 x 4 grid of junctions 15 m apart, lamps
// 2.5 m apart 3 m up, rooms, a corridor missing; the floor swings the cameras 1.2 degrees, the
// wheels read 1.0 % short and 0.8 % long, the ceiling frames come 1.5 s late; 31 of 374 lamps out.
// Carried 3 m along its corridor at 45 s, the robot was looked for. At 51 s the truth matched
// 17 lamps in clear view (two rows) and every blob of the image, and misfit 25.1 (1.5 a lamp);
// its twin 30 m north matched 12 and misfit 15.9, the 12 blobs it left (a room's lamps beside the
// truth, beyond the building beside the twin) going to the far account. The truth, past
// odd_image_misfit (20), was contradicted, and the twin was published 30 m off for 6 s. The bound
// grows with the lamps matched in clear view now (odd_image_misfit_per_lamp).
TEST(FailedLampsAndCarries, AnImageOfManyLampsIsNotOddForMatchingThemAll) {
  const sim::BuildingOptions b = two_rows_grid(55);
  expect_mended([&](bool with_change) {
    evaluation::ReplayOptions o;
    // Without it the bound was 20 whatever the lamps; and a tie was an image within 1 of the
    // best (omni_tie_cost) and the margins to publish were as configured, as then: a tie of 2
    // alone, or the margins raised to the floor's swing alone, mend this drive too.
    if (!with_change) {
      o.runtime.localizer.hypotheses.odd_image_misfit_per_lamp = 0;
      o.runtime.localizer.hypotheses.omni_tie_cost = 1.0;
      o.runtime.localizer.hypotheses.publish_follows_swing = false;
    }
    return replayed(
        b, "J0_0", "J3_3", 96,
        {"H0_1-L5b", "H0_2-L1b", "H1_0-L1b", "H1_1-L1a", "H1_2-L3b", "H1_2-L4a", "H1_3-L4b",
         "H1_3-L5a", "H2_0-L1b", "H2_0-L4a", "H2_1-L1a", "H2_1-L4a", "H2_3-L3a", "J0_2-L1b",
         "J1_1-L1b", "J2_3-L1b", "R0_0-L3",  "R0_0-L8",  "R1_0-L11", "R1_1-L2",  "R2_0-L4",
         "R2_1-L16", "R2_2-L10", "R2_2-L7",  "V0_0-L4b", "V0_1-L3a", "V1_0-L1b", "V2_1-L3b",
         "V3_0-L1a", "V3_0-L5a", "V3_1-L2b"},
        "failed_lamps_two_rows.mcap",
        [](sim::Scenario& s) { as_seed_96_drove(s, 60); },  // the twin was published at 51.5 s
        o);
  });
}

// The fourteenth sweep's drive `grid_10m_low J2_0 -> J2_4` seed 141 (`scripts/localization_sweep.py
// --seed-offset 10`; replayed_on_grid_10m_low), one lamp in twelve failed. With an image within 1
// of the best a tie, two wrong fixes (this drive was not traced; the office grid's and the office
// mission's were, where images fitted the truth and its twin within 2 of each other, each way in
// turn, and such small differences added up). An image within 2 of the best is a tie now
// (HypothesisSetOptions::omni_tie_cost, from 1).
TEST(FailedLampsAndCarries, ImagesWithinTwoOfTheBestAreTies) {
  expect_mended_on_grid_10m_low(
      141, {"H0_3-L4", "V4_0-L3", "J2_4-L1",  "V3_1-L4", "H0_0-L1", "R1_0-L13", "H0_1-L3",
            "R3_2-L4", "V1_3-L2", "R0_3-L14", "R3_2-L7", "V4_1-L3", "J3_3-L1",  "J0_4-L1",
            "R3_2-L5", "V0_0-L4", "R0_1-L7",  "R0_3-L7", "V4_0-L2", "V3_2-L4",  "R1_0-L1"},
      "failed_lamps_ties.mcap", [](evaluation::ReplayOptions& o, bool with_change) {
        o.runtime.localizer.hypotheses.omni_tie_cost = with_change ? 2.0 : 1.0;
        // The margins raised to the floor's swing mend it too: as configured, as then.
        o.runtime.localizer.hypotheses.publish_follows_swing = with_change;
      });
}

// A 4 x 4 grid of junctions 18 m apart, lamps 2.0 m apart 2.6 m up, 0.8 m above the omni camera,
// rooms, two corridors missing (tests/fixtures/maps/low_ceiling_grid.geojson, the eighth sweep's
// n1); the floor swings the cameras 1.2 degrees. After the second carry the truth's images misfit
// it by 20.5 and 22.4 with 6 to 8 lamps in clear view, past odd_image_misfit: contradicted twice,
// its twin 18 m off was published at 58.5 s. The poses near an odd hypothesis are searched now
// (odd_image_search_m), and the truth, moved onto one the image fitted (misfit 14.5), led.
TEST(FailedLampsAndCarries, AHypothesisOffByMoreThanItKnowsIsSearchedAbout) {
  const std::string geojson = test::slurp(test::fixture("maps/low_ceiling_grid.geojson"));
  expect_mended([&](bool with_change) {
    evaluation::ReplayOptions o;
    if (!with_change) {
      o.runtime.localizer.hypotheses.odd_image_search_m = 0;
      // Far blobs capped (AFarBlobCostsAtMostAStrays) and the margins raised to the floor's swing
      // mend this drive too: uncapped and as configured, as then.
      o.runtime.localizer.global.pairs.far_blob_cost_max = std::numeric_limits<double>::infinity();
      o.runtime.localizer.hypotheses.publish_follows_swing = false;
    }
    return replayed_on(
        geojson, "J3_0", "J0_3", 92,
        {"H0_0-L7", "H0_1-L8",  "H0_2-L8",  "H0_3-L5", "H1_3-L1", "H2_1-L6",  "J3_1-L1",
         "R0_2-L9", "R1_0-L10", "R1_0-L13", "R1_0-L8", "R1_0-L9", "R2_2-L11", "R2_2-L16",
         "V1_1-L2", "V1_1-L8",  "V2_1-L1",  "V2_1-L4", "V3_0-L2", "V3_0-L6",  "V3_1-L2",
         "V3_1-L4", "V3_1-L6",  "V3_2-L2",  "V3_2-L6"},
        "failed_lamps_low_ceiling.mcap",
        [](sim::Scenario& s) { as_seed_96_drove(s, 64); },  // the twin was published at 58.5 s
        o);
  });
}

// A 3 x 3 lattice of corridors 16 m long crossing at 60 degrees, half-turn symmetric, lamps 3.2 m
// up (tests/fixtures/maps/oblique_lattice.geojson: the ninth sweep's map, written by
// scripts/make_look_alike_buildings.py, its coordinates rounded to the micrometre). The floor
// swings the cameras 1.2 degrees; the continuity check learns 1.2 to 1.4. After the second carry
// the truth was born 6 degrees off, held at the configured 1.5 degrees; at the lattice's sharp
// corner its refinement settled 1.2 m away, odd, and its half-turn twin was published 51 m off
// at 62.5 s. Newborns are now held as loosely as the floor swings (births_follow_swing).
TEST(FailedLampsAndCarries, NewbornsOnASwingingFloorAreHeldAsLooselyAsItSwings) {
  const std::string geojson = test::slurp(test::fixture("maps/oblique_lattice.geojson"));
  expect_mended([&](bool with_change) {
    evaluation::ReplayOptions o;
    o.runtime.localizer.hypotheses.births_follow_swing = with_change;
    // The margins raised to the floor's swing mend it too: as configured, as then.
    o.runtime.localizer.hypotheses.publish_follows_swing = with_change;
    return replayed_on(
        geojson, "P2_0", "P0_2", 98, {"C12-L1", "C4-L2", "C7-L4", "P0_2-L1"},
        "failed_lamps_lattice.mcap", [](sim::Scenario& s) { as_seed_96_drove(s, 66); }, o);
  });
}

// The thirteenth sweep's drive `grid_10m_low J2_0 -> J2_4` seed 131 (`make sweep`;
// replayed_on_grid_10m_low), one lamp in twelve failed. A far blob used to cost its full distance
// to the lamp nearest it: the truth paid 7.9 and 7.5 for two lights beside its lamps near the
// horizon, and a quarter-turn twin was published 14 m off (twice on this drive; once with ties of
// 2, ImagesWithinTwoOfTheBestAreTies). It now costs at most a stray's
// (LampPairOptions::far_blob_cost_max).
TEST(FailedLampsAndCarries, AFarBlobCostsAtMostAStrays) {
  expect_mended_on_grid_10m_low(
      131, {"R1_1-L6",  "V0_2-L2", "H2_1-L1", "V1_1-L1", "R1_0-L7", "H0_2-L1",  "V1_0-L3",
            "H3_0-L4",  "R3_2-L7", "H2_2-L4", "J2_1-L1", "R0_1-L6", "V2_3-L2",  "V4_2-L2",
            "R0_1-L10", "R0_1-L7", "H1_1-L3", "J1_4-L1", "V3_0-L2", "R0_1-L13", "V2_2-L2"},
      "failed_lamps_grid_10m_low.mcap", [](evaluation::ReplayOptions& o, bool with_change) {
        if (!with_change)
          o.runtime.localizer.global.pairs.far_blob_cost_max =
              std::numeric_limits<double>::infinity();
      });
}

// The fifteenth sweep's drive `grid_10m_low J0_2 -> J4_2` seed 152 (`scripts/localization_sweep.py
// --seed-offset 20`), on the rough floor, one lamp in twelve failed. The floor swings the cameras
// three times what the models assume, and each image, weighed with the configured models, says
// more than it knows: with the margins to publish as configured, a look-alike place 14 m off was
// published at 26.5 s, until audits found it at 33.5 s. The margins are raised to the floor's
// swing now (HypothesisSetOptions::publish_follows_swing): nothing is published on this drive.
TEST(FailedLampsAndCarries, OnASwingingFloorTheMarginsToPublishFollowTheSwing) {
  expect_mended_on_grid_10m_low(
      152, {"V1_0-L4",  "H3_3-L3", "V0_3-L3",  "R0_1-L10", "H2_1-L1",  "H0_2-L1", "H3_0-L4",
            "H2_4-L4",  "H0_3-L2", "R3_2-L5",  "V4_2-L3",  "J3_0-L1",  "V3_1-L2", "R0_3-L2",
            "R0_3-L12", "H1_4-L1", "R1_1-L10", "H0_4-L1",  "R1_1-L15", "R3_2-L1", "V3_1-L3"},
      "failed_lamps_swinging_margins.mcap",
      [](evaluation::ReplayOptions& o, bool with_change) {
        o.runtime.localizer.hypotheses.publish_follows_swing = with_change;
      },
      "J0_2", "J4_2", as_the_thirteenth_sweep_drove_on_the_rough_floor);
}

// The held-out sixteenth sweep's drive `grid_two_rows J0_2 -> J3_1` seed 161
// (`scripts/localization_sweep.py --seed-offset 30`), one lamp in twelve failed, no carry in its
// first 15 s. The first omni images put the half-turn twin 45 m off ahead of the truth, and the set
// published it at 2.5 s with the steady floor's margins: the floor, which swings the cameras 1.8
// times what the models assume, was not measured yet. Until it is, the margins are those of the
// largest swing the continuity check could measure (unmeasured_floor_swings_most).
TEST(FailedLampsAndCarries, UntilTheFloorIsMeasuredTheMarginsAreTheRoughestFloors) {
  const sim::BuildingOptions b = two_rows_grid(54);  // as the sweep script asks for it
  expect_mended(
      [&](bool with_change) {
        evaluation::ReplayOptions o;
        o.runtime.localizer.hypotheses.unmeasured_floor_swings_most = with_change;
        return replayed(
            b, "J0_2", "J3_1", 161,
            {"V0_0-L1b", "H2_2-L3a", "V0_1-L4b", "H2_0-L4a", "H2_3-L4b", "V2_1-L2a", "V1_0-L5a",
             "R2_1-L7",  "H0_1-L4b", "V3_1-L3a", "R2_1-L8",  "R2_2-L10", "V3_2-L5b", "H0_2-L3b",
             "R2_1-L12", "V3_1-L5b", "H0_3-L1a", "R2_1-L6",  "V2_0-L3a", "H0_3-L5a", "V1_1-L2a",
             "R2_1-L4",  "V3_2-L1a", "H0_0-L2a", "H0_0-L4a", "J1_2-L1b", "V0_0-L3b", "J2_2-L1b",
             "V2_1-L4a", "V3_0-L2a", "R1_1-L14"},
            "failed_lamps_unmeasured_floor.mcap",
            [](sim::Scenario& s) {
              as_the_thirteenth_sweep_drove(s);
              s.max_duration_s = 15;
            },
            o);
      },
      0);
}

}  // namespace
}  // namespace lampnav
