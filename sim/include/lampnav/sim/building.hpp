#pragma once
// Generated buildings for the scale benchmarks and the localization batteries: a square grid of
// junctions (corners at the grid's corners) joined by corridors, with rooms and their doors off
// the corridors, lamps along every corridor (in one row or two), over every junction and in every
// room. With every asymmetry off (no rooms, no missing corridor, one spacing, no lobby) the grid
// is perfectly symmetric: a quarter turn maps it onto itself. The asymmetries real buildings have
// can be switched on: a missing corridor, a wing with another lamp spacing, a lobby. The same
// options and seed give the same map.

#include <cstdint>
#include <string>
#include <vector>

namespace lampnav::sim {

struct BuildingOptions {
  int nodes = 100;               // about this many nodes (exactly, when the grid allows it)
  double block_m = 20.0;         // junction spacing
  double lamp_spacing_m = 2.25;  // along corridors, as on the office floor
  double ceiling_m = 2.7;
  bool rooms = true;               // rooms (seeded blocks) with their doors, to the node count
  int missing_corridors = 0;       // corridors left out (seeded; the building stays connected)
  double wing_lamp_spacing_m = 0;  // > 0: corridors east of the middle have this spacing
  bool lobby = false;  // a hall of round lamps south-west of the corner junction at the origin
  // Lamps across a corridor (and over each junction): 1, or 2 rows `row_spacing_m` apart about
  // its axis, as wide corridors hang two rows of troffers (ids -L1a, -L1b, ...).
  int rows = 1;
  double row_spacing_m = 1.2;
  std::uint64_t seed = 1;  // which blocks get rooms, which corridors are missing
  void validate() const;   // throws InputError naming the field
};

struct Building {
  std::string geojson;  // map-format.md, reads back with graph::parse_map
  int nodes = 0, edges = 0, lamps = 0, grid = 0;
  std::vector<std::string> missing;  // names of the corridors left out
};

Building generate_building(const BuildingOptions& options);

}  // namespace lampnav::sim
