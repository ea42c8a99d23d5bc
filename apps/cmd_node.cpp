// lampnav node: the live node on a ROS 2 system (cli.md, docs/ros2.md). The runtime loop of
// replay and run, fed by DDS instead of a log or the simulator.

#include <malloc.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include "commands.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/internal/json_util.hpp"
#include "lampnav/navigation/runtime.hpp"
#include "lampnav/ros/ros_robot.hpp"

namespace lampnav::apps {

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

struct NodeArgs {
  std::string robot, map, initial_pose, stats;
  int domain = -1;
  double tf_wait_s = 1;
  bool no_ceiling = false, no_omni = false, quiet = false;
  ros::RosRobotOptions robot_options;
};

// Publishes what the loop sees and times each frame from its arrival to the pose it gives.
struct Publisher : navigation::RuntimeObserver {
  ros::RosRobot* robot;
  const navigation::Runtime* runtime;
  bool quiet = false;
  std::vector<double> latency_us[2];     // ceiling, omni: arrival to pose out
  std::vector<double> processing_us[2];  // ceiling, omni: decoded to pose out
  // Frames after which no pose went out, only the hypotheses (the robot not yet found): arrival
  // to hypotheses out. Their first omni images search the whole map.
  std::vector<double> searching_us[2];
  // Frames that came before the loop started (while the node waited for the cameras' mounts):
  // their time in the queue is the wait's, not the node's, and they are counted apart.
  ros::Clock::time_point started;
  std::size_t before_start[2] = {0, 0};
  std::string last_mission;

  void on_estimate(const fusion::LocalizerEstimate& e) override {
    robot->publish(e);
    mission_news();
  }
  // Publishes the localizer's estimate as it stands, once it has a pose or places; returns it
  // (nullopt: nothing to publish yet).
  std::optional<fusion::LocalizerEstimate> publish_current() {
    const fusion::Localizer& l = runtime->localizer();
    fusion::LocalizerEstimate e = l.estimate();
    if (!l.initialized() && e.hypotheses.empty()) return std::nullopt;
    robot->publish(e);
    return e;
  }
  void after_frame(CameraRole camera) {
    const std::optional<fusion::LocalizerEstimate> published = publish_current();
    if (!published) return;
    const fusion::LocalizerEstimate& e = *published;
    const auto now = ros::Clock::now();
    const bool omni = camera == CameraRole::omni;
    if (robot->last_arrival() < started) {
      ++before_start[omni];
      return;
    }
    const double arrival =
        std::chrono::duration<double, std::micro>(now - robot->last_arrival()).count();
    if (!e.known()) {
      searching_us[omni].push_back(arrival);
      return;
    }
    latency_us[omni].push_back(arrival);
    processing_us[omni].push_back(
        std::chrono::duration<double, std::micro>(now - robot->last_ready()).count());
  }
  void on_ceiling(const FrameInput&, const fusion::CeilingObservation&) override {
    after_frame(CameraRole::ceiling);
  }
  void on_omni(const FrameInput&, const vision::OmniDetection&) override {
    after_frame(CameraRole::omni);
  }
  void on_refused(const FrameInput& f, const std::string& why) override {
    diagnostic("warning", std::string(f.camera == CameraRole::ceiling ? "ceiling" : "omni") +
                              " frame refused: " + why);
  }
  void on_command(const CommandInput& c, const std::string& why) override {
    const std::string text = why.empty() ? "command taken: " + c.text : "command refused: " + why;
    robot->publish_event(text);
    if (!quiet) diagnostic("note", text);
    last_mission.clear();
  }
  void on_pose_estimate(const PoseInput& p, const std::string& why) override {
    char at[96];
    std::snprintf(at, sizeof at, "(%.2f, %.2f) facing %.0f deg", p.pose.x(), p.pose.y(),
                  p.pose.yaw() * 180 / M_PI);
    const std::string text = why.empty()
                                 ? std::string("pose estimate taken: the robot at ") + at
                                 : std::string("pose estimate at ") + at + " refused: " + why;
    robot->publish_event(text);
    publish_current();  // the pose goes out now, as a fix (relocalized) for the cameras to confirm
    if (!quiet) diagnostic("note", text);
  }
  // The mission's end, once.
  void mission_news() {
    const navigation::Executor& x = runtime->executor();
    std::string news;
    if (x.status() == navigation::ExecutorStatus::arrived) news = "arrived";
    if (x.status() == navigation::ExecutorStatus::failed) news = "failed: " + x.reason();
    if (news.empty() || news == last_mission) return;
    last_mission = news;
    robot->publish_event("mission " + news);
    if (!quiet) diagnostic("note", "mission " + news);
  }
};

// The q-quantile of `sorted` (ascending), nearest rank; 0 when empty.
double percentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0;
  return sorted[std::min(sorted.size() - 1,
                         static_cast<std::size_t>(q * (sorted.size() - 1) + 0.5))];
}

