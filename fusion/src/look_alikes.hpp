#pragma once
// The building's own look-alikes: rigid motions of the map that carry most of its lamps onto
// lamps alike. A regular office has a few (its half turn about the middle, slides along its rows
// of lamps); a grid of identical blocks has many. A robot carried by one of them to the place it
// names sees nearly what it saw: the places to weigh against the estimate first (audits.hpp).
// Private to fusion.

#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::fusion::detail {

struct LookAlikeMotion {
  Pose2 motion;         // in the map frame: a place p looks like motion * p
  double fraction = 0;  // of the lamps it carries onto lamps alike (of a sample of them)
};

// The rigid motions other than the identity that carry at least `min_fraction` of the map's
// lamps onto lamps alike (map_geometry.hpp, lands_on_alike), at most `max_count` of them: the
// largest fractions first, the shortest moves among equals. Found from one lamp and its nearest
// neighbour laid on every pair of lamps alike as far apart, for three such lamps spread over the
// map; counted on at most 256 lamps spread over it. A map of fewer than 4 lamps has none.
std::vector<LookAlikeMotion> look_alike_motions(const graph::TopologicalMap& map,
                                                double min_fraction, int max_count);

}  // namespace lampnav::fusion::detail
