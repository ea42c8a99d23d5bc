// lampnav map check | map render (map build: cmd_map_build.cpp)

#include <CLI/CLI.hpp>
#include <iostream>
#include <map>
#include <memory>

#include "commands.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/map_checks.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "map_drawing.hpp"

namespace lampnav::apps {

namespace {

struct CheckArgs {
  std::string map;
  std::string robot;
  std::string camera = "ceiling_camera";
  double speed = 0.5;
  double fps = 1.0;
};

int run_check(const CheckArgs& a) {
  graph::LoadedMap loaded = graph::read_map(a.map);
  std::vector<graph::MapWarning> warnings = loaded.warnings;
  std::string coverage_line = "camera coverage: not checked (give --robot to check it)";
  if (!a.robot.empty()) {
    const RobotDescription robot = read_robot_description(a.robot);
    const CameraDescription* cam = robot.find_camera(a.camera);
    if (!cam) throw InputError({a.robot, "", "cameras"}, "no camera named '" + a.camera + "'");
    graph::CeilingCoverage cov;
    cov.view_length = [cam](double h) { return vision::ceiling_view_length(*cam, h); };
    cov.speed = a.speed;
    cov.frame_rate = a.fps;
    const auto coverage = graph::check_camera_coverage(loaded.map, cov, a.map);
    warnings.insert(warnings.end(), coverage.begin(), coverage.end());
    char buf[160];
    std::snprintf(buf, sizeof buf, "camera coverage (%s at %.2f m/s, %.2f frames/s): %s",
                  a.camera.c_str(), a.speed, a.fps,
                  coverage.empty() ? "every lamp seen" : "see warnings");
    coverage_line = buf;
  }
  for (const auto& w : warnings) diagnostic("warning", w.text());

  const auto& m = loaded.map;
  std::map<graph::Place, int> by_place;
  std::size_t doors = 0;
  for (const auto& n : m.nodes()) {
    ++by_place[n.place];
    doors += n.doors.size();
  }
  std::cout << "map " << (m.name().empty() ? "(unnamed)" : m.name()) << " (" << a.map
            << "): valid\n";
  std::cout << "nodes: " << m.node_count() << " (";
  bool first = true;
  for (const auto& [place, count] : by_place) {
    std::cout << (first ? "" : ", ") << graph::to_string(place) << " " << count;
    first = false;
  }
  std::cout << ")\n";
  std::cout << "edges: " << m.edge_count() << "\n";
  std::cout << "lamps: " << m.lamp_count() << "\n";
  std::cout << "doors along corridors: " << doors << "\n";
  std::cout << coverage_line << "\n";
  std::cout << "warnings: " << warnings.size() << "\n";
  return 0;
}

}  // namespace

void add_map_commands(CLI::App& app, Job& run) {
  CLI::App* map =
      app.add_subcommand("map", "Validate, draw or build a map (shared/spec/map-format.md)");
  map->require_subcommand(1);
  add_map_build_command(*map, run);
  add_map_survey_command(*map, run);

  auto check_args = std::make_shared<CheckArgs>();
  CLI::App* check = map->add_subcommand("check", "Validate a map; print a summary or the errors");
  check->add_option("MAP", check_args->map, "Map file (.geojson)")->required();
  check->add_option("--robot", check_args->robot,
                    "robot.json: also check that its ceiling camera sees every lamp");
  check->add_option("--camera", check_args->camera, "Camera of --robot to check")
      ->capture_default_str();
  check->add_option("--speed", check_args->speed, "Speed to check the camera coverage for (m/s)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  check->add_option("--fps", check_args->fps, "Frames the camera delivers per second")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  check->callback([check_args, &run] { run = [check_args] { return run_check(*check_args); }; });

  auto render_args = std::make_shared<std::pair<std::string, std::string>>();
  auto drawing = std::make_shared<DrawingOptions>();
  CLI::App* render = map->add_subcommand("render", "Draw regions, graph, lamps, doors and names");
  render->add_option("MAP", render_args->first, "Map file (.geojson)")->required();
  render->add_option("-o,--output", render_args->second, "Picture to write (.png or .svg)")
      ->required();
  render->add_option("--size", drawing->max_size_px, "Longer side of the picture (px)")
      ->capture_default_str()
      ->check(CLI::Range(200, 20000));
  render->add_flag("--lamp-ids", drawing->lamp_ids, "Label every lamp with its id");
  render->callback([render_args, drawing, &run] {
    run = [render_args, drawing] {
      const graph::LoadedMap loaded = graph::read_map(render_args->first);
      for (const auto& w : loaded.warnings) diagnostic("warning", w.text());
      draw_map(loaded.map, render_args->second, *drawing);
      std::cout << render_args->second << "\n";
      return 0;
    };
  });
}

}  // namespace lampnav::apps
