#pragma once
// Ways out of a place the drive did not take, from what the omni camera saw around it. The
// ceiling camera sees a lamp or two overhead; the omni camera sees the lamps metres around, down
// the side corridor of a junction passed straight through, or the third way of a corner that is
// in truth a junction. Two steps, for build_topology (topology.hpp):
//  1. `lamps_seen_around`: each omni blob's ray, from where the drive was when the view was taken
//     (its optimized keyframes), meets the ceiling at the mapped lamps' usual height; sightings
//     from several views within `cluster_m` of each other are a lamp. Only blobs placed within
//     `max_distance_m` of the camera count: a blob's direction error moves its lamp by
//     h dtheta / cos^2(theta) on the ceiling (0.14 m at 9 m for 0.1 degree under a 0.9 m rise; a
//     floor bump's tilt moves it more: each view's tilt is fitted to the lamps the drive mapped
//     first, and what is left the lamp's mean weighs).
//  2. `lamp_rows`: lamps in straight rows, consecutive lamps at most `max_gap_m` apart. A row
//     that starts beside a place and runs away from it is a way out (topology.cpp decides).
// A building's walls hide what is behind them from a real omni camera; the simulator's images
// show every lamp in view, so rows must start at the place (a parallel corridor, a room's lamp
// beside the corridor, are no way out). Private to mapping/.

#include <Eigen/Core>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"
#include "omni_choice.hpp"

namespace lampnav::mapping {

struct OmniLampsOptions {
  double max_distance_m = 9.0;  // from the camera, horizontally
  // A sighting's spread on the ceiling: the floor's tilt (bumps, one sigma) through the ray,
  // rise x (1 + tan^2) of its angle off the vertical. The surest sightings are taken first; each
  // joins the nearest lamp within three spreads (at least cluster_m, at most max_gate_m) or
  // starts one; a lamp is the mean of its sightings weighted by the inverse squared spread.
  double tilt_sigma_deg = 0.5;
  double cluster_m = 0.8;
  double max_gate_m = 1.2;
  int min_views = 3;          // a lamp seen from fewer views is not one (a reflection, a person)
  double max_sigma_m = 0.25;  // nor is one whose mean is less sure than this (from its spreads)
  double max_keyframe_gap_s = 1.0;  // a view between keyframes further apart has no pose
  double max_turn = 0.05;           // rad between the keyframes around a view: turning, not used
  // Each view's tilt (a floor bump, about the floor) and the pose's yaw error are fitted to the
  // mapped lamps within max_distance_m, each matched to the blob nearest its direction within
  // fit_gate_deg, from fit_min_lamps of them, with the blobs fit_min_theta to fit_max_theta rad off
  // the axis that are not split out of a bloom.
  double fit_gate_deg = 3.0;
  int fit_min_lamps = 3;
  double fit_min_theta = 0.6, fit_max_theta = 1.35;
  void validate() const;  // throws InputError naming the field
};

// Lamps the omni camera saw around the drive (those the drive passed under among them), in the
// map frame. `height_m` is the lamps' usual height above the floor; `mapped`, the lamps the drive
// mapped (centres, map frame), to which each view's tilt is fitted.
std::vector<Eigen::Vector2d> lamps_seen_around(const std::vector<OmniView>& views,
                                               const std::vector<KeyframePose>& keyframes,
                                               const CameraDescription& omni_camera,
                                               double height_m,
                                               const std::vector<Eigen::Vector3d>& mapped,
                                               const OmniLampsOptions& options);

struct LampRow {
  Eigen::Vector2d first = Eigen::Vector2d::Zero(), last = Eigen::Vector2d::Zero();
  int lamps = 0;
  Eigen::Vector2d dir() const { return (last - first).normalized(); }
};

// Straight rows of at least `min_lamps` lamps, each within `across_m` of a line through two of
// them, consecutive lamps at most `max_gap_m` apart; `first` and `last` are the row's end lamps
// on the line fitted to all of them. A lamp may be in two rows (a corner).
std::vector<LampRow> lamp_rows(const std::vector<Eigen::Vector2d>& lamps, int min_lamps,
                               double across_m, double max_gap_m);

}  // namespace lampnav::mapping
