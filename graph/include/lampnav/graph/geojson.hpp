#pragma once
// The map file format (map-format.md): one GeoJSON FeatureCollection following the Nav2 Route
// Server's graph-file conventions that nav2_route loads as it is, lampnav's own data under
// `properties.lampnav`.

#include <string>
#include <vector>

#include "lampnav/core/error.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::graph {

// A warning about a map that is valid but probably not what its author meant.
struct MapWarning {
  ErrorContext where;  // file and place (the feature); field when one is to blame
  std::string message;
  std::string text() const { return format_problem(where, message); }
};

struct LoadedMap {
  TopologicalMap map;
  std::vector<MapWarning> warnings;  // check_map() with default options
};

// The map format the writer writes (the reader reads formats 1 and 2: map-format.md).
constexpr int kMapFormat = 2;
// Regions may touch; they may overlap by at most this area before the map is refused (m^2).
constexpr double kRegionOverlapTolerance = 0.01;

// Reads and validates a map file. Every refusal of map-format.md throws InputErrors listing all
// the problems found, each naming the file, the feature (index and id) and the field; JSON syntax
// errors give line and column.
LoadedMap read_map(const std::string& path);
LoadedMap parse_map(const std::string& text, const std::string& source);

// GeoJSON text that parse_map reads back into an identical map.
std::string write_map(const TopologicalMap& map);
// Writes the map to a file; throws lampnav::Error when the file cannot be written.
void save_map(const TopologicalMap& map, const std::string& path);

}  // namespace lampnav::graph
