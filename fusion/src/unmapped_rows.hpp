#pragma once
// A row of lamps the map does not hold, beside a row it holds: what the omni camera sees from a
// wide corridor mapped under one of its two rows (map build says so when it builds such a map,
// docs/mapping.md). Under either row the view is the same: a row overhead that the map holds, a
// row beside that it does not. A robot under the unmapped row is then placed under the mapped one
// by every image, and no weighing can tell, for the truth is off the map's places; the place is
// unsure, whichever row the robot is under. Private to fusion.

#include <optional>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/hypothesis_set.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::fusion::detail {

// Among an image's `strays` (blobs no map lamp explains, placed on the ceiling) within
// `view_m` of `pose`: at least `min_lamps` placed within `reach_m`, in a straight row (each
// within `band_m` of the line), consecutive ones no further apart than 1.5 times the mapped
// row's spacing; and at least three of the map's lamps in a row parallel to it (within `band_m`
// of a line at 0.5 m to `max_offset_m` from it) along the same stretch. The row found, the one
// with the most lamps; none if no row is, or if it holds fewer than half of those strays (one
// lamp per kSameLamp, 0.5 m): a pose whose view is mostly unexplained is wrong, not a row short.
struct UnmappedRowOptions {
  double max_offset_m = 2.5;
  int min_lamps = 3;
  double band_m = 0.3;
  double reach_m = 1.0;
  double view_m = 10.0;
};
std::optional<UnmappedRow> unmapped_row_beside(const graph::TopologicalMap& map, const Pose2& pose,
                                               const std::vector<StraySighting>& strays,
                                               const UnmappedRowOptions& options);

}  // namespace lampnav::fusion::detail
