// A generated grid building as a lampnav map, for the localization sweeps
// (scripts/localization_sweep.py, docs/hypotheses.md): sim::generate_building from the command
// line.
//   make_building OUT.geojson [FIELD=VALUE...]
// FIELD is one of BuildingOptions' (nodes, block_m, lamp_spacing_m, ceiling_m, rooms,
// missing_corridors, wing_lamp_spacing_m, lobby, rows, row_spacing_m, seed); the rest keep their
// defaults. Prints what it wrote as one JSON line (nodes, lamps, grid, missing corridors).
// Exit status 2, naming the argument, on anything it cannot read.

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "lampnav/core/error.hpp"
#include "lampnav/sim/building.hpp"

namespace {

using lampnav::InputError;
using lampnav::sim::BuildingOptions;

double number(const std::string& field, const std::string& text) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno == ERANGE)
    throw InputError({"", "argument", field}, "\"" + text + "\" is not a number");
  return v;
}

// A whole number from 0 to `max`: a count cast to a narrower field must not wrap.
std::int64_t integer(const std::string& field, const std::string& text, double max = 1e15) {
  const double v = number(field, text);
  // The range first: casting a double past int64's (1e20, nan) to it is undefined.
  if (!(v >= 0 && v <= max) || v != std::floor(v))
    throw InputError({"", "argument", field}, "\"" + text + "\" is not a whole number from 0 to " +
                                                  std::to_string(std::int64_t(max)));
  return static_cast<std::int64_t>(v);
}

int small(const std::string& field, const std::string& text) {
  return static_cast<int>(integer(field, text, std::numeric_limits<int>::max()));
}

bool flag(const std::string& field, const std::string& text) {
  if (text == "1" || text == "true") return true;
  if (text == "0" || text == "false") return false;
  throw InputError({"", "argument", field}, "\"" + text + "\" is not 0, 1, true or false");
}

BuildingOptions parse(int argc, char** argv) {
  BuildingOptions o;
  using Set = std::function<void(const std::string&, const std::string&)>;
  const std::map<std::string, Set> fields = {
      {"nodes", [&](auto& f, auto& v) { o.nodes = small(f, v); }},
      {"block_m", [&](auto& f, auto& v) { o.block_m = number(f, v); }},
      {"lamp_spacing_m", [&](auto& f, auto& v) { o.lamp_spacing_m = number(f, v); }},
      {"ceiling_m", [&](auto& f, auto& v) { o.ceiling_m = number(f, v); }},
      {"rooms", [&](auto& f, auto& v) { o.rooms = flag(f, v); }},
      {"missing_corridors", [&](auto& f, auto& v) { o.missing_corridors = small(f, v); }},
      {"wing_lamp_spacing_m", [&](auto& f, auto& v) { o.wing_lamp_spacing_m = number(f, v); }},
      {"lobby", [&](auto& f, auto& v) { o.lobby = flag(f, v); }},
      {"rows", [&](auto& f, auto& v) { o.rows = small(f, v); }},
      {"row_spacing_m", [&](auto& f, auto& v) { o.row_spacing_m = number(f, v); }},
      {"seed", [&](auto& f, auto& v) { o.seed = static_cast<std::uint64_t>(integer(f, v)); }},
  };
  for (int k = 2; k < argc; ++k) {
    const std::string arg = argv[k];
    const std::size_t eq = arg.find('=');
    const std::string field = arg.substr(0, eq);
    const auto it = fields.find(field);
    if (eq == std::string::npos || it == fields.end()) {
      std::string names;
      for (const auto& [name, set] : fields) names += (names.empty() ? "" : ", ") + name;
      throw InputError({"", "argument " + std::to_string(k), field},
                       "expected FIELD=VALUE with FIELD one of " + names);
    }
    it->second(field, arg.substr(eq + 1));
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: make_building OUT.geojson [FIELD=VALUE...]\n";
    return 2;
  }
  try {
    const lampnav::sim::Building b = lampnav::sim::generate_building(parse(argc, argv));
    std::ofstream out(argv[1], std::ios::binary);
    out << b.geojson;
    out.close();
    if (!out) {
      std::cerr << "make_building: " << argv[1] << ": cannot write the map\n";
      return 2;
    }
    nlohmann::ordered_json j = {{"map", argv[1]},   {"nodes", b.nodes}, {"edges", b.edges},
                                {"lamps", b.lamps}, {"grid", b.grid},   {"missing", b.missing}};
    std::cout << j.dump() << "\n";
    return 0;
  } catch (const InputError& e) {
    std::cerr << "make_building: " << e.what() << "\n";
    return 2;
  }
}
