// lampnav sim: record a simulated mission (truth included) as an MCAP mission log.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/internal/json_util.hpp"
#include "lampnav/sim/scenario.hpp"

namespace lampnav::apps {

namespace {

struct SimArgs {
  std::string scenario, map, robot, route, out;
  std::vector<double> kidnaps;
  std::vector<std::string> failed_lamps;
  std::uint64_t seed = 1;
  bool no_bumps = false, quiet = false;
  double bump_deg = 0.5;
  std::optional<double> ceiling_delay, omni_delay;
  std::string image_format;
  std::vector<double> wheel_scale;  // left, right
};

int run_sim(const SimArgs& a) {
  if (a.scenario.empty() == a.route.empty()) {
    throw InputError({"", "", a.scenario.empty() ? "--route" : "--scenario"},
                     "give either --scenario NAME or --route \"A -> B\" (with --map and --robot)");
  }
  std::string map_path = a.map, robot_path = a.robot;
  if (!a.scenario.empty()) {
    const bool museum = a.scenario.rfind("domus", 0) == 0;
    if (map_path.empty())
      map_path = data_path(museum ? "maps/domus_museum.geojson" : "maps/office_floor.geojson");
    if (robot_path.empty()) robot_path = data_path("maps/robots/pioneer.json");
  } else if (map_path.empty() || robot_path.empty()) {
    throw InputError({"", "", map_path.empty() ? "--map" : "--robot"},
                     "--route needs --map and --robot");
  }
  const std::string map_text = json::read_file(map_path);
  graph::LoadedMap loaded = graph::parse_map(map_text, map_path);
  const RobotDescription robot = read_robot_description(robot_path);

  sim::Scenario s;
  if (!a.scenario.empty()) {
    s = sim::make_named_scenario(a.scenario, loaded.map, map_text, robot, a.seed);
  } else {
    const auto arrow = a.route.find("->");
    if (arrow == std::string::npos)
      throw InputError({"", "", "--route"}, "expected \"FROM -> TO\", found \"" + a.route + "\"");
    auto trim = [](std::string t) {
      t.erase(0, t.find_first_not_of(" \t"));
      t.erase(t.find_last_not_of(" \t") + 1);
      return t;
    };
    s = sim::make_route_scenario(loaded.map, map_text, robot, trim(a.route.substr(0, arrow)),
                                 trim(a.route.substr(arrow + 2)), a.seed);
  }
  for (double t : a.kidnaps) s.kidnaps.push_back({t, std::nullopt});
  std::sort(s.kidnaps.begin(), s.kidnaps.end(),
            [](const auto& x, const auto& y) { return x.at_s < y.at_s; });
  for (const auto& id : a.failed_lamps) s.failed_lamps.insert(id);
  s.bump_sigma_rad = a.no_bumps ? 0.0 : a.bump_deg * M_PI / 180.0;
  if (!a.wheel_scale.empty()) {
    if (a.wheel_scale.size() != 2)
      throw InputError({"", "--wheel-scale", ""}, "expected LEFT,RIGHT (two fractions), found " +
                                                      std::to_string(a.wheel_scale.size()) +
                                                      " numbers");
    s.odometry.left_scale = a.wheel_scale[0];
    s.odometry.right_scale = a.wheel_scale[1];
  }
  if (a.ceiling_delay) s.ceiling_delay_s = *a.ceiling_delay;
  if (a.omni_delay) s.omni_delay_s = *a.omni_delay;
  if (!a.image_format.empty())
    s.images = io::parse_image_encoding(a.image_format, "--image-format");

  ProgressBar bar(a.quiet);
  const auto start = std::chrono::steady_clock::now();
  const auto stats = sim::record_mission(s, a.out, [&](double f) { bar.update(f, "recording"); });
  bar.done();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "scenario: " << s.name << " (seed " << a.seed << ")\n"
            << "log: " << a.out << " (" << std::filesystem::file_size(a.out) / 1024 << " KiB)\n"
            << "mission: " << stats.duration_s << " s, " << stats.path_length_m << " m driven, "
            << (stats.arrived ? "arrived" : "did NOT arrive") << "\n"
            << "wheel readings: " << stats.wheel_messages
            << ", ceiling frames: " << stats.ceiling_frames
            << ", omni frames: " << stats.omni_frames << ", dropped: " << stats.dropped_frames
            << "\n"
            << "kidnaps: " << stats.kidnaps << ", wheel slips: " << stats.slips << "\n"
            << "recorded in " << wall << " s (" << (wall > 0 ? stats.duration_s / wall : 0)
            << "x real time)\n";
  return stats.arrived ? 0 : 1;
}

}  // namespace

void add_sim_command(CLI::App& app, Job& run) {
  auto a = std::make_shared<SimArgs>();
  CLI::App* cmd =
      app.add_subcommand("sim", "Record a simulated mission (truth included) as an MCAP log");
  cmd->add_option("--scenario", a->scenario,
                  "Named scenario: corridor, domus-global, domus-kidnap, office-mission");
  cmd->add_option("--map", a->map, "Map (.geojson); a named scenario defaults to its bundled map");
  cmd->add_option("--robot", a->robot,
                  "robot.json; a named scenario defaults to maps/robots/pioneer.json");
  cmd->add_option("--route", a->route, "Drive the planned route \"FROM -> TO\" (node names)");
  cmd->add_option("--kidnap", a->kidnaps,
                  "Lift the robot at T seconds and put it down elsewhere (repeatable)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--fail-lamp", a->failed_lamps, "A lamp that does not light (repeatable)");
  cmd->add_option("--seed", a->seed, "Random seed: the same seed writes the same bytes")
      ->capture_default_str();
  cmd->add_option("--bumps", a->bump_deg,
                  "Floor-bump swing of the cameras, standard deviation (deg)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_flag("--no-bumps", a->no_bumps, "Turn floor bumps off");
  cmd->add_option("--wheel-scale", a->wheel_scale,
                  "LEFT,RIGHT: how much longer than the truth each wheel reads its travel "
                  "(fractions; default 0.004,-0.003)")
      ->delimiter(',')
      ->check(CLI::Range(-0.2, 0.2));
  cmd->add_option("--ceiling-delay", a->ceiling_delay,
                  "Ceiling camera capture-to-availability delay (s, default 1)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--omni-delay", a->omni_delay,
                  "Omni camera capture-to-availability delay (s, default 0.5)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--image-format", a->image_format,
                  "How the log stores frames: png, jpeg or jpeg:QUALITY (1-100); default jpeg:" +
                      std::to_string(io::ImageEncoding{}.jpeg_quality));
  cmd->add_flag("-q,--quiet", a->quiet, "No progress bar");
  cmd->add_option("-o,--output", a->out, "Mission log to write (.mcap)")->required();
  cmd->callback([a, &run] { run = [a] { return run_sim(*a); }; });
}

}  // namespace lampnav::apps
