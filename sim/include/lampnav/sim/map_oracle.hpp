#pragma once
// The map oracle: for a drive through a building, the travel after which the lamps seen so far
// fit only the true place. It knows the map and the exact drive, sees every working lamp within
// its view radius without noise, and tells two places apart as soon as one lamp differs; so no
// localizer using those lamps can be sure earlier. It bounds what "converged late" means in a
// regular building (issue 14: convergence within the oracle's distance plus 10 m).
//
// Method. A twin of the drive is a rigid motion T of the whole drive (same odometry, elsewhere):
// the start pose moved by T, the drive carried along. Twins are enumerated from the first view
// with two lamps: its two lamps nearest the robot mapped onto every pair of map lamps alike in
// shape, size and spacing. A twin dies at the first pose of the drive where (a) a lamp in view of
// the true pose has no lamp alike at the same place in the twin's view, or the other way round,
// or (b) the twin's pose is out of every region (it drove through a wall). The oracle's distance
// is the travel at which the last twin other than the truth itself died.

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::sim {

struct MapOracleOptions {
  double view_radius_m = 20.0;  // horizontal distance within which a lamp is seen
  double tolerance_m = 0.15;    // a lamp matches one within this (after the motion)
  double border_m = 0.5;        // lamps within this of the view's edge are not required to match
  double same_place_m = 0.5;    // a twin this close to the truth (and 5 degrees) is the truth
  double wall_margin_m = 0.4;   // a twin this far out of every region has gone through a wall
  std::size_t max_twins = 100000;  // enumeration bound (a view with two lamps is enough)
  std::set<std::string> failed_lamps;  // lamp ids that do not light, as the sensors have them
  void validate() const;               // throws InputError naming the field
};

// One pose of a drive and the travel up to it (m, from the drive's start).
struct DriveSample {
  double travel_m = 0;
  Pose2 pose;
};

struct OracleVerdict {
  // The travel at which the last twin died (0: the first view was unique); empty when a twin
  // lived to the end of the drive.
  std::optional<double> distinguishing_m;
  std::size_t twins = 0;        // twins enumerated from the first view (the truth excluded)
  std::size_t alive_at_end = 0;  // twins that matched the whole drive
};

class MapOracle {
 public:
  MapOracle(const graph::TopologicalMap& map, const MapOracleOptions& options = {});
  // The drive, in order of travel (e.g. a sample every 0.25 m).
  OracleVerdict judge(const std::vector<DriveSample>& drive) const;

 private:
  const graph::TopologicalMap* map_;
  MapOracleOptions o_;
};

}  // namespace lampnav::sim
