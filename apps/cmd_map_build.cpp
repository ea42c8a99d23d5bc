// lampnav map build LOG.mcap [--robot R.json] -o M.geojson [--names NAMES.json]
//                   [--distance FROM,TO,METRES ...]
// lampnav map survey M LOG.mcap [--robot R.json] [--json] [--update OUT.geojson]

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include <iomanip>
#include <nlohmann/json.hpp>
#include "commands.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/internal/json_util.hpp"
#include "lampnav/io/mission_log.hpp"
#include "lampnav/mapping/map_builder.hpp"
#include "lampnav/mapping/survey.hpp"

namespace lampnav::apps {

namespace {

struct BuildArgs {
  std::string log, robot, out, names, initial_pose;
  std::vector<std::string> distances;
  io::BagTopics topics;
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

// --distance FROM,TO,METRES: two lamp ids of the map and their distance measured in the building.
mapping::KnownDistance parse_distance_option(const std::string& text) {
  const std::string flag = "--distance " + text;
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) parts.push_back(part);
  if (parts.size() != 3 || parts[0].empty() || parts[1].empty())
    throw InputError({"", flag, ""},
                     "expected FROM,TO,METRES: two lamp ids of the map and the distance measured "
                     "between them, e.g. C1-L2,C4-L7,24.315");
  mapping::KnownDistance d;
  d.from = parts[0];
  d.to = parts[1];
  d.given_as = flag;
  try {
    std::size_t used = 0;
    d.metres = std::stod(parts[2], &used);
    if (used != parts[2].size()) throw std::invalid_argument(parts[2]);
  } catch (const std::exception&) {
    throw InputError({"", flag, ""}, "'" + parts[2] + "' is not a number of metres");
  }
  return d;
}

int run_build(const BuildArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<mapping::PlaceName> names =
      a.names.empty() ? std::vector<mapping::PlaceName>{} : read_names(a.names);
  mapping::MapBuildOptions o;
  o.topology.corridor_width_m = a.corridor_width;
  if (!a.initial_pose.empty()) o.start = parse_pose_option(a.initial_pose, "--initial-pose");
  for (const auto& d : a.distances) o.distances.push_back(parse_distance_option(d));
  o.validate();  // before the log is read and mapped: a mistyped flag is told at once
  RobotDescription robot;
  const io::MissionLog log = read_log_for_robot(a.log, a.robot, a.topics, robot);
  const double read_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
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
            << r.lamps_seen_whole << " lamps seen whole, " << r.lamps_seen_cut
            << " cut by the border\n";
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
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "%.1f s (reading the log %.1f s, detecting %.1f s, lamp SLAM %.1f s of which "
                "%.1f s in the solver, %d solves)",
                took, read_s, r.detect_seconds, r.slam_seconds, r.mapped.solve_seconds,
                r.mapped.solves);
  std::cout << "time       " << buf << "\n";
  return 0;
}

struct SurveyArgs {
  std::string map, log, robot, update, initial_pose;
  io::BagTopics topics;
  bool json = false, quiet = false;
};

int run_survey(const SurveyArgs& a) {
  const graph::LoadedMap loaded = graph::read_map(a.map);
  for (const auto& w : loaded.warnings) diagnostic("warning", w.text());
  RobotDescription robot;
  const io::MissionLog log = read_log_for_robot(a.log, a.robot, a.topics, robot);
  ProgressBar bar(a.quiet || a.json);
  mapping::SurveyOptions so;
  if (!a.initial_pose.empty()) so.start = parse_pose_option(a.initial_pose, "--initial-pose");
  // Given where the drive started, the drive's lamps are kept in the frame of its start.
  mapping::MapBuildOptions bo;
  bo.keep_larger_part = !so.start;
  const mapping::DriveLamps drive = mapping::map_drive_lamps(
      log, a.log, robot, bo, [&bar](double f) { bar.update(f, "mapping the drive"); });
  bar.done();
  for (const auto& note : drive.notes) diagnostic("note", note);
  if (so.start && !drive.from_start) {
    diagnostic("note",
               "--initial-pose is where the drive started, which is not in the drive's map (the "
               "drive before the first carry mapped no lamp): the drive is placed by its lamps");
    so.start.reset();
  }
  const mapping::SurveyResult s = mapping::survey(loaded.map, drive.mapped, robot, so);
  if (!a.update.empty()) graph::save_map(s.updated, a.update);
  int failed = 0, moved = 0, added = 0;
  for (const auto& f : s.findings) {
    failed += f.status == mapping::LampStatus::failed;
    moved += f.status == mapping::LampStatus::moved;
    added += f.status == mapping::LampStatus::added;
  }
  auto xyz = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  if (a.json) {
    nlohmann::json j = {
        {"map", a.map},
        {"log", a.log},
        {"judged", s.judged},
        {"ok", s.ok},
        {"failed", failed},
        {"moved", moved},
        {"new", added},
        {"alignment",
         {{"lamps", s.agreeing}, {"rms_m", s.alignment_rms_m}, {"drive_scale", s.drive_scale}}},
        {"lamps", nlohmann::json::array()}};
    for (const auto& f : s.findings) {
      nlohmann::json e = {{"status", mapping::to_string(f.status)},
                          {"id", f.lamp},
                          {"place", f.node},
                          {"where", f.where}};
      if (f.status != mapping::LampStatus::added) e["map_xyz"] = xyz(f.map_xyz);
      if (f.status != mapping::LampStatus::failed) e["seen_xyz"] = xyz(f.seen_xyz);
      if (f.status == mapping::LampStatus::moved) e["moved_m"] = f.offset_m;
      j["lamps"].push_back(e);
    }
    if (!a.update.empty()) j["updated_map"] = a.update;
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  if (std::abs(s.drive_scale - 1) >= 5e-4) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "the drive's wheels read %.2f %% %s than the map: the drive was scaled to it",
                  100 * std::abs(1 / s.drive_scale - 1), s.drive_scale < 1 ? "longer" : "shorter");
    diagnostic("note", buf);
  }
  std::cout << "survey of " << a.map << " with " << a.log << ": " << s.judged
            << " lamps in clear view, " << s.ok << " where the map has them; " << failed
            << " failed, " << moved << " moved, " << added << " new\n";
  if (!s.findings.empty()) {
    // Columns as wide as their longest entry (place names and lamp ids are the map's own).
    std::size_t lamp_w = 10, where_w = 32;
    for (const auto& f : s.findings) {
      lamp_w = std::max(lamp_w, f.lamp.size());
      where_w = std::max(where_w, f.where.size());
    }
    const int lw = static_cast<int>(lamp_w + 2), ww = static_cast<int>(where_w + 2);
    std::cout << std::left << std::setw(8) << "status" << std::setw(lw) << "lamp" << std::setw(ww)
              << "where"
              << "detail\n";
    for (const auto& f : s.findings) {
      char detail[96] = "";
      if (f.status == mapping::LampStatus::moved)
        std::snprintf(detail, sizeof detail, "moved %.1f cm, now at (%.2f, %.2f)", f.offset_m * 100,
                      f.seen_xyz.x(), f.seen_xyz.y());
      else if (f.status == mapping::LampStatus::added)
        std::snprintf(detail, sizeof detail, "at (%.2f, %.2f, %.2f)", f.seen_xyz.x(),
                      f.seen_xyz.y(), f.seen_xyz.z());
      else
        std::snprintf(detail, sizeof detail, "in view, never lit");
      std::cout << std::setw(8) << mapping::to_string(f.status) << std::setw(lw) << f.lamp
                << std::setw(ww) << f.where << detail << "\n";
    }
  }
  if (!a.update.empty()) std::cout << "corrected map: " << a.update << "\n";
  return 0;
}

}  // namespace

