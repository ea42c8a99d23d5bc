#pragma once
// Ways out of a place the drive did not take, for build_topology (topology.hpp): rows of the lamps
// the omni camera saw around the drive (omni_ways.hpp) that start beside a run and go away from
// it. Private to mapping/.

#include <Eigen/Core>
#include <vector>

#include "halls.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"
#include "lampnav/mapping/topology.hpp"

namespace lampnav::mapping::drive_topology {

struct SeenWay {
  Eigen::Vector2d at, way;  // where its row's line crosses the run, and the way from there
  Eigen::Vector2d middle;   // of the row
  int lamps = 0;            // in the row
};

// The ways seen: rows of `seen` (the lamps around the drive, map frame) that start beside a run
// and go away from it, each alone (no other such row beside it, at most one lamp off its line
// near it). `lamps`, those the drive mapped, tell how far apart a corridor's rows stand.
std::vector<SeenWay> ways_not_driven(const std::vector<Line>& lines, const std::vector<Run>& runs,
                                     const std::vector<MappedLamp>& lamps,
                                     const std::vector<Eigen::Vector2d>& seen,
                                     const TopologyOptions& o);

}  // namespace lampnav::mapping::drive_topology
