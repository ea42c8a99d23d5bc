#pragma once
// The omnidirectional view's own answer to "is the robot where the estimate says?" while the
// estimate is certain: second opinions when an omni check disagrees, and audits on schedule
// whatever the checks say, whose evidence adds up over the frames that follow
// (docs/localization.md, "Audits", "Audits that add up" and "The building's own look-alikes").
// Private to the localizer.

#include <optional>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/kidnap_monitor.hpp"
#include "lampnav/fusion/localizer.hpp"
#include "lampnav/fusion/odometry_track.hpp"
#include "look_alikes.hpp"

namespace lampnav::fusion::detail {

// A place an omni frame's search finds away from the estimate, weighed against it on that
// frame. Both poses are scored alike (the estimate's uncertainty for both), so the ratio
// compares the places, not their refinement.
// The position and heading sigmas an estimate's omni image is refined and scored with: the
// filter's own, held to what one omni image can tell apart (5 cm to 0.5 m, 0.5 to 5 degrees).
struct EstimateSigmas {
  double position_m = 0;
  double yaw_rad = 0;
};
EstimateSigmas estimate_sigmas(const FilterState& prior);

struct Elsewhere {
  Pose2 pose;
  double away = 0;       // m from the estimate
  double log_ratio = 0;  // ln L(there) - ln L(estimate)
};

class Auditor {
 public:
  // Reads the second-opinion and audit options of `o` (validated by LocalizerOptions), and
  // HypothesisSetOptions::station_m: one spot's images repeat one image's evidence. Finds the
  // map's look-alike motions (look_alikes.hpp) once.
  Auditor(const graph::TopologicalMap& map, const GlobalLocalizer& global,
          const LocalizerOptions& o);

  // An omni check disagreed with the estimate: does the frame itself put the robot farther than
  // second_opinion_distance away, second_opinion_ratio likelier? Asked only of a search that
  // names one place.
  std::optional<LossVerdict> second_opinion(const FilterState& prior, const OmniCheckResult& r,
                                            const vision::OmniDetection& omni) const;

  // Whether the omni frame captured at `stamp` is audited, asked of each frame while the estimate
  // is certain: on schedule (audit_period), and every frame while a challenger stands. The
  // first frame of a certain stretch starts the schedule, so a fix is not audited by its own
  // image.
  bool due(Stamp stamp);
  // The estimate became unsure: audits start again with the next certain stretch.
  void reset();

  // An audit of the frame `omni` captured at `stamp`, the estimate then `prior`. A place more
  // than second_opinion_distance away, audit_ratio likelier, proves a loss; one audit_step_ratio
  // likelier becomes the challenger, carried by `odometry` and weighed in each audited frame that
  // follows: images station_m apart add up to audit_ratio (a loss); a frame where it is the less
  // likely clears it, as do audit_challenge_frames frames short of audit_ratio.
  std::optional<LossVerdict> audit(Stamp stamp, const FilterState& prior, const OmniCheckResult& r,
                                   const vision::OmniDetection& omni,
                                   const OdometryTrack& odometry);

 private:
  // The place a challenger names, the evidence for it so far.
  struct Challenger {
    Pose2 pose;              // at the last frame that weighed it
    Pose2 odometry;          // the dead-reckoned pose then
    Pose2 counted_odometry;  // where the robot was at the last image counted
    double log_sum = 0;      // ln of the likelihood ratios counted, added up
    int images = 0;          // images counted
    int frames = 0;          // frames weighed
  };

  // The likeliest place the frame's search finds more than second_opinion_distance from the
  // estimate. `named`: only a search that names one place (not ambiguous) answers, and only
  // with that place.
  std::optional<Elsewhere> elsewhere(const FilterState& prior, const vision::OmniDetection& omni,
                                     bool named) const;
  // The likeliest of the places the map's look-alike motions carry the estimate to, more than
  // second_opinion_distance away and explaining as many of the frame's blobs as the estimate
  // (three or more), refined on the frame: the places a carry the ceiling camera cannot see puts
  // the robot, weighed whether or not the search finds them.
  std::optional<Elsewhere> likeliest_look_alike(const FilterState& prior,
                                                const vision::OmniDetection& omni) const;
  Elsewhere compared(const FilterState& prior, const Pose2& there,
                     const vision::OmniDetection& omni) const;
  std::optional<LossVerdict> challenge(Stamp stamp, const FilterState& prior,
                                       const OmniCheckResult& r, const vision::OmniDetection& omni,
                                       const OdometryTrack& odometry);
  static LossVerdict loss(const Elsewhere& e, double log_sum, int images, const OmniCheckResult& r);

  const GlobalLocalizer* global_;
  std::vector<LookAlikeMotion> look_alikes_;
  Duration period_;
  double second_opinion_ratio_, distance_m_, ratio_, step_ratio_, station_m_;
  int challenge_frames_;
  std::optional<Stamp> last_;
  std::optional<Challenger> challenger_;
};

}  // namespace lampnav::fusion::detail
