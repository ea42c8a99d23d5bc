#include "lampnav/navigation/runtime.hpp"

#include <cmath>

#include "lampnav/core/error.hpp"

namespace lampnav::navigation {

void RuntimeOptions::validate() const {
  localizer.validate();
  executor.validate();
  inputs.validate();
  if (!(max_duration_s > 0))
    throw InputError({"", "runtime options", "max_duration_s"}, "must be positive");
  if (!(start_sigma_m > 0) || !(start_sigma_deg > 0))
    throw InputError({"", "runtime options", "start_sigma"}, "must be positive");
}

Runtime::Runtime(const graph::TopologicalMap& map, const RobotDescription& robot,
                 const RuntimeOptions& options)
    : map_(&map),
      o_(options),
      localizer_(map, robot, options.localizer),
      executor_(map, robot.semi_axis, options.executor),
      semi_axis_(robot.semi_axis),
      inputs_(options.inputs) {
  o_.validate();
}

RunOutcome Runtime::run(Robot& robot, const std::optional<Pose2>& start,
                        const std::vector<graph::RouteCommand>& commands, RuntimeObserver* observer,
                        bool keep_running) {
  RunOutcome out;
  RuntimeObserver none;
  RuntimeObserver& obs = observer ? *observer : none;
  std::vector<graph::RouteCommand> mission = commands;
  bool driving = !mission.empty();  // a mission to start or in progress
  auto stop = [&] { robot.set_wheel_speeds(0, 0); };
  while (auto input = robot.next()) {
    if (const auto fault = inputs_.check(*input)) obs.on_input_fault(*fault);
    if (const auto* w = std::get_if<WheelInput>(&*input)) {
      if (!out.first) {
        out.first = w->stamp;
        if (start) {
          const double sp = o_.start_sigma_m, sy = o_.start_sigma_deg * M_PI / 180;
          localizer_.initialize(w->stamp, *start,
                                Eigen::Vector3d(sp * sp, sp * sp, sy * sy).asDiagonal());
        }
      }
      out.last = w->stamp;
      ++out.wheel_readings;
      localizer_.wheels(w->stamp, w->left, w->right);
      const fusion::LocalizerEstimate e = localizer_.estimate();
      if (!localizer_.initialized() && e.hypotheses.empty()) continue;
      obs.on_estimate(e);
      if (driving) {
        if (executor_.status() == ExecutorStatus::idle && e.known())
          executor_.start(e.stamp, e.pose, mission);
        const WheelSpeeds s = executor_.step(e);
        robot.set_wheel_speeds(s.left, s.right);
        const ExecutorStatus st = executor_.status();
        if (st == ExecutorStatus::arrived || st == ExecutorStatus::failed) {
          if (st == ExecutorStatus::failed) out.reason = executor_.reason();
          if (!keep_running) break;
          driving = false;
          stop();
        }
      }
      if (to_seconds(*out.last - *out.first) > o_.max_duration_s) {
        out.time_limit = true;
        break;
      }
      continue;
    }
    if (const auto* c = std::get_if<CommandInput>(&*input)) {
      try {
        std::vector<graph::RouteCommand> parsed = graph::parse_route_commands(c->text);
        graph::check_commands(*map_, parsed);
        if (parsed.empty()) throw InputError({"", "command", ""}, "no command in the text");
        mission = std::move(parsed);
        executor_ = Executor(*map_, semi_axis_, o_.executor);  // the new mission replaces the old
        driving = true;
        out.reason.clear();
        ++out.commands;
        obs.on_command(*c, "");
      } catch (const InputError& e) {
        ++out.refused_commands;
        obs.on_command(*c, e.what());
      }
      continue;
    }
    if (const auto* p = std::get_if<PoseInput>(&*input)) {
      // The operator's word, as a fix: the cameras confirm it (relocalized, then tracking) or
      // find the robot elsewhere as after a carry. Before any wheel reading, it starts the filter.
      if (localizer_.global_fix({p->arrival, p->pose, p->covariance, "an operator's estimate"})) {
        ++out.pose_estimates;
        obs.on_pose_estimate(*p, "");
      } else {
        obs.on_pose_estimate(*p,
                             "the filter refused it (a time outside the filter's history, or a "
                             "pose or covariance it cannot use)");
      }
      continue;
    }
    const auto& f = std::get<FrameInput>(*input);
    const vision::ImageView view = vision::ImageView::of(f.image);
    try {
      if (f.camera == CameraRole::ceiling) {
        if (!localizer_.has_ceiling_camera()) continue;
        ++out.ceiling_frames;
        obs.on_ceiling(f, localizer_.ceiling_frame(f.capture, view));
      } else {
        if (!localizer_.has_omni_camera()) continue;
        ++out.omni_frames;
        obs.on_omni(f, localizer_.omni_frame(f.capture, view));
        localizer_.audit();  // once the frame's pose is out
      }
    } catch (const InputError& e) {
      ++out.refused_frames;
      obs.on_refused(f, e.what());
    }
  }
  stop();
  for (int s = 0; s < 3; ++s) out.faults[s] = inputs_.counts(static_cast<InputStream>(s));
  out.status = executor_.status();
  if (!mission.empty() && out.status != ExecutorStatus::arrived && out.reason.empty())
    out.reason = out.time_limit ? "the time limit came first" : "the robot stopped giving input";
  return out;
}

}  // namespace lampnav::navigation
