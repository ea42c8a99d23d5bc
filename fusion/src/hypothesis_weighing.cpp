#include "hypothesis_weighing.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "lampnav/fusion/chi_square.hpp"
#include "map_evidence.hpp"
#include "map_geometry.hpp"

namespace lampnav::fusion::detail {

namespace {

constexpr double kDeg = M_PI / 180.0;

double sigma_position(const Eigen::Matrix3d& P) { return std::sqrt(std::max(P(0, 0), P(1, 1))); }

bool contradicts(int expected, int missing, int seen, int unexplained) {
  return (expected >= 3 && 2 * missing > expected) || (seen >= 4 && 2 * unexplained > seen);
}

}  // namespace

HypothesisWeigher::HypothesisWeigher(const graph::TopologicalMap& map,
                                     const CameraDescription* ceiling_camera,
                                     const GlobalLocalizer* omni,
                                     const CeilingPipelineOptions& ceiling_options,
                                     const HypothesisSetOptions& o)
    : map_(&map), o_(&o), omni_(omni), measurement_(ceiling_options.measurement) {
  measurement_.map_sigma = std::max(measurement_.map_sigma, o.map_sigma_m);
  fit_gate_ = chi_square_quantile(o.fit_gate_probability, 3);
  if (ceiling_camera) {
    LabellerOptions lo = ceiling_options.labeller;
    lo.map_sigma = std::max(lo.map_sigma, o.map_sigma_m);
    labeller_.emplace(map, *ceiling_camera, lo);
    geometry_.emplace(*ceiling_camera);
    camera_.emplace(*ceiling_camera);
    kind_ = shape_prior_for(map, *ceiling_camera);
    lamp_height_ = kind_->nominal_distance + ceiling_camera->mount.xyz.z();
  }
}

double HypothesisWeigher::update(Hypothesis& h, const Pose2& z, const Eigen::Matrix3d& R) const {
  return update_pose(h.pose, h.covariance, z, R, o_->sigma_m, o_->sigma_yaw_deg * kDeg);
}

HypothesisWeigher::StrayKind HypothesisWeigher::kind(const StraySighting& b) const {
  if (b.reach > o_->stray_reach_max_m) return StrayKind::far;
  return o_->count_beyond_map || !beyond_places(b) ? StrayKind::spot : StrayKind::beyond;
}

bool HypothesisWeigher::beyond_places(const StraySighting& b) const {
  return map_->node_near(b.at, b.reach) == nullptr;
}

HypothesisWeigher::StrayCounts HypothesisWeigher::count_strays(
    const std::vector<StraySighting>& strays) const {
  StrayCounts n;
  for (const StraySighting& b : strays) {
    const StrayKind k = kind(b);
    n.spots += k == StrayKind::spot;
    n.beyond += k == StrayKind::beyond;
  }
  return n;
}

double HypothesisWeigher::far_cost(int unexplained, int spots) const {
  return omni_->options().pairs.spurious_cost * std::max(0, unexplained - spots);
}

double HypothesisWeigher::far_charge(double& spent, double far, int beyond) const {
  return std::max(charge_account(spent, far, o_->far_stray_cost_max),
                  o_->beyond_map_blob_cost * beyond);
}

double HypothesisWeigher::charge_image(
    Hypothesis& h, const std::vector<const graph::Lamp*>& missed, int unexplained,
    const std::vector<StraySighting>& strays,
    const std::vector<std::pair<const graph::Lamp*, double>>& lamp_costs) const {
  h.keep_strays(strays, o_->row_beside_images);
  const double each = omni_->options().pairs.miss_cost;
  const double stray = omni_->options().pairs.spurious_cost;
  double delta = charge_absences(h.map_costs.lamps, missed, each, o_->lamp_out_cost) -
                 each * static_cast<double>(missed.size());
  int spots = 0, beyond = 0;  // kind() asks the map: once a stray
  for (const StraySighting& b : strays) switch (kind(b)) {
      case StrayKind::spot:
        ++spots;
        delta += charge_stray(h.map_costs.strays, b.at, std::max(o_->stray_radius_m, b.reach),
                              stray, o_->unmapped_lamp_cost) -
                 stray;
        break;
      case StrayKind::beyond:
        ++beyond;
        break;
      case StrayKind::far:
        break;
    }
  const double far = far_cost(unexplained, spots);
  delta += far_charge(h.map_costs.far_strays, far, beyond) - far;
  for (const auto& [l, c] : lamp_costs)
    delta += charge_misfit(h.map_costs.misfits, l, c, o_->lamp_out_cost) - c;
  return delta;
}

double HypothesisWeigher::misfit(double score, int missing, int unexplained) const {
  const LampPairOptions& q = omni_->options().pairs;
  return score - q.miss_cost * missing - q.spurious_cost * unexplained;
}

bool HypothesisWeigher::odd(double score, int expected, int missing, int unexplained) const {
  return misfit(score, missing, unexplained) >
         std::max(o_->odd_image_misfit, o_->odd_image_misfit_per_lamp * (expected - missing));
}

Eigen::Matrix3d HypothesisWeigher::measurement_covariance(const PoseHypothesis& p) const {
  Eigen::Matrix3d R = p.covariance;
  R.diagonal() += Eigen::Vector3d(o_->omni_bump_sigma_m * o_->omni_bump_sigma_m,
                                  o_->omni_bump_sigma_m * o_->omni_bump_sigma_m,
                                  std::pow(o_->omni_bump_sigma_deg * kDeg, 2));
  return R;
}

std::optional<std::pair<PoseHypothesis, double>> HypothesisWeigher::move_nearby(
    const Hypothesis& h, const PoseHypothesis& odd_fit, const vision::OmniDetection& d) const {
  EnumerationPrior near;
  near.poses = {h.pose};
  near.gate_m = o_->odd_image_search_m;
  near.gate_rad = o_->odd_image_search_deg * kDeg;
  // Within a gate this small a handful of poses is plenty: the best 8, from the candidates
  // screened within 10 (and the search's own 30) of the best.
  GlobalLocalization found = omni_->enumerate(d, 8, 10.0, &near);
  for (PoseHypothesis& c : found.hypotheses) {
    if (c.matches.size() < 2 || !(c.score < odd_fit.score) || odd(c)) continue;
    // The best such pose only, and only when the move is likelier for the hypothesis than the
    // contradiction it replaces (its innovation under the hypothesis's covariance less than
    // contradiction_cost): the search mends a refinement that settled beside the truth, not a
    // hypothesis that is truly off. Moves past that, tried, rescued a look-alike place and its
    // twin alike after a carry (no image then contradicted them all, and the set, not started
    // again, published the wrong one).
    Pose2 pose = h.pose;
    Eigen::Matrix3d P = h.covariance;
    const double cost = std::max(0.0, update_pose(pose, P, c.pose, measurement_covariance(c),
                                                  o_->sigma_m, o_->sigma_yaw_deg * kDeg));
    if (cost >= o_->contradiction_cost) return std::nullopt;
    return std::make_pair(std::move(c), cost);
  }
  return std::nullopt;
}

Weighed HypothesisWeigher::omni(Hypothesis& h, const vision::OmniDetection& d,
                                bool may_search) const {
  const double ps = std::clamp(sigma_position(h.covariance), 0.03, 1.5);
  const double ys = std::clamp(std::sqrt(h.covariance(2, 2)), 0.5 * kDeg, 15 * kDeg);
  std::optional<PoseHypothesis> r = omni_->refine(h.pose, ps, ys, d);
  if (r && r->matches.size() >= 2) {
    std::optional<double> move_cost;
    if (may_search && o_->odd_image_search_m > 0 && odd(*r))
      if (auto moved = move_nearby(h, *r, d)) {
        r = std::move(moved->first);
        move_cost = moved->second;
      }
    const Eigen::Matrix3d R = measurement_covariance(*r);
    // Moved, the hypothesis is where the image puts it, as sure of it as the image is, and the
    // move is charged as the Kalman update's innovation would be: a look-alike place moved onto
    // a pose that fits must not gain on one the images fitted all along.
    double innovation = 0;
    if (move_cost) {
      innovation = *move_cost;
      h.pose = r->pose;
      h.covariance = R;
    } else {
      innovation = std::max(0.0, update(h, r->pose, R));
    }
    const int seen = static_cast<int>(r->matches.size()) + r->unexplained;
    // A misfit better than expected says nothing (map_evidence.hpp, charge_misfit).
    return judged(r->score + charge_image(h, r->missed, r->unexplained, r->strays, r->lamp_costs) +
                      innovation,
                  r->score, r->expected, r->missing, seen, r->unexplained);
  }
  // Nothing to refine on: the prediction scored as it stands, with its own uncertainty.
  const GlobalLocalizer::PoseScore sc = omni_->score(h.pose, ps, ys, d);
  return judged(sc.cost + charge_image(h, sc.missed, sc.unexplained, sc.strays, sc.lamp_costs),
                sc.cost, sc.expected, sc.missing, sc.matched + sc.unexplained, sc.unexplained);
}

Weighed HypothesisWeigher::judged(double cost, double score, int expected, int missing, int seen,
                                  int unexplained) const {
  const bool contradicted = contradicts(expected, missing, seen, unexplained) ||
                            odd(score, expected, missing, unexplained) || cost > o_->odd_image_cost;
  return {contradicted ? cost + o_->contradiction_cost : cost, contradicted};
}

double HypothesisWeigher::unlabelled(Hypothesis& h, const vision::LampDetection& d) const {
  const std::optional<Eigen::Vector2d> base = geometry_->base_point(d.centre, lamp_height_);
  if (!base) return o_->ceiling_spurious_cost;
  const Eigen::Vector2d at = h.pose.transform_from(*base);
  const std::vector<const graph::Lamp*> near = map_->lamps_within(at, o_->stray_radius_m);
  if (!near.empty())
    return charge_account(account_of(h.map_costs.misfits, near.front()), o_->ceiling_spurious_cost,
                          o_->lamp_out_cost);
  return charge_stray(h.map_costs.strays, at, o_->stray_radius_m, o_->ceiling_spurious_cost,
                      o_->unmapped_lamp_cost);
}

Weighed HypothesisWeigher::ceiling(Hypothesis& h,
                                   const std::vector<vision::LampDetection>& lamps) const {
  std::vector<LabelledLamp> labelled;
  std::set<LampId> taken;
  Eigen::Matrix3d label_covariance = h.covariance;
  if (!h.ceiling_fitted) {
    const double floor = o_->ceiling_label_sigma_m * o_->ceiling_label_sigma_m;
    for (int k = 0; k < 2; ++k) label_covariance(k, k) = std::max(label_covariance(k, k), floor);
  }
  double cost = 0;
  bool unexplained = false;
  for (const auto& d : lamps) {
    if (d.view == vision::LampView::partial) continue;
    const LabelResult r = labeller_->label(d, h.pose, label_covariance, taken);
    if (r.outcome == LabelOutcome::labelled) {
      labelled.push_back({r.lamp, d});
      taken.insert(r.lamp->id);
    } else if (r.outcome == LabelOutcome::no_candidate) {
      cost += unlabelled(h, d);
      unexplained = true;
    }
  }
  h.unexplained_frames = (h.unexplained_frames << 1) | (unexplained ? 1u : 0u);
  if (!lamps.empty())  // a dark frame says nothing of missing lamps
    cost += charge_absences(
        h.map_costs.lamps,
        unseen_lamps(*map_, *camera_, *geometry_, *kind_, lamps, h.pose, h.covariance),
        o_->ceiling_miss_cost, o_->lamp_out_cost);
  if (!labelled.empty()) {
    PoseRefusal refusal = PoseRefusal::none;
    const std::optional<PoseMeasurement> m = measure_pose(*geometry_, *camera_, labelled, h.pose,
                                                          Stamp{}, measurement_, nullptr, &refusal);
    // The ceiling camera places a lamp to a few millimetres, so a fit's misfit is mostly the
    // map's error (a lamp a few centimetres off), the same in every frame: counted, it made one
    // of two look-alike places certain within a second. Only a misfit past what the map's errors
    // explain (fit_gate_) says the hypothesis is off, charged to the lamps it was fit to.
    if (m) {
      h.ceiling_fitted = true;
      const double misfit = update(h, m->pose, m->covariance) + 3.0 - fit_gate_;
      if (misfit > 0) {
        std::vector<const graph::Lamp*> from;
        for (const LabelledLamp& l : labelled) from.push_back(l.lamp);
        cost += charge_fit(h.map_costs.misfits, from, misfit, o_->lamp_out_cost);
      }
    } else if (refusal == PoseRefusal::labels_disagree) {
      cost += o_->ceiling_spurious_cost;
    }
  }
  return {cost, std::nullopt};
}

}  // namespace lampnav::fusion::detail
