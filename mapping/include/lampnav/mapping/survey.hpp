#pragma once
// A drive against an existing map (`lampnav map survey`): the drive's lamps (lamp_mapper.hpp) put
// onto the map by the rigid motion most of them agree on (and the scale of the map), then each map
// lamp the ceiling camera had clearly in view judged: there (ok), not seen (failed), seen more than
// `moved_m` away (moved); and each lamp of the drive no map lamp accounts for: new. Every finding
// says where, as facility staff would: "C3, 4th lamp from J2".

#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/robot_description.hpp"
#include "lampnav/graph/map.hpp"
#include "lampnav/mapping/lamp_mapper.hpp"

namespace lampnav::mapping {

struct SurveyOptions {
  double moved_m = 0.10;      // a lamp seen further than this from its place in the map moved
  double match_m = 0.9;       // ... and at most this far (beyond it: a failed lamp and a new one)
  int min_views = 5;          // a map lamp in clear view at fewer keyframes is not judged
  double view_margin = 0.15;  // of the image size: "clearly in view" stays this far inside
  // Where the drive started in the map, if known: needed where the drive alone fits several
  // places (a regular building); the lamps then refine it.
  std::optional<Pose2> start;
  // The map holds the building's scale, the drive its wheels' (a camera looking up cannot tell):
  // the drive is scaled to the map, by at most this much (beyond it the survey fails: not this
  // building, or wheels far off their calibration), when its lamps spread over at least
  // `scale_extent_m` (RMS from their middle; over less, the scale is the wheels').
  double max_scale_change = 0.02;
  double scale_extent_m = 5.0;
  void validate() const;  // throws InputError naming the field
};

enum class LampStatus { ok, failed, moved, added };
const char* to_string(LampStatus s);

struct SurveyFinding {
  LampStatus status = LampStatus::ok;
  std::string lamp;   // the map's lamp id (a new lamp: the id --update gives it)
  std::string node;   // the place that holds it
  std::string where;  // "C3, 4th lamp from J2"
  Eigen::Vector3d map_xyz = Eigen::Vector3d::Zero();   // in the map (failed, moved)
  Eigen::Vector3d seen_xyz = Eigen::Vector3d::Zero();  // where the drive saw it (moved, added)
  double offset_m = 0;                                 // moved: how far
};

struct SurveyResult {
  std::vector<SurveyFinding> findings;  // failed, moved and new lamps, by place
  int ok = 0;                           // map lamps seen where the map has them
  int judged = 0;                       // map lamps the drive had clearly in view
  Pose2 drive_to_map;                   // the drive's frame, once scaled, onto the map's
  double drive_scale = 1;               // the drive scaled by this to fit the map: its wheels
                                        // read 1 / drive_scale - 1 long
  double alignment_rms_m = 0;           // of the lamps that agreed
  int agreeing = 0;
  graph::TopologicalMap updated;  // the map with moved lamps moved, new ones added, failed ones
                                  // taken out
};

// Throws JobFailed when the drive's lamps fit nowhere in the map.
SurveyResult survey(const graph::TopologicalMap& map, const MappingResult& drive,
                    const RobotDescription& robot, const SurveyOptions& options = {});

}  // namespace lampnav::mapping
