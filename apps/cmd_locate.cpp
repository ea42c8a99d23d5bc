// lampnav locate --map M --robot R.json --image IMG [--camera omni_camera]
//                [--method paper|default] [--json]
// Global localization from one omnidirectional image: ranked pose hypotheses with their merit,
// the lamps each matched and the node each lies in.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
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
  std::string map, robot, image, camera = "omni_camera", method = "default";
  bool json = false;
};

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
  const graph::LoadedMap loaded = graph::read_map(a.map);
  const RobotDescription robot = read_robot_description(a.robot);
  const CameraDescription* camera = robot.find_camera(a.camera);
  if (!camera) throw InputError({a.robot, "cameras", "name"}, "no camera named '" + a.camera + "'");
  if (!is_fisheye(camera->model))
    throw InputError({a.robot, "cameras[" + a.camera + "]", "model"},
                     "global localization needs an omnidirectional (pajdla_bakstein or "
                     "kannala_brandt) camera");
  const auto method = fusion::parse_global_method(a.method);
  if (!method)
    throw InputError({"", "--method", ""}, "'" + a.method + "' is not a method (paper, default)");
  const Image8 image = io::decode_image(read_bytes(a.image), a.image);
  vision::OmniLampDetector detector(*camera);
  vision::OmniDetection detection;
  try {
    detection = detector.detect(vision::ImageView::of(image));
  } catch (const InputError& e) {
    throw InputError({a.image, "", ""},
                     e.message() + " (camera '" + a.camera + "' in " + a.robot + ")");
  }
  const fusion::GlobalLocalizer global(loaded.map, *camera);
  const auto t0 = std::chrono::steady_clock::now();
  const fusion::GlobalLocalization r = global.locate(detection, *method);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  if (a.json) {
    nlohmann::ordered_json j;
    j["image"] = a.image;
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
  cmd->add_option("--robot", args->robot, "Robot description (robot.json)")->required();
  cmd->add_option("--image", args->image, "Omnidirectional image (PNG or JPEG)")->required();
  cmd->add_option("--camera", args->camera, "Camera of robot.json that took it")
      ->capture_default_str();
  cmd->add_option("--method", args->method,
                  "paper (Alg. 3 of paper 1, as published) or default (lamp pairs)")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "Print the result as JSON");
  cmd->callback([args, &run] { run = [args] { return run_locate(*args); }; });
}

}  // namespace lampnav::apps