void add_map_survey_command(CLI::App& map, Job& run) {
  auto args = std::make_shared<SurveyArgs>();
  CLI::App* survey = map.add_subcommand(
      "survey", "Compare a drive with a map: failed, moved and new lamps, named by place");
  survey->add_option("MAP", args->map, "Map file (.geojson)")->required();
  survey
      ->add_option(
          "LOG", args->log,
          "Mission log (.mcap) or ROS 2 bag of the drive (its directory, or a .mcap or .db3 file)")
      ->required();
  survey->add_option("--robot", args->robot, "robot.json (default: the log's attachment)");
  survey->add_flag("--json", args->json, "Print the findings as JSON");
  survey->add_option("--initial-pose", args->initial_pose,
                     "X,Y,YAW: where the drive started in the map (m, m, rad), when the drive "
                     "alone fits several places");
  survey->add_option("--update", args->update,
                     "Write the corrected map (moved lamps moved, new ones added, failed ones "
                     "taken out)");
  survey->add_flag("--quiet", args->quiet, "No progress bar");
  add_bag_topic_options(*survey, args->topics);
  survey->callback([args, &run] { run = [args] { return run_survey(*args); }; });
}

void add_map_build_command(CLI::App& map, Job& run) {
  auto args = std::make_shared<BuildArgs>();
  CLI::App* build = map.add_subcommand(
      "build", "Build a map (lamps, places, connections) from a drive; never reads the log's map");
  build
      ->add_option(
          "LOG", args->log,
          "Mission log (.mcap) or ROS 2 bag of the drive (its directory, or a .mcap or .db3 file)")
      ->required();
  build->add_option("--robot", args->robot, "robot.json (default: the log's attachment)");
  build->add_option("-o,--output", args->out, "Map to write (.geojson)")->required();
  build->add_option("--names", args->names,
                    "NAMES.json: [{\"name\": ..., \"at\": [x, y]}], a point inside each place");
  build
      ->add_option("--corridor-width", args->corridor_width,
                   "Width of the places' regions (m; wider where a corridor's two rows need it)")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 20.0));
  build->add_option("--initial-pose", args->initial_pose,
                    "X,Y,YAW: where the drive started, in the frame the map should have (m, m, "
                    "rad); default: the start is the origin, facing x");
  build->add_option("--distance", args->distances,
                    "FROM,TO,METRES: two lamps of the map (ids as `map render --lamp-ids` shows "
                    "them) and their distance measured in the building; scales the map to it "
                    "(repeatable)");
  build->add_flag("--quiet", args->quiet, "No progress bar");
  add_bag_topic_options(*build, args->topics);
  build->callback([args, &run] { run = [args] { return run_build(*args); }; });
}

}  // namespace lampnav::apps
