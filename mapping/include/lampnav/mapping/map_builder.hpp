#pragma once
// A map from a recorded drive (`lampnav map build`): the lamps' look learnt from the drive's own
// frames, every ceiling frame through the lamp detector, the wheels and the detections through
// the lamp SLAM (lamp_mapper.hpp), then the places (topology.hpp). The log's map attachment is
// never read: the map comes from the drive alone.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/mapping/lamp_kinds.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"
#include "lampnav/mapping/topology.hpp"
#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::io {
struct MissionLog;
}

namespace lampnav::mapping {

// A distance measured in the building between two lamps of the map: a laser meter or a tape on
// the floor below their centres, or the lighting plan. It is what gives the map its true scale:
// the ceiling camera sees a building and a smaller one with a lower ceiling alike, so without a
// measured distance the map's scale is the wheels' calibration (docs/mapping.md, "Scale").
struct KnownDistance {
  std::string from, to;  // lamp ids in the map built without it (`map render --lamp-ids`)
  double metres = 0;     // horizontal, centre to centre
  std::string given_as;  // how the user gave it (the CLI's "--distance ..."), for messages
};

struct MapBuildOptions {
  LampMapperOptions mapper;
  TopologyOptions topology;
  vision::LampDetectorOptions detector;
  int probe_frames = 300;  // frames spread over the drive from which the lamps' look is learnt
  LampKindOptions kinds;   // how the lamps' looks are told apart into kinds
  // At most this many omni frames, spread over the drive, are detected for the ways out it did
  // not take (TopologyOptions::way_min_lamps; 0: none; a robot without an omni camera has none).
  int omni_views_for_ways = 600;
  // Where the drive started, in the frame the map should have (an existing map's, a floor plan's);
  // without it the map's frame is the start itself (x forward, y left).
  std::optional<Pose2> start;
  // Of the parts of a drive between carries that cannot be joined, keep the one that maps the
  // most lamps (the map's frame then starts where the robot was put down), or the first (false:
  // its frame is the drive's start, as a survey given that start needs).
  bool keep_larger_part = true;
  // Distances measured between lamps: the map is scaled to fit them (least squares), about the
  // drive's start; heights above the ceiling camera scale alike. Refused (InputError) when a lamp
  // is not in the map, when they ask for a scale further than `max_scale_change` from the wheels'
  // (not the lamps measured, or the tape misread), or when they disagree with each other by more
  // than `distance_tolerance_m` plus 3 sigma of the tape.
  std::vector<KnownDistance> distances;
  double max_scale_change = 0.02;     // wheels are calibrated to better than 2 %
  double tape_sigma_m = 0.003;        // a measured distance's error (1 sigma)
  double distance_tolerance_m = 0.1;  // what the map's own lamps may be off between two of them
  void validate() const;              // throws InputError naming the field
};

// The lamps of a recorded drive (the first half of a map build; a survey's whole input).
struct DriveLamps {
  MappingResult mapped;
  // Learnt: the kinds of lamp, each its size seen from unit distance, the most common first
  // (`prior`).
  std::vector<vision::LampShapePrior> kinds;
  vision::LampShapePrior prior;
  std::size_t frames = 0, unreadable_frames = 0, lamps_seen_whole = 0;
  std::size_t lamps_seen_cut = 0;  // sightings of lamps cut by the image's border
  double travel_m = 0;
  // The map's frame is the drive's start; false: where the robot was put down after a carry (the
  // drive before it is left out).
  bool from_start = true;
  double detect_seconds = 0;       // learning the lamps' look and detecting them in every frame
  double slam_seconds = 0;         // the lamp SLAM, solves included
  std::vector<std::string> notes;  // for the user
};

struct MapBuildResult : DriveLamps {
  graph::TopologicalMap map;
  TopologyReport topology;
  double scale = 1;  // applied to fit the measured distances (1 without them)
};

// The lamp SLAM over a recorded drive. Throws as build_map does.
DriveLamps map_drive_lamps(const io::MissionLog& log, const std::string& source,
                           const RobotDescription& robot, const MapBuildOptions& options,
                           const std::function<void(double)>& progress = {});

// `source` names the log in messages. Throws InputError when the log cannot give a map (no
// ceiling camera frames, no wheels, a robot without a ceiling camera) and JobFailed when the
// drive does not (the robot never moved, no lamp was ever seen whole).
MapBuildResult build_map(const io::MissionLog& log, const std::string& source,
                         const RobotDescription& robot, const MapBuildOptions& options,
                         const std::vector<PlaceName>& names,
                         const std::function<void(double)>& progress = {});

}  // namespace lampnav::mapping
