#pragma once
// What one frame says of one pose hypothesis (docs/hypotheses.md): an omni frame's score at the
// pose least squares refines it to, a ceiling frame's labelled lamps, the lamps either camera
// missed and the blobs no lamp explains, each charged to the hypothesis's ledgers of what the
// map may have wrong (map_evidence.hpp), and the Kalman update of the hypothesis by the pose the
// frame measures. Private to the hypothesis set.

#include <optional>
#include <utility>
#include <vector>

#include "lampnav/fusion/ceiling_geometry.hpp"
#include "lampnav/fusion/ceiling_pipeline.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/hypothesis_set.hpp"
#include "lampnav/fusion/pose_from_lamps.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::fusion::detail {

// -2 ln L of one frame for one hypothesis, and whether the frame contradicts it (judged(), below).
// Only an omni frame sees enough of the ceiling to judge that; a ceiling frame leaves it
// unjudged, and the hypothesis keeps what the last omni frame said of it.
struct Weighed {
  double cost = 0;
  std::optional<bool> contradicted;
};

class HypothesisWeigher {
 public:
  // `ceiling_camera` and `omni` may be null: that camera then weighs nothing. `o` is validated
  // by the caller and must outlive the weigher, as must `map` and `omni`.
  HypothesisWeigher(const graph::TopologicalMap& map, const CameraDescription* ceiling_camera,
                    const GlobalLocalizer* omni, const CeilingPipelineOptions& ceiling_options,
                    const HypothesisSetOptions& o);

  bool weighs_ceiling() const { return labeller_.has_value(); }

  // An omni frame for one hypothesis (carried to the frame), updating it. With `may_search`,
  // an image odd at the pose the refinement reached is searched for near the hypothesis
  // (HypothesisSetOptions::odd_image_search_m), and a pose there that it fits moves it.
  Weighed omni(Hypothesis& h, const vision::OmniDetection& d, bool may_search) const;
  // A ceiling frame for one hypothesis (carried to the frame), updating it.
  Weighed ceiling(Hypothesis& h, const std::vector<vision::LampDetection>& lamps) const;

  // Charges what an omni image said of a hypothesis to its ledgers: the lamps it missed, its
  // `unexplained` blobs no lamp explains (those placed well enough to a spot, the rest to the
  // far account), what each lamp's directions cost. Returns what the ledgers charged less what
  // the image's score counted for them in full.
  double charge_image(Hypothesis& h, const std::vector<const graph::Lamp*>& missed, int unexplained,
                      const std::vector<StraySighting>& strays,
                      const std::vector<std::pair<const graph::Lamp*, double>>& lamp_costs) const;
  // Where an omni blob no lamp explains (a stray) is charged: to a spot of its own when it places
  // its lamp near enough (stray_reach_max_m) and, unless count_beyond_map, within its reach of
  // one of the map's places; to the far account otherwise, as a lamp placed well but beyond every
  // place (`beyond`) or as one placed too loosely to tell where (`far`). (The map is asked only
  // of the near ones: a far stray's reach spans many places, and the search through them cost
  // as much as weighing the hypothesis.)
  enum class StrayKind { spot, beyond, far };
  StrayKind kind(const StraySighting& b) const;
  // Whether a stray's lamp would lie beyond every place of the map (further than its reach).
  bool beyond_places(const StraySighting& b) const;
  struct StrayCounts {
    int spots = 0;
    int beyond = 0;
  };
  StrayCounts count_strays(const std::vector<StraySighting>& strays) const;
  // What an image's `unexplained` blobs that place no lamp well enough for a spot (all but
  // `spots` of them) cost in full: the far account's charge before its bound.
  double far_cost(int unexplained, int spots) const;
  // What the far account charges for an image's far blobs, `far` (far_cost) in full, `beyond` of
  // them placed well but beyond the map's places; `spent` is what it has charged the hypothesis
  // before: at most far_stray_cost_max in all, and never less than beyond_map_blob_cost for
  // each of `beyond`.
  double far_charge(double& spent, double far, int beyond) const;
  // Whether an image fits the hypothesis as no right place's images were seen to: its misfit past
  // HypothesisSetOptions::odd_image_misfit, and past odd_image_misfit_per_lamp for each of the
  // `expected` lamps in clear view it matched (all but `missing`).
  bool odd(double score, int expected, int missing, int unexplained) const;
  bool odd(const PoseHypothesis& p) const {
    return odd(p.score, p.expected, p.missing, p.unexplained);
  }

 private:
  // The covariance of the pose an omni image measures: its least squares' and the floor's bumps
  // (omni_bump_sigma_m, omni_bump_sigma_deg).
  Eigen::Matrix3d measurement_covariance(const PoseHypothesis& p) const;
  // The best pose within odd_image_search_m and odd_image_search_deg of `h` that the image
  // allows, scores better than `odd_fit` and is not odd, with what moving `h` there costs it;
  // nullopt when there is none, or when the move costs more than a contradiction.
  std::optional<std::pair<PoseHypothesis, double>> move_nearby(
      const Hypothesis& h, const PoseHypothesis& odd_fit, const vision::OmniDetection& d) const;
  // What an omni image's score says of the lamps' directions alone, its missing lamps and
  // unexplained blobs taken out: what odd() bounds.
  double misfit(double score, int missing, int unexplained) const;
  // An omni image's verdict on one hypothesis, from its `cost` after the ledgers, its `score` and
  // its counts (`seen`: blobs matched or unexplained): contradicted when most lamps expected in
  // clear view are unseen or most blobs unexplained, when the image is odd() for it, or when the
  // cost passes HypothesisSetOptions::odd_image_cost. A
  // contradiction is charged as the evidence it is (contradiction_cost).
  Weighed judged(double cost, double score, int expected, int missing, int seen,
                 int unexplained) const;
  // Kalman update of a hypothesis with a pose measurement (map_geometry.hpp), its covariance no
  // smaller than odometry between frames allows; returns the normalized innovation squared less
  // its expectation (3).
  double update(Hypothesis& h, const Pose2& z, const Eigen::Matrix3d& R) const;
  // A lamp in full view the labeller found no map lamp for. Near a map lamp, that lamp is off
  // by more than the gate: its misfit. Elsewhere, a lamp the map does not have: its spot.
  double unlabelled(Hypothesis& h, const vision::LampDetection& d) const;

  const graph::TopologicalMap* map_;
  const HypothesisSetOptions* o_;
  const GlobalLocalizer* omni_;
  std::optional<LampLabeller> labeller_;
  std::optional<CeilingGeometry> geometry_;
  std::optional<vision::PinholeCamera> camera_;
  std::optional<vision::LampShapePrior> kind_;  // the lamps the ceiling camera looks for
  PoseMeasurementOptions measurement_;
  // Where a stray ceiling sighting is placed: the usual height of the lamps the ceiling camera
  // looks for (their shape prior's nominal distance, above the floor).
  double lamp_height_ = 0;
  double fit_gate_ = 0;  // the ceiling fit's normalized innovation the map's errors explain
};

}  // namespace lampnav::fusion::detail
