#pragma once
// Halls for build_topology (topology.hpp): where the drive went up and down beside itself, or
// among lamps off to both its sides, and the drive's straight runs cut where they cross one.
// Internal to mapping/.

#include <Eigen/Core>
#include <cmath>
#include <utility>
#include <vector>

#include "lampnav/graph/geometry.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"
#include "lampnav/mapping/topology.hpp"

namespace lampnav::mapping::drive_topology {

// A straight line the drive went along, and the stretches of it driven (as intervals of the
// distance along it), merged into runs.
struct Line {
  Eigen::Vector2d origin, dir;  // dir canonical: angle in (-pi/2, pi/2]
  std::vector<std::pair<double, double>> intervals;
  Eigen::Vector2d at(double s) const { return origin + s * dir; }
  double along(const Eigen::Vector2d& p) const { return (p - origin).dot(dir); }
  double across(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = p - origin;
    return std::abs(d.x() * dir.y() - d.y() * dir.x());
  }
};

struct Run {
  int line = 0;
  double s0 = 0, s1 = 0;
  int hall0 = -1, hall1 = -1;  // the hall an end stops at (the run went on through it)
};

// A wide corridor of two rows of lamps driven as docs/mapping.md asks, up one row and back along
// the other: two parallel lines, side by side (further apart than same_line_m, at most
// row_beside_m) over more than hall_min_overlap_m, whose mapped lamps there (out to row_beside_m
// beyond either) stand in exactly two rows, each line under one of them (within same_line_m). Such
// lanes are one corridor, not a hall: the pair becomes one line half way between them, holding both
// lines' stretches. Returns how far apart the two rows of each pair joined are.
std::vector<double> join_lanes_under_two_rows(std::vector<Line>& lines,
                                              const std::vector<MappedLamp>& lamps,
                                              const TopologyOptions& o);

// Halls from lanes: the pieces of runs with another beside them, grouped where they touch; a
// group is a hall when the lamps around it stand in rows along its lanes, spread across them.
std::vector<graph::Polygon> halls_from_lanes(const std::vector<Line>& lines,
                                             const std::vector<Run>& runs,
                                             const std::vector<MappedLamp>& lamps,
                                             const TopologyOptions& o);

// Halls seen from one lane: lamps in no run's band, off to both sides of the drive, with no row
// of the drive's own among them.
std::vector<graph::Polygon> halls_beside(const std::vector<Line>& lines,
                                         const std::vector<Run>& runs,
                                         const std::vector<MappedLamp>& lamps,
                                         const std::vector<graph::Polygon>& lane_halls,
                                         const TopologyOptions& o);

// Halls whose regions overlap are one (the hull of both).
void merge_overlapping(std::vector<graph::Polygon>& halls);

// The runs with what lies inside the halls cut out (pieces shorter than min_length dropped); the
// ends left at a hall say so.
std::vector<Run> cut_at_halls(const std::vector<Line>& lines, const std::vector<Run>& runs,
                              const std::vector<graph::Polygon>& halls, double min_length);

}  // namespace lampnav::mapping::drive_topology
