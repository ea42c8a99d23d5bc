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

// A wide corridor driven under one of its rows: the ceiling camera sees the other row only cut by
// its border, so the drive maps none of it; the omni camera sees it along the run. `run`'s other
// row: `seen` lamps in a row parallel to it, beside its mapped lamps (more than 0.5 m off their
// spread) within `row_beside_m`, along half the run's mapped row or more, of at least 4 lamps
// spaced as the mapped row's (at most 1.5 times as far apart).
struct RowBeside {
  int run = 0;
  Eigen::Vector2d middle = Eigen::Vector2d::Zero();   // of the run's mapped row
  Eigen::Vector2d towards = Eigen::Vector2d::Zero();  // unit, from the mapped row to the other
  double offset = 0;      // of the other row from the run's line (positive to its right)
  double s0 = 0, s1 = 0;  // where the other row begins and ends along the run's line
  double apart_m = 0;     // between the two rows
  int lamps = 0;          // seen in the other row
};
std::vector<RowBeside> rows_beside(const std::vector<Line>& lines, const std::vector<Run>& runs,
                                   const std::vector<MappedLamp>& lamps,
                                   const std::vector<Eigen::Vector2d>& seen,
                                   const TopologyOptions& o);

struct SeenWay {
  Eigen::Vector2d at, way;  // where its row's line crosses the run, and the way from there
  Eigen::Vector2d middle;   // of the row
  int lamps = 0;            // in the row
};

// The ways seen: rows of `seen` (the lamps around the drive, map frame) that start beside a run
// and go away from it, each alone (no other such row beside it, at most one lamp off its line
// near it). `lamps`, those the drive mapped, tell how far apart a corridor's rows stand; the
// lamps of a run's `other_rows` (rows_beside) are the run's own, as its mapped lamps are.
std::vector<SeenWay> ways_not_driven(const std::vector<Line>& lines, const std::vector<Run>& runs,
                                     const std::vector<MappedLamp>& lamps,
                                     const std::vector<Eigen::Vector2d>& seen,
                                     const std::vector<RowBeside>& other_rows,
                                     const TopologyOptions& o);

}  // namespace lampnav::mapping::drive_topology
