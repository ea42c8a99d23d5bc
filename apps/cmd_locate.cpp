// lampnav locate --map M --robot R.json --image IMG [--camera omni_camera]
//                [--method paper|default] [--json]
// lampnav locate --map M [--robot R.json] --log LOG.mcap [--at SECONDS] [bag topic options] ...
// Global localization from one omnidirectional image: ranked pose hypotheses with their merit,
// the lamps each matched and the node each lies in. The image is a file, or an omni frame of a
// mission log or ROS 2 bag (the first captured at or after --at; the robot defaults to the
// log's robot.json, a bag's camera mount to its transforms).

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/vision/omni_detector.hpp"

namespace lampnav::apps {

namespace {

constexpr double kDeg = M_PI / 180.0;

struct LocateArgs {
  std::string map, robot, image, log, camera = "omni_camera", method = "default";
  std::optional<double> at;  // s, capture time of the log's frame
  io::BagTopics topics;
  bool json = false;
};

// The image to locate from, and what to call it in messages and output.
struct Picture {
  Image8 image;
  std::string name;
  std::optional<double> captured_s;  // a log's frame
};

// The first omni frame of the log captured at or after `at` (the first, without it).
Picture frame_of_log(const io::MissionLog& log, const LocateArgs& a) {
  if (log.omni_images.empty())
    throw InputError({a.log, "", ""}, log.ros2_bag ? "no omni camera images in the bag (see "
                                                     "--omni-topic)"
                                                   : "no omni camera images (/omni_camera/image)");
  const auto& frames = log.omni_images;
  auto it = frames.begin();
  if (a.at) {
    it = std::find_if(frames.begin(), frames.end(),
                      [&](const auto& f) { return to_seconds(f.value.stamp) >= *a.at - 1e-9; });
    if (it == frames.end()) {
      std::ostringstream why;
      why << "no omni frame captured at or after " << *a.at << " s (the log's are from "
          << to_seconds(frames.front().value.stamp) << " to "
          << to_seconds(frames.back().value.stamp) << " s)";
      throw InputError({a.log, "--at", ""}, why.str());
    }
  }
  std::ostringstream name;
  name << a.log << ", omni frame captured at " << std::fixed << std::setprecision(3)
       << to_seconds(it->value.stamp) << " s";
  return {io::decode_image(it->value.data, name.str()), name.str(), to_seconds(it->value.stamp)};
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path, "", ""}, "cannot open the image");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

nlohmann::ordered_json to_json(const fusion::PoseHypothesis& h,
                               const vision::OmniDetection& detection) {
  nlohmann::ordered_json j;
  j["x"] = h.pose.x();
  j["y"] = h.pose.y();
  j["yaw_deg"] = h.pose.yaw() / kDeg;
  j["node"] = h.node ? nlohmann::ordered_json(h.node->name) : nlohmann::ordered_json(nullptr);
  j["weight"] = h.weight;
  j["merit_px"] = std::isfinite(h.merit) ? nlohmann::ordered_json(h.merit) : nullptr;
  j["score"] = h.score;
  j["sigma_xy_m"] = std::sqrt(0.5 * (h.covariance(0, 0) + h.covariance(1, 1)));
  j["sigma_yaw_deg"] = std::sqrt(h.covariance(2, 2)) / kDeg;
  j["expected"] = h.expected;
  j["missing"] = h.missing;
  j["unexplained"] = h.unexplained;
  j["matches"] = nlohmann::ordered_json::array();
  for (const auto& m : h.matches) {
    nlohmann::ordered_json mj;
    mj["lamp"] = m.lamp->id.value;
    const auto& b = detection.blobs[m.blob];
    mj["blob"] = m.blob;
    mj["u"] = b.centroid_px.x();
    mj["v"] = b.centroid_px.y();
    mj["error_deg"] = m.error_deg;
    j["matches"].push_back(mj);
  }
  return j;
}

int run_locate(const LocateArgs& a) {
  if (a.image.empty() == a.log.empty())
    throw InputError({"", "--image", ""}, "give one of --image IMG and --log LOG.mcap");
  if (!a.image.empty() && a.robot.empty())
    throw InputError({"", "--robot", ""}, "--robot is needed with --image");
  if (!a.image.empty() && a.at)
    throw InputError({"", "--at", ""}, "--at picks a frame of --log, not of --image");
  const graph::LoadedMap loaded = graph::read_map(a.map);
  RobotDescription robot;
  Picture picture;
  if (!a.log.empty()) {
    const io::MissionLog log = read_log_for_cameras(a.log, a.robot, a.topics, robot);
    picture = frame_of_log(log, a);
  } else {
    robot = read_robot_description(a.robot);
    picture = {io::decode_image(read_bytes(a.image), a.image), a.image, std::nullopt};
  }
  const std::string robot_source = a.robot.empty() ? a.log + " (robot.json attachment)" : a.robot;
  const CameraDescription* camera = robot.find_camera(a.camera);
  if (!camera)
    throw InputError({robot_source, "cameras", "name"}, "no camera named '" + a.camera + "'");
  if (!is_fisheye(camera->model))
    throw InputError({robot_source, "cameras[" + a.camera + "]", "model"},
                     "global localization needs an omnidirectional (pajdla_bakstein or "
                     "kannala_brandt) camera");
  const auto method = fusion::parse_global_method(a.method);
  if (!method)
    throw InputError({"", "--method", ""}, "'" + a.method + "' is not a method (paper, default)");
  vision::OmniLampDetector detector(*camera);
  vision::OmniDetection detection;
  try {
    detection = detector.detect(vision::ImageView::of(picture.image));
  } catch (const InputError& e) {
    throw InputError({picture.name, "", ""},
                     e.message() + " (camera '" + a.camera + "' in " + robot_source + ")");
  }
  const fusion::GlobalLocalizer global(loaded.map, *camera);
  const auto t0 = std::chrono::steady_clock::now();
  const fusion::GlobalLocalization r = global.locate(detection, *method);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  if (a.json) {
    nlohmann::ordered_json j;
    j["image"] = picture.name;
    if (picture.captured_s) j["captured_s"] = *picture.captured_s;
    j["method"] = fusion::to_string(r.method);
    j["lamps_seen"] = detection.blobs.size();
    j["plausible"] = r.plausible;
    j["ambiguous"] = r.ambiguous;
    j["why"] = r.why.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(r.why);
    j["merit_evaluations"] = r.merit_evaluations;
    j["time_ms"] = ms;
    j["hypotheses"] = nlohmann::ordered_json::array();
    for (const auto& h : r.hypotheses) j["hypotheses"].push_back(to_json(h, detection));
    std::cout << j.dump(2) << "\n";
  } else if (r.found()) {
    std::cout << r.plausible << " plausible of " << r.hypotheses.size()
              << " ranked hypotheses from " << detection.blobs.size() << " lamps seen (method "
              << fusion::to_string(r.method) << ", " << r.merit_evaluations << " poses scored, "
              << std::fixed << std::setprecision(1) << ms << " ms)\n";
    if (r.ambiguous) std::cout << "ambiguous: " << r.why << "\n";
    std::cout << "rank        x        y  yaw_deg  node       weight  merit_px  matched  missing\n";
    int rank = 0;
    for (const auto& h : r.hypotheses) {
      std::cout << std::setw(4) << ++rank << std::fixed << std::setprecision(3) << std::setw(9)
                << h.pose.x() << std::setw(9) << h.pose.y() << std::setprecision(2) << std::setw(9)
                << h.pose.yaw() / kDeg << "  " << std::left << std::setw(10)
                << (h.node ? h.node->name : "-") << std::right << std::setprecision(3)
                << std::setw(7) << h.weight << std::setprecision(2) << std::setw(10) << h.merit
                << std::setw(9) << h.matches.size() << std::setw(6) << h.missing << "/"
                << h.expected << "\n";
    }
    for (std::size_t k = 0; k < r.hypotheses.size(); ++k) {
      std::cout << "lamps of " << k + 1 << ":";
      for (const auto& m : r.hypotheses[k].matches) std::cout << " " << m.lamp->id.value;
      std::cout << "\n";
    }
  }
  if (!r.found()) throw JobFailed("no hypothesis: " + r.why);
  return 0;
}

}  // namespace

void add_locate_command(CLI::App& app, Job& run) {
  auto args = std::make_shared<LocateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "locate", "Global localization from one omnidirectional image: ranked pose hypotheses");
  cmd->add_option("--map", args->map, "Map file (.geojson)")->required();
  cmd->add_option("--robot", args->robot,
                  "Robot description (robot.json); with --log, default: the log's attachment");
  cmd->add_option("--image", args->image, "Omnidirectional image (PNG or JPEG)");
  cmd->add_option("--log", args->log,
                  "Mission log or ROS 2 bag (MCAP): locate from one of its omni frames");
  cmd->add_option("--at", args->at,
                  "With --log: the first omni frame captured at or after this time (s)");
  add_bag_topic_options(*cmd, args->topics);
  cmd->add_option("--camera", args->camera, "Camera of robot.json that took it")
      ->capture_default_str();
  cmd->add_option("--method", args->method,
                  "paper (Alg. 3 of paper 1, as published) or default (lamp pairs)")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "Print the result as JSON");
  cmd->callback([args, &run] { run = [args] { return run_locate(*args); }; });
}

}  // namespace lampnav::apps
