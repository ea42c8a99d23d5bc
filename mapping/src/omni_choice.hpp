#pragma once
// Which of several places a carried part of a drive fits alike (part_placement.hpp) the omni
// camera's views tell apart. The ceiling camera sees a lamp or two overhead, and a regular
// building's corridors, one lamp further along or turned at a corner, look the same to it; the
// omni camera sees the lamps metres around (a junction's side corridor, a corridor's end). Each
// candidate joins the two parts' lamps into one map, and every omni view of both parts is scored
// against it from where the drive was then: the lamps in clear view that the view does not show
// (fusion::GlobalLocalizer::score). Only those count: blobs no mapped lamp explains are lamps the
// drive did not pass under (rooms, far corridors), fewer where a candidate puts more lamps,
// right or wrong. A building symmetric in its lamps (the bundled office under a half turn about
// its middle) leaves its twin places alike to this test as well: then the part is not joined.
// The one place a part fits, or the best of several, must also explain the views about as well
// as each part's own lamps alone do: a part put down where the drive before never went may fit
// a look-alike place of the map, whose lamps the views around it do not show.
// Private to mapping/.

#include <optional>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/vision/omni_detector.hpp"
#include "part_placement.hpp"

namespace lampnav::mapping {

struct OmniView {
  Stamp stamp;
  vision::OmniDetection detection;
};

// Where a drive was at `t`, between its keyframes (in time order) on either side; nullopt outside
// them, between two more than `max_gap_s` apart (a part of the drive left out between them), or
// two whose headings differ by more than `max_turn` (rad: a turn, where the interpolated heading
// is least sure).
inline constexpr double kNoGap = 1e18;
std::optional<Pose2> pose_at(const std::vector<KeyframePose>& keyframes, Stamp t, double max_gap_s,
                             double max_turn = kNoGap);

struct OmniChoiceOptions {
  double position_sigma_m = 0.05;  // the drive's pose at a view, from its keyframes
  double yaw_sigma = 0.02;         // rad
  // The candidate missing the fewest lamps in all views is chosen when, against every other,
  // the lamps only the other misses (view by view) number at least min_gap + gap_sigmas *
  // sqrt(1 + the lamps only it misses).
  double min_gap = 3;
  double gap_sigmas = 3;
  int max_views = 60;       // of each part, spread over it
  int max_candidates = 64;  // more alike than this: not tried

  // Whether the views are asked to choose among this many places alike (or to check the one).
  bool tries(std::size_t candidates) const {
    return candidates >= 1 && candidates <= static_cast<std::size_t>(max_candidates);
  }
};

struct OmniChoice {
  std::optional<std::size_t> chosen;  // index into the candidates
  int views = 0;                      // scored, both parts
  int fewest_missed = 0;  // lamps in clear view not seen, all views, at the best candidate
  int least_extra = 0;    // the fewest lamps only another candidate misses
  int own_missed = 0;     // lamps in clear view not seen, all views, each part's own alone
  int joined_extra = 0;   // lamps the best misses past those, view by view
  bool explains = false;  // joined_extra within the allowance (the best is chosen only then)
};

// `map_views` and `part_views` are the omni views taken during each part (any order); a view
// outside its part's keyframes is not used.
OmniChoice choose_by_omni(const DrivePart& map, const DrivePart& part,
                          const std::vector<PlacementFit>& candidates,
                          const std::vector<const OmniView*>& map_views,
                          const std::vector<const OmniView*>& part_views,
                          const CameraDescription& omni_camera,
                          const OmniChoiceOptions& options = {});

}  // namespace lampnav::mapping
