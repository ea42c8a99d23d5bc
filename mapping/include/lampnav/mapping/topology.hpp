#pragma once
// The places and connections of a building from a mapped drive (trajectory first, as road maps
// are inferred from GPS traces): the optimized drive is cut into straight stretches; collinear
// stretches make corridor lines; where lines meet are places, their kind by the ways out the
// drive took (one: an end, two at an angle: a corner, three or more: a junction); the pieces of
// the lines between places are corridors. Each lamp goes to the place whose region holds it, in
// walking order. Halls are where the drive went up and down beside itself (parallel stretches
// closer than a corridor's width cannot be two corridors) over lamps spread across its lanes, and
// where it saw lamps off to its side in no corridor's row: their region is the lanes and the
// lamps, and the places and corridors around link to them. What the drive never went down is not in
// the map, but a way out it did not take counts in its place's kind when the lamps seen around the
// drive (the omni camera's) stand in a row going away from the place: a junction passed straight
// through, or turned at, is a junction; without them it comes out no place, or a corner.

#include <map>
#include <string>
#include <vector>

#include "lampnav/graph/map.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"

namespace lampnav::mapping {

struct TopologyOptions {
  double corridor_width_m = 2.0;  // regions' width (the omni view could measure it: not yet)
  double simplify_m = 0.3;        // the drive's polyline is simplified to this tolerance
  double min_stretch_m = 1.0;     // shorter straight stretches (turns on the spot) are dropped
  // After a turn the robot may leave the corner askew and settle onto the corridor's line a few
  // metres on: the simplified drive keeps that short stretch, not parallel enough to share the
  // corridor's line, and the corridor's run then begins past the corner, further than a place
  // reaches (2.1 m on a simulated 300 m loop: the corridor after each turn was left out with its
  // lamps). A stretch shorter than this between two longer ones that meet at an angle, within
  // this of its ends, is part of the turn: the two meet where their lines do.
  double turn_m = 3.5;
  double same_line_m = 0.6;  // stretches this close across and parallel share a line
  double parallel_deg = 8.0;
  double gap_m = 1.5;    // a line's stretches this far apart are one corridor
  double place_m = 1.5;  // line meetings this close are one place
  // Halls: stretches side by side over hall_min_overlap_m (longer than the turn from one lane to
  // the next, which is itself a stretch), further apart than same_line_m and at most
  // hall_lane_gap_m (0: no halls), with the lamps around them in rows along them
  // hall_min_spread_m apart (one row is a corridor driven twice, once on each side).
  double hall_lane_gap_m = 3.0;
  double hall_min_overlap_m = 4.0;
  double hall_min_spread_m = 1.5;
  double hall_margin_m = 0.5;  // a hall's region: its lanes and lamps, and this much around them
  // Halls seen from one lane: at least hall_min_lamps lamps (0: none) beside the drive, in no
  // corridor's band, each within hall_link_m of another, or within hall_link_per_height times
  // their height above the floor (lamps hung higher are further apart: lighting designs keep
  // spacing within about 1.5 times the mounting height).
  int hall_min_lamps = 3;
  double hall_link_m = 6.0;
  double hall_link_per_height = 1.5;
  // Ways out not driven, from the lamps seen around the drive: a row of at least way_min_lamps
  // of them (0: none), each within way_across_m of the row's line, consecutive ones at most
  // way_gap_m apart, whose line crosses a run at least way_min_angle_deg from it, its first lamp
  // at most way_first_lamp_m from the crossing and the row all on one side of it, with no other
  // such row going the same way within way_beside_m of it and at most one lamp off its line
  // within way_clear_m of it (rows side by side, and diagonals, are a room's or a hall's grid of
  // lamps; one lamp beside is a room's, seen through its door).
  // The lamps the drive passed under within rows_reach_m across a run tell where its lamps hang
  // across it (the middle of their spread: under the drive, or to one side) and how far apart its
  // rows are (half their spread, the median over runs: 0 for one row). Lamps within same_line_m
  // of that middle, along the run, are its own. When the half spread is more than way_across_m (two
  // rows or more), it widens the rows of ways (each lamp within way_across_m plus it of the row's
  // line), the runs' own lamps, and the lamps beside a row that are not its own.
  double rows_reach_m = 1.5;
  // A row of the omni camera's lamps beside a run's mapped lamps, within row_beside_m, along half
  // the mapped row, its lamps as close: the corridor's other row, not mapped (a note says so).
  double row_beside_m = 2.5;
  int way_min_lamps = 3;
  double way_across_m = 0.3;
  double way_gap_m = 5.0;
  double way_first_lamp_m = 3.0;
  double way_beside_m = 6.0;
  double way_clear_m = 4.5;
  double way_min_angle_deg = 45.0;
  void validate() const;  // throws InputError naming the field
};

struct TopologyReport {
  std::size_t lamps_placed = 0;
  std::size_t lamps_outside = 0;  // lamps in no place's region (left out of the map)
  std::size_t ways_seen = 0;      // ways out seen, not driven, that changed a place's kind
  std::size_t rows_beside = 0;    // rows of lamps the omni camera saw beside a corridor, unmapped
  std::size_t lanes_joined = 0;   // lanes under a wide corridor's two rows, joined as one corridor
  std::vector<std::string> notes;
};

// Names: C1, C2, ... for corridors, J for junctions, K for corners, E for ends, numbered in the
// order the drive first reached them; `names` maps a point inside a place to the name to use.
struct PlaceName {
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  std::string name;
};

// `seen`: lamps seen around the drive, in the map frame (the omni camera's, those the drive passed
// under among them; empty: the drive's own ways only).
graph::TopologicalMap build_topology(const MappingResult& mapped, const TopologyOptions& options,
                                     const std::vector<PlaceName>& names, TopologyReport* report,
                                     const std::vector<Eigen::Vector2d>& seen = {});

}  // namespace lampnav::mapping
