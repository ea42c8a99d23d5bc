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
#include "lampnav/mapping/lamp_mapper.hpp"
#include "lampnav/mapping/topology.hpp"
#include "lampnav/vision/lamp_detector.hpp"

namespace lampnav::io {
struct MissionLog;
}

namespace lampnav::mapping {

struct MapBuildOptions {
  LampMapperOptions mapper;
  TopologyOptions topology;
  vision::LampDetectorOptions detector;
  int probe_frames = 300;  // frames spread over the drive from which the lamps' look is learnt
  // Where the drive started, in the frame the map should have (an existing map's, a floor plan's);
  // without it the map's frame is the start itself (x forward, y left).
  std::optional<Pose2> start;
  void validate() const;  // throws InputError naming the field
};

// The lamps of a recorded drive (the first half of a map build; a survey's whole input).
struct DriveLamps {
  MappingResult mapped;
  vision::LampShapePrior prior;  // learnt: the lamps' size seen from unit distance
  std::size_t frames = 0, unreadable_frames = 0, lamps_seen_whole = 0;
  double travel_m = 0;
  double detect_seconds = 0;       // learning the lamps' look and detecting them in every frame
  double slam_seconds = 0;         // the lamp SLAM, solves included
  std::vector<std::string> notes;  // for the user
};

struct MapBuildResult : DriveLamps {
  graph::TopologicalMap map;
  TopologyReport topology;
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
