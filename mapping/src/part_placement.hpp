#pragma once
// Where a part of a drive mapped on its own (the robot carried to it, which the wheels do not see)
// lies in the map of the drive before: the rigid motion that puts its lamps onto lamps of the map,
// found only when exactly one such motion fits. Private to mapping/.
//
// A motion fits when at least `min_shared` of the part's lamps fall on lamps of the map of the same
// kind, height and axis, and nothing contradicts it: no lamp of either lies where the other drive
// passed right under it (`sure_m`, away from its ends) without a lamp of the other there, and no
// lamp lies beside one of the other (closer than `clash_m`, not on it) or on one of another kind or
// axis. In a regular building many motions put a few lamps onto lamps (a corridor onto its
// twin, one lamp further along, or turned at a corner); the drive's own path rules out most of
// them, and when more than one is left, the part is not placed.

#include <optional>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"

namespace lampnav::mapping {

struct PlacementOptions {
  // A lamp this close to one of the other is the same lamp: once the motion is fitted to the
  // lamps they share (the maps place lamps within a few centimetres; a junction's lamp is 12.5 cm
  // nearer its neighbours than a row's are to each other), and while candidates are sought.
  double match_m = 0.1;
  double seek_m = 0.25;
  double clash_m = 0.8;              // closer than this, and not the same: the motion is wrong
  double pair_tolerance_m = 0.15;    // two lamps' distance in both maps, within this
  double height_tolerance_m = 0.15;  // a lamp's height in both maps (each within 3 cm)
  double axis_tolerance = 0.17;      // rad (10 deg), a rectangular lamp's axis in both maps
  // A lamp was surely mapped by a drive that passed within this of it (horizontally), per metre
  // it hangs above the ceiling camera (half the tangent of the camera's narrower half-angle:
  // 0.239 on maps/robots/pioneer.json, 0.57 m under the office's lamps), and at least sure_m:
  double sure_per_height = 0.2;
  double camera_height_m = 0.3;
  double sure_m = 0.5;
  int end_keyframes = 10;    // unless this many keyframes from its start or end
  int min_shared = 3;        // lamps both drives mapped
  int neighbours = 4;        // each of the part's lamps paired with its nearest this many
  double max_pair_m = 12.0;  // lamps paired at most this far apart
};

// Lamps and keyframes of a drive, in its own frame.
struct DrivePart {
  const std::vector<MappedLamp>* lamps = nullptr;
  const std::vector<KeyframePose>* keyframes = nullptr;
};

struct PlacementFit {
  Pose2 motion;  // part frame -> map frame
  int shared = 0;
};

struct Placement {
  std::optional<Pose2> motion;     // part frame -> map frame, when exactly one fits
  int shared = 0;                  // lamps the fitting motion puts onto the map's
  int fitting = 0;                 // motions that fit (distinct): 0 none, 1 placed, more: ambiguous
  std::vector<PlacementFit> fits;  // every fitting motion, those sharing the most lamps first
  // Motions that would fit but for one lamp (failed, or missed by one drive): in a regular
  // building with a lamp in twelve failed, the one place a part fits is often one such lamp
  // away from several more, and a place the drive before never went fits one or none of them.
  std::vector<PlacementFit> near_fits;
};

Placement place_part(const DrivePart& map, const DrivePart& part,
                     const PlacementOptions& options = {});

}  // namespace lampnav::mapping
