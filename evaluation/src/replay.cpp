#include "lampnav/evaluation/replay.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/fusion/odometry_calibration.hpp"
#include "lampnav/internal/json_util.hpp"

namespace lampnav::evaluation {

// ---------------------------------------------------------------------------------------------
// The recorded robot.

LogRobot::LogRobot(const io::MissionLog& log, bool use_ceiling, bool use_omni)
    : log_(&log), items_(io::inputs_in_arrival_order(log, use_ceiling, use_omni)) {}

LogRobot::Decoded LogRobot::decode(const Item& it) const {
  const bool ceiling = it.kind == io::LogInput::Kind::ceiling;
  const auto& f = (ceiling ? log_->ceiling_images : log_->omni_images)[it.index];
  try {
    return {io::decode_image(f.value.data, f.value.frame_id), {}};
  } catch (const InputError& e) {
    return {std::nullopt, std::string(ceiling ? "ceiling" : "omni") + " frame captured at " +
                              std::to_string(to_seconds(f.value.stamp)) + " s: " + e.message()};
  }
}

std::optional<RobotInput> LogRobot::next() {
  constexpr std::size_t kAhead = 4;
  while (next_ < items_.size()) {
    // Keep up to kAhead frames decoding ahead of the loop.
    while (ahead_.size() < kAhead && launched_ < items_.size()) {
      const std::size_t k = launched_++;
      if (items_[k].kind == io::LogInput::Kind::wheels) continue;
      ahead_.emplace_back(k,
                          std::async(std::launch::async, [this, k] { return decode(items_[k]); }));
    }
    const std::size_t k = next_++;
    const Item& it = items_[k];
    if (it.kind == io::LogInput::Kind::wheels) {
      const auto& w = log_->wheels[it.index];
      return WheelInput{w.value.stamp, w.value.left, w.value.right};
    }
    Decoded d = ahead_.front().second.get();  // frames are launched in item order
    ahead_.pop_front();
    if (!d.image) {
      problems_.push_back(d.problem);
      continue;
    }
    const bool ceiling = it.kind == io::LogInput::Kind::ceiling;
    const auto& f = (ceiling ? log_->ceiling_images : log_->omni_images)[it.index];
    return FrameInput{ceiling ? CameraRole::ceiling : CameraRole::omni, f.value.stamp, f.log_time,
                      std::move(*d.image)};
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// Replay.

namespace {

// Collects what the loop saw.
struct Recorder : navigation::RuntimeObserver {
  ReplayResult* r;
  void on_estimate(const fusion::LocalizerEstimate& e) override {
    r->estimates.push_back({e.stamp, e.pose, e.covariance, e.mode, e.node ? e.node->name : ""});
    // The hypotheses change with frames, not with odometry: kept when their number, the mode or
    // the leader's weight changes.
    const HypothesesSample* last = r->hypotheses.empty() ? nullptr : &r->hypotheses.back();
    const bool changed =
        !last || last->mode != e.mode || last->hypotheses.size() != e.hypotheses.size() ||
        (!e.hypotheses.empty() && last->hypotheses.front().weight != e.hypotheses.front().weight);
    if (changed) r->hypotheses.push_back({e.stamp, e.mode, e.hypotheses});
  }
  void on_input_fault(const navigation::InputFault& f) override { r->input_faults.push_back(f); }
  void on_ceiling(const FrameInput& f, const fusion::CeilingObservation& ob) override {
    LampFrame lf;
    lf.arrival = f.arrival;
    lf.observations.stamp = f.capture;
    lf.observations.camera = "ceiling_camera";
    for (const auto& l : ob.lamps) {
      io::LampObservation o;
      o.u = l.detection.centre_px.x();
      o.v = l.detection.centre_px.y();
      o.orientation = l.detection.orientation;
      o.area = l.detection.area;
      o.track = l.track_id;
      if (l.lamp) o.label = l.lamp->id.value;
      lf.observations.lamps.push_back(o);
    }
    r->lamp_frames.push_back(std::move(lf));
  }
};

// Why a replay never published a pose, in words: what the localizer last said.
std::string never_localized(const ReplayResult& r, const io::MissionLog& log) {
  std::string s = "the robot was never localized";
  if (!r.events.empty())
    s += ": " + r.events.back().reason;
  else if (r.outcome.omni_frames == 0 && !log.omni_images.empty())
    s += ": no omni frame could be used";
  else if (r.outcome.omni_frames == 0)
    s += ": no omni frame to find it with";
  return s;
}

std::string one_decimal(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

// What came in wrong, in a few lines: each stream's faults counted, the first few in full, and
// what the localizer did not use because of them.
void note_input_faults(ReplayResult& r, const fusion::LocalizerCounts& c) {
  constexpr std::size_t kShown = 3;
  for (int s = 0; s < 3; ++s) {
    const navigation::InputFaultCounts& n = r.outcome.faults[s];
    if (n.total() == 0) continue;
    std::string line = std::string(to_string(static_cast<navigation::InputStream>(s))) + ": " +
                       std::to_string(n.gaps) + " gaps (longest " + one_decimal(n.longest_gap_s) +
                       " s), " + std::to_string(n.duplicates) + " duplicates, " +
                       std::to_string(n.out_of_order) + " out of order";
    std::size_t shown = 0;
    for (const auto& f : r.input_faults)
      if (static_cast<int>(f.stream) == s && shown++ < kShown) line += "; " + f.text();
    r.notes.push_back(line);
  }
  if (c.frames_too_old > 0)
    r.notes.push_back(std::to_string(c.frames_too_old) +
                      " frames captured before the filter's history (too late to apply)");
}

// What the lamps taught the localizer of the wheels: odometry whose wheel radius is off shows here,
// for the user to mend at its source (the localizer corrects it as it drives either way).
void note_wheels(ReplayResult& r, const fusion::OdometryCalibration& c) {
  constexpr int kEnough = 50;  // pairs of positions
  if (c.travel_pairs() < kEnough) return;
  const double travel = 1 / (1 + c.travel_scale()) - 1;  // how much longer the wheels read
  std::string line = "the wheels, learnt from the lamps: travel read " +
                     one_decimal(std::fabs(travel) * 100) + " % " +
                     (travel >= 0 ? "long" : "short") + ", heading drift " +
                     one_decimal(c.yaw_drift_per_m() * 180 / M_PI) + " deg a metre";
  if (std::fabs(travel) >= 0.01)
    line += " (the wheel radius giving the travel is off by about that)";
  r.notes.push_back(line);
}

// The floor's swing the ceiling frames showed, when it is past what the models assume: a rough
// floor or a loose mount, for the user to know (the localizer weighs its lamps for it while it
// knows where the robot is, either way). While it looks for the robot it keeps the models'
// swing, so that a carry does not hide in the floor's (docs/hypotheses.md, "The lattice's wrong
// fix"): on such a floor that calls moves that were not, each costing the search what it had
// learnt, and the user is told how many, the one cost of the floor they can remove.
void note_swing(ReplayResult& r, const fusion::CeilingContinuity* c,
                const fusion::CeilingContinuityOptions& o, const fusion::LocalizerCounts& n) {
  if (!c || !c->learnt_tilt_sigma() || c->tilt_sigma() <= o.tilt_sigma) return;
  std::string line = "the floor swings the ceiling camera by " +
                     one_decimal(*c->learnt_tilt_sigma() * 180 / M_PI) +
                     " deg from frame to frame (the localizer's models assume " +
                     one_decimal(o.tilt_sigma * 180 / M_PI) +
                     "): the lamps were weighed for it while the robot's place was known; " +
                     std::to_string(c->tilt_samples()) + " lamps seen twice measured it";
  if (n.unseen_moves_while_looking > 0)
    line += ". While the robot was looked for, the ceiling camera called " +
            std::to_string(n.unseen_moves_while_looking) +
            " moves the wheels did not see, each starting the search again (judged by the "
            "models' swing, so that a carry does not hide in the floor's; some may be the "
            "floor's): a steadier floor or camera mount shortens the time lost";
  r.notes.push_back(line);
}

}  // namespace

ReplayResult replay(const io::MissionLog& log, const graph::TopologicalMap& map,
                    const RobotDescription& robot, const ReplayOptions& options) {
  if (log.wheels.empty())
    throw JobFailed("the log has no wheel readings (/wheels): nothing to replay");
  const bool omni =
      options.use_omni && !log.omni_images.empty() && robot.find_camera("omni_camera");
  const bool ceiling =
      options.use_ceiling && !log.ceiling_images.empty() && robot.find_camera("ceiling_camera");
  if (!options.initial_pose && !omni)
    throw JobFailed(
        "no starting pose and no omnidirectional frames to find the robot with: give "
        "--initial-pose X,Y,YAW");
  ReplayResult r;
  r.notes.push_back("inputs: " + std::to_string(log.wheels.size()) + " wheel readings" +
                    (ceiling ? ", " + std::to_string(log.ceiling_images.size()) + " ceiling frames"
                             : std::string(", no ceiling camera")) +
                    (omni ? ", " + std::to_string(log.omni_images.size()) + " omni frames"
                          : std::string(", no omni camera")));
  r.notes.push_back(options.initial_pose
                        ? "started from the given pose"
                        : "not told where the robot starts: localized globally from the omni "
                          "camera first");
  if (log.truth.empty()) r.notes.push_back("the log has no truth (/truth/pose): errors not scored");
  if (log.report.truncated)
    r.notes.push_back("the log is truncated (" + log.report.truncation +
                      "): replayed what it holds");
  if (log.skipped_messages > 0)
    r.notes.push_back(std::to_string(log.skipped_messages) + " damaged messages skipped");

  LogRobot robot_in(log, ceiling, omni);
  navigation::Runtime rt(map, robot, options.runtime);
  Recorder rec;
  rec.r = &r;
  const auto t0 = std::chrono::steady_clock::now();
  r.outcome = rt.run(robot_in, options.initial_pose, {}, &rec);
  const double runtime_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const auto& p : robot_in.problems()) r.notes.push_back("skipped " + p);
  note_input_faults(r, rt.localizer().counts());
  note_wheels(r, rt.localizer().calibration());
  note_swing(r, rt.localizer().continuity(), options.runtime.localizer.continuity,
             rt.localizer().counts());
  const auto& ev = rt.localizer().events();
  for (const auto& e : ev)
    if (e.cause != fusion::ModeCause::initialized) r.events.push_back(e);
  // Wheels alone, from the first pose the stack had.
  const auto known =
      std::find_if(r.estimates.begin(), r.estimates.end(),
                   [](const EstimateSample& e) { return fusion::is_certain(e.mode); });
  if (known != r.estimates.end()) {
    const Stamp from = known->stamp;
    fusion::StateVector x = known->pose.vector();
    std::optional<std::pair<double, double>> last;
    for (const auto& w : log.wheels) {
      if (w.value.stamp < from) continue;
      if (last)
        x = fusion::predict_motion(x, w.value.left - last->first, w.value.right - last->second,
                                   robot.semi_axis);
      last = {w.value.left, w.value.right};
      r.odometry.emplace_back(w.value.stamp, Pose2(x.x(), x.y(), wrap_angle(x.z())));
    }
  } else {
    r.notes.push_back(never_localized(r, log));
  }
  r.metrics = score(r, log);
  r.metrics.frames_too_old = rt.localizer().counts().frames_too_old;
  r.metrics.runtime_s = runtime_s;
  r.metrics.realtime_factor = runtime_s > 0 ? r.metrics.duration_s / runtime_s : 0.0;
  return r;
}

// ---------------------------------------------------------------------------------------------
// Outputs.

io::SceneUpdate map_scene(const graph::TopologicalMap& map, Stamp stamp) {
  io::SceneUpdate u;
  u.stamp = stamp;
  io::SceneEntity regions{"regions", {}, {}, {}}, graph_e{"graph", {}, {}, {}},
      lamps{"lamps", {}, {}, {}};
  for (const auto& n : map.nodes()) {
    if (n.region.size() >= 3) {
      io::SceneLine l;
      for (const auto& v : n.region.vertices()) l.points.emplace_back(v.x(), v.y(), 0.0);
      l.points.emplace_back(n.region.vertices().front().x(), n.region.vertices().front().y(), 0.0);
      l.color = {0.55, 0.6, 0.7, 1.0};
      l.thickness = 0.04;
      regions.lines.push_back(std::move(l));
    }
    if (n.axis) {
      io::SceneLine l;
      l.points = {{n.axis->first.x(), n.axis->first.y(), 0.01},
                  {n.axis->second.x(), n.axis->second.y(), 0.01}};
      l.color = {0.3, 0.5, 0.9, 1.0};
      l.thickness = 0.03;
      graph_e.lines.push_back(std::move(l));
    }
    graph_e.texts.push_back({{n.point.x(), n.point.y(), 0.2}, n.name, {0.1, 0.1, 0.1, 1.0}, 0.4});
    for (const auto& lamp : n.lamps)
      lamps.cubes.push_back({lamp.xyz,
                             {std::max(0.05, lamp.length), std::max(0.05, lamp.width), 0.05},
                             lamp.yaw,
                             {1.0, 0.8, 0.1, 1.0}});
  }
  for (const auto& e : map.edges()) {
    io::SceneLine l;
    for (const auto& part : e.geometry)
      for (const auto& p : part) l.points.emplace_back(p.x(), p.y(), 0.02);
    if (l.points.size() < 2) continue;
    l.color = {0.4, 0.4, 0.4, 0.8};
    l.thickness = 0.02;
    graph_e.lines.push_back(std::move(l));
  }
  u.entities = {std::move(regions), std::move(graph_e), std::move(lamps)};
  return u;
}

std::string tum(const std::vector<std::pair<Stamp, Pose2>>& poses) {
  std::string out;
  char line[160];
  for (const auto& [t, p] : poses) {
    std::snprintf(line, sizeof line, "%.9f %.6f %.6f 0 0 0 %.9f %.9f\n", to_seconds(t), p.x(),
                  p.y(), std::sin(p.yaw() / 2), std::cos(p.yaw() / 2));
    out += line;
  }
  return out;
}

void write_replay(const ReplayResult& r, const io::MissionLog& log,
                  const graph::TopologicalMap& map, const std::string& map_geojson,
                  const std::string& robot_json, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError({dir, "", ""}, "cannot create the output directory: " + ec.message());
  {
    io::MissionLogWriter w(dir + "/replay.mcap");
    w.attach_robot(robot_json);
    w.attach_map(map_geojson);
    for (const auto& m : log.commands) w.write(m.log_time, m.value);
    for (const auto& m : log.events) w.write(m.log_time, m.value);
    w.write(log.wheels.empty() ? Stamp{} : log.wheels.front().log_time,
            map_scene(map, log.wheels.empty() ? Stamp{} : log.wheels.front().value.stamp));
    for (const auto& m : log.wheels) w.write(m.log_time, m.value);
    for (const auto& m : log.truth) w.write(m.log_time, m.value);
    for (const auto& m : log.ceiling_images) w.write_image(m.log_time, m.value);
    for (const auto& m : log.omni_images) w.write_image(m.log_time, m.value);
    for (const auto& e : r.estimates) {
      io::PoseEstimate p;
      p.stamp = e.stamp;
      p.pose = e.pose;
      for (int k = 0; k < 9; ++k) p.covariance[k] = e.covariance(k / 3, k % 3);
      p.node = e.node;
      p.mode = e.mode;
      w.write(e.stamp, p);
    }
    for (const auto& f : r.lamp_frames) w.write(f.arrival, f.observations);
    // The replay's notes, for people, at the start of the log.
    const Stamp first = log.wheels.empty() ? Stamp{} : log.wheels.front().value.stamp;
    for (const auto& n : r.notes) {
      const bool warn = n.rfind("skipped", 0) == 0 || n.find("truncated") != std::string::npos ||
                        n.find("never localized") != std::string::npos;
      w.write(first, io::LogMessage{
                         first, warn ? io::LogMessage::Level::warning : io::LogMessage::Level::info,
                         n, "lampnav replay"});
    }
    for (const auto& h : r.hypotheses) {
      io::Hypotheses msg;
      msg.stamp = h.stamp;
      msg.mode = h.mode;
      for (const auto& p : h.hypotheses)
        msg.hypotheses.push_back({p.pose, p.weight, p.node ? p.node->name : ""});
      w.write(h.stamp, msg);
    }
    w.close();
  }
  std::vector<std::pair<Stamp, Pose2>> est;  // the poses published as tracking only (cli.md)
  for (const auto& e : r.estimates)
    if (e.mode == fusion::LocalizerMode::tracking) est.emplace_back(e.stamp, e.pose);
  json::write_file(dir + "/estimate.tum", tum(est));
  if (!log.truth.empty()) {
    const io::TruthTrack truth(log.truth);
    std::vector<std::pair<Stamp, Pose2>> t;
    for (const auto& s : truth.samples()) t.emplace_back(s.value.stamp, s.value.pose);
    json::write_file(dir + "/truth.tum", tum(t));
  }
  json::write_file(dir + "/metrics.json", metrics_json(r.metrics));
}

}  // namespace lampnav::evaluation
