// lampnav map build LOG.mcap [--robot R.json] -o M.geojson [--names NAMES.json]

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>

#include "commands.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/internal/json_util.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/mapping/map_builder.hpp"

namespace lampnav::apps {

namespace {

struct BuildArgs {
  std::string log, robot, out, names;
  double corridor_width = 2.0;
  bool quiet = false;
};

// NAMES.json: [{"name": "Main corridor", "at": [x, y]}, ...], a point inside each place in the
// built map's frame (the drive's start: build once, render, then name).
std::vector<mapping::PlaceName> read_names(const std::string& path) {
  const json::Json doc = json::parse(json::read_file(path), path);
  const json::Cursor root(doc, {path, "", ""});
  std::vector<mapping::PlaceName> names;
  const std::size_t n = root.array_size();
  for (std::size_t i = 0; i < n; ++i) {
    const json::Cursor e = root[i];
    e.only_keys({"name", "at"});
    const json::Cursor at = e.at("at");
    at.array_size(2, 2);
    names.push_back({{at[0].number(), at[1].number()}, e.at("name").string()});
  }
  return names;
}

int run_build(const BuildArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<mapping::PlaceName> names =
      a.names.empty() ? std::vector<mapping::PlaceName>{} : read_names(a.names);
  const io::MissionLog log = io::read_mission_log(a.log);
  RobotDescription robot;
  if (!a.robot.empty()) {
    robot = read_robot_description(a.robot);
  } else if (log.robot_json) {
    robot = parse_robot_description(*log.robot_json, a.log + " (robot.json attachment)");
  } else {
    throw InputError({a.log, "attachments", "robot.json"},
                     "the log has no robot.json: give --robot");
  }
  mapping::MapBuildOptions o;
  o.topology.corridor_width_m = a.corridor_width;
  ProgressBar bar(a.quiet);
  const mapping::MapBuildResult r = mapping::build_map(
      log, a.log, robot, o, names, [&bar](double f) { bar.update(f, "mapping"); });
  bar.done();
  graph::TopologicalMap map = r.map;
  map.set_name(a.out);
  graph::save_map(map, a.out);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const auto& note : r.notes) diagnostic("note", note);
  std::map<graph::Place, int> by_place;
  for (const auto& n : map.nodes()) ++by_place[n.place];
  std::cout << "map        " << a.out << "\n";
  std::cout << "drive      " << r.travel_m << " m, " << r.frames << " ceiling frames, "
            << r.lamps_seen_whole << " lamps seen whole\n";
  std::cout << "lamps      " << map.lamp_count() << " mapped (" << r.mapped.revisits
            << " sightings after a loop; " << r.mapped.merged << " merged, " << r.mapped.dropped
            << " seen too few times); reprojection RMS " << r.mapped.final_rms_px << " px\n";
  std::cout << "places     " << map.node_count() << " (";
  bool first = true;
  for (const auto& [place, count] : by_place) {
    std::cout << (first ? "" : ", ") << graph::to_string(place) << " " << count;
    first = false;
  }
  std::cout << "), " << map.edge_count() << " edges\n";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f s (%.1f s in the solver, %d solves)", took,
                r.mapped.solve_seconds, r.mapped.solves);
  std::cout << "time       " << buf << "\n";
  return 0;
}

}  // namespace

void add_map_build_command(CLI::App& map, Job& run) {
  auto args = std::make_shared<BuildArgs>();
  CLI::App* build = map.add_subcommand(
      "build", "Build a map (lamps, places, connections) from a drive; never reads the log's map");
  build->add_option("LOG", args->log, "Mission log of the drive (.mcap)")->required();
  build->add_option("--robot", args->robot, "robot.json (default: the log's attachment)");
  build->add_option("-o,--output", args->out, "Map to write (.geojson)")->required();
  build->add_option("--names", args->names,
                    "NAMES.json: [{\"name\": ..., \"at\": [x, y]}], a point inside each place");
  build->add_option("--corridor-width", args->corridor_width, "Width of the places' regions (m)")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 20.0));
  build->add_flag("--quiet", args->quiet, "No progress bar");
  build->callback([args, &run] { run = [args] { return run_build(*args); }; });
}

}  // namespace lampnav::apps
