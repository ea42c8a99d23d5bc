// lampnav route M --from NODE --to NODE [--json]

#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "lampnav/graph/geojson.hpp"
#include "lampnav/graph/route_commands.hpp"

namespace lampnav::apps {

namespace {

struct RouteArgs {
  std::string map, from, to;
  bool json = false;
};

const graph::Node& named_node(const graph::TopologicalMap& map, const std::string& name,
                              const std::string& map_file, const char* flag) {
  const graph::Node* n = map.find_node(name);
  if (!n) {
    throw InputError({map_file, "", flag}, "no node named '" + name + "' in the map");
  }
  return *n;
}

int run_route(const RouteArgs& a) {
  const graph::LoadedMap loaded = graph::read_map(a.map);
  const graph::Node& from = named_node(loaded.map, a.from, a.map, "--from");
  const graph::Node& to = named_node(loaded.map, a.to, a.map, "--to");
  const auto route = graph::plan_route(loaded.map, from.id, to.id);
  if (!route) throw JobFailed("no route from '" + a.from + "' to '" + a.to + "' in " + a.map);
  const auto commands = graph::route_to_commands(loaded.map, *route);
  if (a.json) {
    nlohmann::ordered_json j;
    j["from"] = a.from;
    j["to"] = a.to;
    j["cost"] = route->cost;
    j["nodes"] = nlohmann::ordered_json::array();
    for (const auto& id : route->nodes) j["nodes"].push_back(loaded.map.node(id).name);
    j["commands"] = nlohmann::ordered_json::array();
    for (const auto& c : commands) j["commands"].push_back(c.text());
    std::cout << j.dump(2) << "\n";
  } else {
    for (const auto& c : commands) std::cout << c.text() << "\n";
  }
  return 0;
}

}  // namespace

void add_route_command(CLI::App& app, Job& run) {
  auto args = std::make_shared<RouteArgs>();
  CLI::App* cmd =
      app.add_subcommand("route", "Plan the shortest route and print its route commands");
  cmd->add_option("MAP", args->map, "Map file (.geojson)")->required();
  cmd->add_option("--from", args->from, "Start node name")->required();
  cmd->add_option("--to", args->to, "Goal node name")->required();
  cmd->add_flag("--json", args->json, "Print the route as JSON (nodes, cost, commands)");
  cmd->callback([args, &run] { run = [args] { return run_route(*args); }; });
}

}  // namespace lampnav::apps
