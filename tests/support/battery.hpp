#pragma once
// A battery for multi-hypothesis localization: a robot driven through a building (a person at
// the joystick: along corridors, a random way at each junction), with noisy odometry and the
// lamp detections of both cameras (sim::LampSensors, no rendering) delivered late as on the real
// robot, fed to the Localizer in arrival order. Episodes: kidnaps (tracking, then put down
// anywhere in a corridor at any heading) and unknown starts; each is scored against the truth:
// detected, relocalized to the true place, wrong fixes (a pose published as certain more than
// 0.5 m off), latency in seconds and metres, hypotheses at most. Shared by tests and bench.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/fusion/localizer.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/sim/building.hpp"
#include "lampnav/sim/lamp_sensors.hpp"

namespace lampnav::test {

struct EpisodeResult {
  bool detected = false;     // kidnap: the localizer left tracking after it
  bool fixed = false;        // a pose was published as certain after the kidnap / start
  bool fix_correct = false;  // ... within 0.5 m and 5 degrees of the truth
  int wrong_fixes = 0;       // stretches published as certain more than 0.5 m off (excused:
                             // between a kidnap and its detection, 10 s at most)
  double fix_error_m = 0;    // of the first fix
  double latency_s = 0, latency_m = 0;  // kidnap (or start) to the first fix
  double detection_s = 0;               // kidnap to detection
  std::size_t max_hypotheses = 0;
  double ambiguous_s = 0, lost_s = 0;
  double localizer_s = 0;  // wall time in the localizer
  std::size_t frames = 0;  // camera frames given to it
  // Of those, while it did not know (lost or ambiguous): the time they took and the live
  // hypotheses they weighed (summed over the frames).
  double unsure_s = 0;
  std::size_t unsure_frames = 0, unsure_hypotheses = 0;
  // Of those, the frames that found 50 to 200 live hypotheses (the target's "100"), and every
  // frame given to the localizer (tracking too): time and count.
  double many_s = 0;
  std::size_t many_frames = 0, many_hypotheses = 0;
  std::string last_why;  // the localizer's last word when it never fixed
  // The map oracle on the drive from the kidnap (or start) on: the travel after which no other
  // place fits the lamps seen (sim::MapOracle); empty when a twin fits the whole drive.
  std::optional<double> oracle_m;
  std::size_t oracle_twins = 0;  // places the first view fit, the truth excluded
};

struct BatteryOptions {
  double speed = 0.5;                       // m/s
  double ceiling_rate = 10, omni_rate = 1;  // Hz
  double ceiling_delay_s = 1.0, omni_delay_s = 0.5;
  double odometry_scale_sigma = 0.005;  // per wheel, drawn per episode
  double odometry_noise = 0.002;        // m per sqrt(m) of wheel travel
  double tracking_before_m = 4.0;       // kidnap: driven while tracking before it
  // After the kidnap / start, at most. A kidnap is over when the robot knows: two of the 1,000-
  // node kidnaps were still ambiguous at 300 m, the map oracle undecided too (the drive's views
  // fit a twin's all along), and fixed right at 328 and 373 m.
  double max_travel_m = 600.0;
  double after_fix_s = 10.0;  // driven on after the first fix, to catch a wrong one
  sim::LampSensorOptions sensors;
  // The building as the cameras see it, when it is not the map the localizer is given: a map
  // made with errors (lamps a few centimetres off, as `map build` or a tape leave them), or lamps
  // added or taken away since. Same nodes as the map (the robot is driven on the map); null: the
  // map itself. The map oracle judges on the map, as the localizer does.
  const graph::TopologicalMap* world = nullptr;
  // Judge each drive with the map oracle, its view the lamps the omni camera places within the
  // oracle's tolerance (LampSensors::omni_resolving_radius_m).
  bool oracle = true;
  // Called after each frame the localizer took (for looking into a failing episode).
  std::function<void(double t, const Pose2& truth, const fusion::Localizer&)> trace;
};

class Battery {
 public:
  Battery(const graph::TopologicalMap& map, const RobotDescription& robot,
          const BatteryOptions& options = {}, const fusion::LocalizerOptions& localizer = {});
  ~Battery();

  // Tracking from a random corridor place, then lifted and put down at another random corridor
  // place, any heading.
  EpisodeResult kidnap(std::uint64_t seed);
  // Not told where it starts: a random corridor place, any heading.
  EpisodeResult unknown_start(std::uint64_t seed);
  // From a given pose, not told where it is, driving the given waypoints (then at random).
  EpisodeResult unknown_start_at(const Pose2& start, std::uint64_t seed);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

std::string summarize(const std::vector<EpisodeResult>& results);

// A generated building with the asymmetries real ones have: rooms off some corridors, a missing
// corridor, an east wing with another lamp spacing (2.7 m against 2.25 m), a lobby.
sim::BuildingOptions asymmetric_building(int nodes);

// A map that is not the building (BatteryOptions::world): each lamp of the GeoJSON map `geojson`
// moved by `sigma_m` (normal, in x and y; its height by half that), and `unmapped_percent` of
// the lamps left out, drawn from `rng`. Returns the map's GeoJSON.
std::string imperfect_map(const std::string& geojson, double sigma_m, double unmapped_percent,
                          std::mt19937_64& rng);

// The figures of a battery: counts, and latency percentiles over the episodes that fixed.
struct BatteryFigures {
  int episodes = 0, detected = 0, fixed = 0, correct = 0, wrong_fixes = 0;
  double latency_s_median = 0, latency_s_p95 = 0, latency_m_median = 0, latency_m_p95 = 0;
  std::size_t max_hypotheses = 0;
  double unsure_us_per_frame = 0, unsure_mean_hypotheses = 0;
  // Frames that found 50 to 200 live hypotheses, and every frame (amortized).
  double many_us_per_frame = 0, many_mean_hypotheses = 0;
  std::size_t many_frames = 0;
  double amortized_us_per_frame = 0;
  // Against the map oracle: episodes it decided within the drive, episodes fixed right within
  // its distance plus 10 m (the target; an oracle undecided when the drive ended decides after
  // the fix), and the travel past it (fixed episodes it decided; negative: fixed before it).
  int oracle_decided = 0, within_oracle_10m = 0;
  double past_oracle_m_median = 0, past_oracle_m_p95 = 0;
};
BatteryFigures figures(const std::vector<EpisodeResult>& results);

}  // namespace lampnav::test
