#pragma once
// Generated buildings for the scale benchmarks (issue 8): a square grid of junctions (corners at
// the grid's corners) joined by corridors, with rooms and their doors off the corridors, lamps
// along every corridor and in every room. The same size and seed give the same map.

#include <cstdint>
#include <string>

namespace lampnav::sim {

struct BuildingOptions {
  int nodes = 100;               // about this many nodes (exactly, when the grid allows it)
  double block_m = 20.0;         // junction spacing
  double lamp_spacing_m = 2.25;  // along corridors, as on the office floor
  double ceiling_m = 2.7;
  std::uint64_t seed = 1;  // which blocks get rooms
  void validate() const;   // throws InputError naming the field
};

struct Building {
  std::string geojson;  // map-format.md, reads back with graph::parse_map
  int nodes = 0, edges = 0, lamps = 0, grid = 0;
};

Building generate_building(const BuildingOptions& options);

}  // namespace lampnav::sim
