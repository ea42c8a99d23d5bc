#pragma once
// The kinds of lamp a building has, learnt from the lamps a drive saw whole. A building rarely has
// one kind: strip lights down the corridors and round lamps in the rooms and the lobby, or a high
// hall's large lamps beside a low gallery's small ones. The ceiling camera sees each lamp's size
// divided by its height above the camera, so a kind is what the image shows: a shape (long, or
// round) and a size seen from unit distance. Kinds are the groups of those sizes with gaps
// between them: sorted by size (the logarithm of length and width), a gap of more than
// `split_log_gap` between neighbours separates two kinds, and a group is a kind when it holds at
// least `min_sightings` lamps and `min_share` of all. Private to mapping/.

#include <vector>

#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::mapping {

struct LampKindOptions {
  // Neighbouring sizes further apart than this (in the logarithm: 0.2 is 22 %) are two kinds. One
  // kind's lamps hang at one height, give or take a few percent; a floor bump or the detector
  // moves a size by a few percent more.
  double split_log_gap = 0.2;
  int min_sightings = 8;    // whole sightings a kind needs: fewer are a glint or a person
  double min_share = 0.02;  // of all whole sightings
  // Lamps up to 30 % nearer or 40 % further than the kind's median (the detector's distance
  // bounds, from unit distance).
  double min_distance = 0.7;
  double max_distance = 1.4;
  void validate() const;  // throws InputError naming the field
};

// A lamp seen whole, from unit distance: its long and short axes (normalized image units).
struct LampLook {
  double length = 0, width = 0;
};

// Long lamps are those whose length is more than this many times their width.
constexpr double kLongLamp = 1.5;

// The kinds among `looks`, most sightings first, each as a detector's prior at unit distance;
// none when `looks` is empty. The most common kind is always one, however few its sightings.
std::vector<vision::LampShapePrior> lamp_kinds(const std::vector<LampLook>& looks,
                                               const LampKindOptions& options = {});

// The index in `kinds` of the kind a lamp seen whole with these axes is: the nearest in size
// among those of its shape (any shape when none is); -1 when `kinds` is empty.
int nearest_kind(const std::vector<vision::LampShapePrior>& kinds, double length, double width);

}  // namespace lampnav::mapping
