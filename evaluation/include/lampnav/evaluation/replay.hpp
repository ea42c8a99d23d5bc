#pragma once
// Replay of a mission log (shared/spec/mission-log.md) through the runtime loop: the inputs in
// the order they became available, the localizer's estimate at odometry rate, the lamps seen and
// labelled, and the metrics against the truth when the log has it. /truth/pose only scores,
// never estimates. Outputs as the spec lists: replay.mcap (the inputs plus /lampnav/pose,
// /lampnav/estimate, /lampnav/lamps and /lampnav/scene), estimate.tum, truth.tum, metrics.json.

#include <Eigen/Core>
#include <deque>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/robot.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/navigation/runtime.hpp"

namespace lampnav::evaluation {

// A recorded mission behind the robot interface: its wheel readings and camera frames in the
// order they became available (a frame after the wheel reading of the same instant).
class LogRobot : public Robot {
 public:
  LogRobot(const io::MissionLog& log, bool use_ceiling, bool use_omni);
  void set_wheel_speeds(double, double) override {}
  std::optional<RobotInput> next() override;
  // Frames whose image did not decode, one line each.
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  using Item = io::LogInput;
  struct Decoded {
    std::optional<Image8> image;
    std::string problem;
  };
  Decoded decode(const Item& it) const;

  const io::MissionLog* log_;
  std::vector<Item> items_;
  std::size_t next_ = 0;
  // Frames decode on other threads a few items ahead of the loop (PNG decoding is most of a
  // replay's time); the results are the same whatever the timing.
  std::deque<std::pair<std::size_t, std::future<Decoded>>> ahead_;
  std::size_t launched_ = 0;  // items_ before this have had their decoding started (or are wheels)
  std::vector<std::string> problems_;
};

struct ReplayOptions {
  navigation::RuntimeOptions runtime;
  bool use_ceiling = true, use_omni = true;
  std::optional<Pose2> initial_pose;  // without it the omni camera finds the robot first
};

struct EstimateSample {
  Stamp stamp;
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  fusion::LocalizerMode mode = fusion::LocalizerMode::tracking;
  std::string node;
};

// The places the robot may be, whenever they change (lost and ambiguous); an empty list once one
// pose is known.
struct HypothesesSample {
  Stamp stamp;
  fusion::LocalizerMode mode = fusion::LocalizerMode::lost;
  std::vector<fusion::WeightedPose> hypotheses;
};

struct LampFrame {
  Stamp arrival;
  io::LampObservations observations;
};

struct ErrorStats {
  std::size_t n = 0;
  double mean = 0, rms = 0, max = 0;
};

struct Metrics {
  std::size_t frames = 0, ceiling_frames = 0, omni_frames = 0;
  double duration_s = 0;
  bool has_truth = false;
  ErrorStats position_error_m, yaw_error_deg;  // tracking, outside the lost intervals
  double lost_s = 0;       // time lost (nothing published as certain, places not all known)
  double ambiguous_s = 0;  // time with no single answer, every place it may be known
  // With truth: stretches where a pose was published as certain (tracking or relocalized) more
  // than 0.5 m off, outside the time from a kidnap to its detection.
  int wrong_fixes = 0;
  int kidnaps = 0, recoveries = 0;
  ErrorStats relocalization_latency_s;  // from each kidnap to the fix that follows it
  std::size_t lamps_seen = 0, lamps_labelled = 0;
  navigation::InputFaultCounts
      input_faults[3];               // by navigation::InputStream: gaps, duplicates, out of order
  std::uint64_t frames_too_old = 0;  // captured before the filter's history
  double runtime_s = 0, realtime_factor = 0;
};

struct ReplayResult {
  std::vector<EstimateSample> estimates;             // one per wheel reading, once a pose is known
  std::vector<HypothesesSample> hypotheses;          // whenever they change
  std::vector<std::pair<Stamp, Pose2>> odometry;     // wheels alone, from the first pose
  std::vector<LampFrame> lamp_frames;                // ceiling frames with their detections
  std::vector<fusion::LocalizerEvent> events;        // the localizer's mode changes
  std::vector<navigation::InputFault> input_faults;  // as they came
  navigation::RunOutcome outcome;
  Metrics metrics;
  std::vector<std::string> notes;  // what was used, what was missing, what was cut short
};

// Runs the stack over the log. Throws JobFailed when there is nothing to localize with (no wheel
// readings; neither a start pose nor an omni camera).
ReplayResult replay(const io::MissionLog& log, const graph::TopologicalMap& map,
                    const RobotDescription& robot, const ReplayOptions& options = {});

// The metrics of a run against its log (spec/cli.md), from what the run published: frames and
// lamps counted, time lost and time ambiguous (each estimate's mode held until the next one),
// kidnaps (the log's events) and the first `relocalized` after each, errors of the poses published
// as tracking outside [kidnap, its fix], and wrong fixes: stretches of poses published as certain
// more than 0.5 m from the truth, except from a kidnap to the localizer's first mode change after
// it (10 s at most). Runtime, real-time factor and frames too old are left to the caller.
Metrics score(const ReplayResult& run, const io::MissionLog& log);

// The map for viewers: regions, corridor axes, lamps and names.
io::SceneUpdate map_scene(const graph::TopologicalMap& map, Stamp stamp);

// Writes DIR/replay.mcap, DIR/estimate.tum, DIR/truth.tum (when the log has truth) and
// DIR/metrics.json. Throws InputError naming a file it cannot write.
void write_replay(const ReplayResult& result, const io::MissionLog& log,
                  const graph::TopologicalMap& map, const std::string& map_geojson,
                  const std::string& robot_json, const std::string& dir);

std::string metrics_json(const Metrics& metrics);
// TUM trajectory lines: "t x y z qx qy qz qw", t in seconds.
std::string tum(const std::vector<std::pair<Stamp, Pose2>>& poses);

}  // namespace lampnav::evaluation