nlohmann::json counts_json(const ros::InputCounts& c) {
  return {
      {"received", c.received}, {"used", c.used}, {"refused", c.refused}, {"dropped", c.dropped}};
}

// The cameras the node reads: role and robot.json name.
std::vector<std::pair<CameraRole, std::string>> cameras_in_use(const ros::NodeTopics& t) {
  std::vector<std::pair<CameraRole, std::string>> used;
  if (!t.ceiling_image.empty()) used.emplace_back(CameraRole::ceiling, "ceiling_camera");
  if (!t.omni_image.empty()) used.emplace_back(CameraRole::omni, "omni_camera");
  return used;
}

// The cameras' mounts from /tf_static (robot_state_publisher's, from the robot's URDF), as a
// bag's transforms give them to replay: the node waits until every camera in use has sent an
// image and /tf_static joins the base to each image's frame, or until --tf-wait seconds after the
// first message of any kind came. A camera not joined keeps robot.json's mount (a note says so).
std::vector<std::string> mounts_from_static_tf(ros::RosRobot& ros_robot, const NodeArgs& a,
                                               RobotDescription& robot) {
  const ros::NodeTopics& t = a.robot_options.topics;
  const auto used = cameras_in_use(t);
  std::optional<ros::Clock::time_point> first_message;
  std::vector<io::FrameTransform> transforms;
  for (;;) {
    if (g_stop) return {};
    transforms = ros_robot.static_transforms();
    bool joined = true;
    for (const auto& [role, name] : used) {
      const std::string frame = ros_robot.camera_frame(role);
      joined &= !frame.empty() && io::mount_from_tf(transforms, frame).has_value();
    }
    if (joined) break;
    const ros::NodeCounts c = ros_robot.counts();
    if (!first_message && c.ceiling.received + c.omni.received + c.odometry.received +
                                  c.commands.received + c.pose_estimates.received >
                              0)
      first_message = ros::Clock::now();
    if (first_message &&
        ros::Clock::now() - *first_message > std::chrono::duration<double>(a.tf_wait_s))
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  char waited[32];
  std::snprintf(waited, sizeof waited, "%g s", a.tf_wait_s);
  auto note = [&](const std::string& text) {
    if (!a.quiet) diagnostic("note", text);
  };
  if (transforms.empty()) {
    note("nothing came on " + t.tf_static + " within " + waited +
         " of the first message: the cameras' mounts from robot.json");
    return {};
  }
  for (const auto& [role, name] : used)
    if (ros_robot.camera_frame(role).empty())
      note(name + " sent no image within " + waited +
           " of the first message: its mount from robot.json");
  return mounts_from_tf(
      transforms,
      [&](const CameraDescription& c) {
        for (const auto& [role, name] : used)
          if (name == c.name) return ros_robot.camera_frame(role);
        return std::string();
      },
      "node", t.tf_static, robot, a.quiet);
}

// What the node has told of its cameras' descriptions while running (each thing once).
struct CameraChecks {
  std::vector<std::string> late_mounts;      // cameras warned of
  std::optional<io::CameraInfo> checked[2];  // ceiling, omni: the CameraInfo checked
};

bool same_calibration(const io::CameraInfo& a, const io::CameraInfo& b) {
  return a.width == b.width && a.height == b.height && a.distortion_model == b.distortion_model &&
         a.d == b.d && a.k == b.k;
}

// Every second while running. Once running, the mounts are not changed: a camera whose mount on
// /tf_static came or changed after the start (robot_state_publisher started late, a URDF edited)
// is told once, with what to do. Each camera's driver calibration (CameraInfo) is checked
// against robot.json when it first comes and when it changes. Damaged /tf_static and camera_info
// messages are reported here too.
void check_cameras(ros::RosRobot& ros_robot, const NodeArgs& a, const RobotDescription& robot,
                   CameraChecks& done) {
  const std::vector<io::FrameTransform> transforms = ros_robot.static_transforms();
  const ros::NodeTopics& t = a.robot_options.topics;
  for (const auto& [role, name] : cameras_in_use(t)) {
    const CameraDescription* c = robot.find_camera(name);
    if (!c) continue;
    std::optional<io::CameraInfo>& checked = done.checked[role == CameraRole::omni];
    if (const auto info = ros_robot.camera_info(role);
        info && !(checked && same_calibration(*checked, *info))) {
      checked = info;
      const std::string w = camera_info_disagreement(
          *c, *info,
          ros::camera_info_topic(role == CameraRole::ceiling ? t.ceiling_image : t.omni_image));
      if (!w.empty()) diagnostic("warning", w);
    }
    const std::string frame = ros_robot.camera_frame(role);
    if (t.tf_static.empty() || frame.empty() ||
        std::count(done.late_mounts.begin(), done.late_mounts.end(), name))
      continue;
    const auto m = io::mount_from_tf(transforms, frame);
    // Compared as rotations: roll, pitch and yaw wrap.
    if (!m || ((m->xyz - c->mount.xyz).norm() < 1e-3 &&
               (Mount{m->xyz, m->rpy}.rotation() - c->mount.rotation()).norm() < 1e-3))
      continue;
    done.late_mounts.push_back(name);
    diagnostic("warning", name + "'s mount on " + t.tf_static +
                              " came or changed after the node started (" + m->base + " -> " +
                              frame + "): the node goes on with the mount it started with; " +
                              "restart it to take the new one");
  }
}

// The node's health on /diagnostics, once a second, as ROS's diagnostic tools show it:
// - localization: OK while one pose is known (tracking, relocalized); WARN while it is one of
//   several places (ambiguous) or looked for (lost), saying which;
// - each input (the cameras in use, the odometry): OK with its rate; WARN when messages of it
//   were dropped (the node slower than the camera) or refused since the last report; ERROR when
//   none has come for 2 s or more, or none yet.
class HealthReport {
 public:
  explicit HealthReport(const ros::NodeTopics& topics) : topics_(topics) {}

  std::vector<io::ros2::DiagnosticStatus> report(const ros::NodeCounts& now,
                                                 ros::Clock::time_point at) {
    using Status = io::ros2::DiagnosticStatus;
    std::vector<Status> out;
    Status where;
    where.name = "lampnav: localization";
    where.values = {{"mode", now.mode.empty() ? "none yet" : now.mode},
                    {"hypotheses", std::to_string(now.hypotheses)},
                    {"poses_published", std::to_string(now.poses_published)}};
    if (now.mode == "tracking" || now.mode == "relocalized") {
      where.message = now.mode;
    } else {
      where.level = Status::warn;
      where.message =
          now.mode == "ambiguous" ? "ambiguous: one of " + std::to_string(now.hypotheses) +
                                        " places (the pose is not published; see the hypotheses)"
          : now.mode == "lost" ? "lost: looking for the robot (the pose is not published)"
                               : "no estimate yet";
    }
    out.push_back(where);
    const double dt = seen_ ? std::chrono::duration<double>(at - last_at_).count() : 0;
    auto input = [&](int k, const char* name, const std::string& topic, const ros::InputCounts& c,
                     const ros::InputCounts& before) {
      if (topic.empty()) return;
      Status s;
      s.name = std::string("lampnav: ") + name;
      s.hardware_id = topic;
      if (c.received > before.received) last_message_[k] = at;  // (the first report: since start)
      const double rate = dt > 0 ? static_cast<double>(c.received - before.received) / dt : 0;
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.1f", rate);
      s.values = {{"received", std::to_string(c.received)},
                  {"used", std::to_string(c.used)},
                  {"dropped", std::to_string(c.dropped)},
                  {"refused", std::to_string(c.refused)},
                  {"rate_hz", buf}};
      const std::uint64_t dropped = c.dropped - before.dropped,
                          refused = c.refused - before.refused;
      const double silent =
          last_message_[k] ? std::chrono::duration<double>(at - *last_message_[k]).count() : 0;
      if (c.received == 0) {
        s.level = Status::error;
        s.message = "nothing yet on " + topic;
      } else if (silent >= 2) {
        std::snprintf(buf, sizeof buf, "%.1f", silent);
        s.level = Status::error;
        s.message = std::string("nothing for ") + buf + " s on " + topic;
      } else if (dropped + refused > 0) {
        s.level = Status::warn;
        s.message = std::to_string(dropped) + " dropped (the node is slower than the input), " +
                    std::to_string(refused) +
                    " refused (the node's log says why) since the last report";
      } else {
        std::snprintf(buf, sizeof buf, "%.1f Hz", rate);
        s.message = buf;
      }
      out.push_back(s);
    };
    input(0, "ceiling camera", topics_.ceiling_image, now.ceiling, last_.ceiling);
    input(1, "omni camera", topics_.omni_image, now.omni, last_.omni);
    input(2, "odometry", topics_.joint_states.empty() ? topics_.odometry : topics_.joint_states,
          now.odometry, last_.odometry);
    last_ = now;
    last_at_ = at;
    seen_ = true;
    return out;
  }

 private:
  ros::NodeTopics topics_;
  ros::NodeCounts last_;
  ros::Clock::time_point last_at_{};
  std::optional<ros::Clock::time_point> last_message_[3];
  bool seen_ = false;
};

int run_node(NodeArgs& a) {
  // Images of up to a megabyte come and go at 30 Hz. By default glibc maps each such block from
  // the kernel and gives it back when freed, so every frame's pixels are faulted in again page by
  // page (on this machine's virtual CPU that cost more than decoding the JPEG). The node keeps
  // them: blocks below 32 MB come from the heap, and the heap is not trimmed below 256 MB free.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  RobotDescription robot = read_robot_description(a.robot);
  const graph::LoadedMap loaded = graph::parse_map(json::read_file(a.map), a.map);
  std::optional<Pose2> start;
  if (!a.initial_pose.empty()) start = parse_pose_option(a.initial_pose, "--initial-pose");
  ros::RosRobotOptions& ro = a.robot_options;
  ro.semi_axis = robot.semi_axis;
  if (a.no_ceiling || !robot.find_camera("ceiling_camera")) ro.topics.ceiling_image.clear();
  if (a.no_omni || !robot.find_camera("omni_camera")) ro.topics.omni_image.clear();
  for (auto [name, size] :
       {std::pair{"ceiling_camera", &ro.ceiling_size}, std::pair{"omni_camera", &ro.omni_size}})
    if (const CameraDescription* c = robot.find_camera(name)) *size = {c->width, c->height};
  if (!start && ro.topics.omni_image.empty() && ro.topics.pose_estimate.empty())
    throw InputError({"", "option", "--initial-pose"},
                     "no starting pose, no omni camera to find the robot with, and no pose "
                     "estimate topic to be told on");
  // The images that come while the node waits for the cameras' mounts are all kept.
  ro.hold_images = !ro.topics.tf_static.empty();
  ro.validate();
  const int domain = a.domain >= 0 ? a.domain : ros::domain_from_environment();
  ros::Participant participant(domain);
  ros::RosRobot ros_robot(participant, ro);
  ros_robot.on_problem = [](const std::string& p) { diagnostic("error", p); };

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::atomic<bool> done{false}, looping{false};
  std::thread watcher([&] {
    ros::NodeCounts reported;
    bool counting = false;  // images dropped while the node waited for the mounts are not news
    CameraChecks checks;
    HealthReport health(ro.topics);
    for (int tick = 1; !done; ++tick) {
      if (g_stop) ros_robot.stop();
      if (!counting && looping) {
        counting = true;
        reported = ros_robot.counts();
        tick = 1;
      }
      // Every second; `robot` is the node's own from the start on.
      if (counting && tick % 20 == 0) {
        check_cameras(ros_robot, a, robot, checks);
        ros_robot.publish_diagnostics(health.report(ros_robot.counts(), ros::Clock::now()));
      }
      if (counting && !a.quiet && tick % 100 == 0) {  // every 5 s: images dropped since then
        const ros::NodeCounts c = ros_robot.counts();
        const std::uint64_t ceiling = c.ceiling.dropped - reported.ceiling.dropped,
                            omni = c.omni.dropped - reported.omni.dropped;
        if (ceiling + omni > 0)
          diagnostic("warning", std::to_string(ceiling) + " ceiling and " + std::to_string(omni) +
                                    " omni images dropped in the last 5 s: the node processes "
                                    "them more slowly than the cameras send them, and keeps "
                                    "each camera's newest " +
                                    std::to_string(ro.max_images_waiting));
        reported = c;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  if (!a.quiet)
    diagnostic("note",
               "joined ROS 2 domain " + std::to_string(domain) + "; inputs " +
                   (ro.topics.ceiling_image.empty() ? "" : ro.topics.ceiling_image + ", ") +
                   (ro.topics.omni_image.empty() ? "" : ro.topics.omni_image + ", ") +
                   (ro.topics.joint_states.empty() ? ro.topics.odometry : ro.topics.joint_states) +
                   ", " + ro.topics.command +
                   (ro.topics.pose_estimate.empty() ? "" : ", " + ro.topics.pose_estimate));
  if (!a.quiet && !start && ro.topics.omni_image.empty())
    diagnostic("note", "no starting pose and no omni camera: waiting for a pose estimate on " +
                           ro.topics.pose_estimate);
  std::vector<std::string> tf_mounts;
  std::optional<navigation::Runtime> made;
  try {
    if (!ro.topics.tf_static.empty()) tf_mounts = mounts_from_static_tf(ros_robot, a, robot);
    navigation::RuntimeOptions opts;
    opts.max_duration_s = 1e9;  // a live node runs until stopped
    made.emplace(loaded.map, robot, opts);
  } catch (...) {
    done = true;
    watcher.join();
    throw;
  }
  navigation::Runtime& runtime = *made;
  ros_robot.release_images();
  Publisher pub;
  pub.robot = &ros_robot;
  pub.runtime = &runtime;
  pub.quiet = a.quiet;
  navigation::RunOutcome out;
  pub.started = ros::Clock::now();
  looping = true;
  try {
    out = runtime.run(ros_robot, start, {}, &pub, true);
  } catch (...) {
    done = true;
    watcher.join();
    throw;
  }
  done = true;
  watcher.join();

  const ros::NodeCounts c = ros_robot.counts();
  auto latency = [](std::vector<double> v) {  // us in, ms out
    std::sort(v.begin(), v.end());
    return nlohmann::json{{"n", v.size()},
                          {"p50", percentile(v, 0.5) / 1000},
                          {"p99", percentile(v, 0.99) / 1000},
                          {"max", percentile(v, 1.0) / 1000}};
  };
  const nlohmann::json ceiling_ms = latency(pub.latency_us[0]),
                       omni_ms = latency(pub.latency_us[1]),
                       omni_searching_ms = latency(pub.searching_us[1]);
  std::cout << "lampnav node: " << out.wheel_readings << " wheel readings, " << out.ceiling_frames
            << " ceiling and " << out.omni_frames << " omni frames, " << c.poses_published
            << " poses published; image in to pose out: ceiling p50 " << ceiling_ms["p50"]
            << " ms, p99 " << ceiling_ms["p99"] << " ms; omni p50 " << omni_ms["p50"] << " ms, p99 "
            << omni_ms["p99"] << " ms";
  if (c.ceiling.dropped + c.omni.dropped > 0)
    std::cout << "; images dropped, the node behind its cameras: " << c.ceiling.dropped
              << " ceiling, " << c.omni.dropped << " omni";
  if (!pub.searching_us[1].empty())
    std::cout << "; omni image in to hypotheses out while searching (" << omni_searching_ms["n"]
              << " frames): max " << omni_searching_ms["max"] << " ms";
  std::cout << "\n";
  if (!a.stats.empty()) {
    nlohmann::json j = {
        {"domain", domain},
        {"ceiling", counts_json(c.ceiling)},
        {"omni", counts_json(c.omni)},
        {"odometry", counts_json(c.odometry)},
        {"commands", counts_json(c.commands)},
        {"pose_estimates", counts_json(c.pose_estimates)},
        {"static_transforms", counts_json(c.static_transforms)},
        {"camera_info", counts_json(c.camera_info)},
        {"mounts_from_tf", tf_mounts},
        {"images_before_start", {{"ceiling", pub.before_start[0]}, {"omni", pub.before_start[1]}}},
        {"wheel_readings", out.wheel_readings},
        {"ceiling_frames", out.ceiling_frames},
        {"omni_frames", out.omni_frames},
        {"refused_frames", out.refused_frames},
        {"poses_published", c.poses_published},
        {"image_to_pose_ms", {{"ceiling", ceiling_ms}, {"omni", omni_ms}}},
        {"decoded_to_pose_ms",
         {{"ceiling", latency(pub.processing_us[0])}, {"omni", latency(pub.processing_us[1])}}},
        {"image_to_hypotheses_ms",
         {{"ceiling", latency(pub.searching_us[0])}, {"omni", omni_searching_ms}}}};
    json::write_file(a.stats, j.dump(2) + "\n");
  }
  return 0;
}

}  // namespace

void add_node_command(CLI::App& app, Job& run) {
  auto a = std::make_shared<NodeArgs>();
  CLI::App* c = app.add_subcommand(
      "node", "The live node: joins a ROS 2 system over DDS (no ROS installation needed)");
  c->add_option("--robot", a->robot, "robot.json")->required();
  c->add_option("--map", a->map, "the building's map (GeoJSON)")->required();
  c->add_option("--domain", a->domain, "ROS 2 domain id (default: ROS_DOMAIN_ID, else 0)")
      ->check(CLI::Range(0, 232));
  c->add_option("--initial-pose", a->initial_pose,
                "X,Y,YAW where the robot starts (m, m, rad); without it the omni camera finds it");
  ros::NodeTopics& t = a->robot_options.topics;
  c->add_option("--ceiling-topic", t.ceiling_image,
                "the ceiling camera's images (CompressedImage when the name ends in /compressed, "
                "else Image)")
      ->capture_default_str();
  c->add_option("--omni-topic", t.omni_image, "the omni camera's images")->capture_default_str();
  c->add_option("--odometry-topic", t.odometry, "nav_msgs/msg/Odometry")->capture_default_str();
  c->add_option("--joint-states-topic", t.joint_states,
                "sensor_msgs/msg/JointState with the two wheel joints, instead of odometry");
  c->add_option("--left-joint", t.left_joint, "the left wheel's joint (default: named left)");
  c->add_option("--right-joint", t.right_joint, "the right wheel's joint (default: named right)");
  c->add_option("--wheel-radius", t.wheel_radius, "with joint states: the wheels' radius (m)")
      ->check(CLI::PositiveNumber);
  c->add_option("--pose-estimate-topic", t.pose_estimate,
                "geometry_msgs/msg/PoseWithCovarianceStamped in the map frame: an operator's pose "
                "estimate, taken as a fix (\"\": none)")
      ->capture_default_str();
  c->add_option("--tf-static-topic", t.tf_static,
                "tf2_msgs/msg/TFMessage: the cameras' mounts where they join base_footprint (or "
                "base_link) to the images' frames; robot.json's elsewhere (\"\": robot.json's)")
      ->capture_default_str();
  c->add_option("--tf-wait", a->tf_wait_s,
                "at start, wait this long after the first message for the mounts on the "
                "tf_static topic (s)")
      ->check(CLI::Range(0.0, 60.0))
      ->capture_default_str();
  c->add_option("--command-topic", t.command, "std_msgs/msg/String route commands")
      ->capture_default_str();
  c->add_option("--cmd-vel-topic", t.cmd_vel, "geometry_msgs/msg/Twist out")->capture_default_str();
  c->add_option("--diagnostics-topic", t.diagnostics,
                "diagnostic_msgs/msg/DiagnosticArray out, every second: localization and inputs "
                "(\"\": none)")
      ->capture_default_str();
  c->add_option("--namespace", t.ns, "the node's outputs: pose, mode, hypotheses, events")
      ->capture_default_str();
  c->add_flag("--no-ceiling", a->no_ceiling, "do not use the ceiling camera");
  c->add_flag("--no-omni", a->no_omni, "do not use the omni camera");
  c->add_option("--idle-exit", a->robot_options.idle_exit_s,
                "end after this many seconds with no input, once input came (s)")
      ->check(CLI::NonNegativeNumber);
  c->add_option("--images-waiting", a->robot_options.max_images_waiting,
                "each camera's images kept waiting while the node is behind; beyond, its oldest "
                "waiting image is dropped")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  c->add_option("--stats", a->stats, "write counts and latencies here (JSON) on exit");
  c->add_flag("--quiet", a->quiet, "no notes on stderr");
  c->callback([a, &run] { run = [a] { return run_node(*a); }; });
}

}  // namespace lampnav::apps
