#include "lampnav/fusion/kidnap_monitor.hpp"

#include "ceiling_rays.hpp"
#include "spurious_blobs.hpp"

#include <algorithm>
#include <cmath>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/chi_square.hpp"

namespace lampnav::fusion {

using Eigen::Vector3d;

void KidnapMonitorOptions::validate() const {
  auto fail = [](const char* field, const char* msg) {
    throw InputError({"", "kidnap monitor options", field}, msg);
  };
  if (window_frames < 1 || window_frames > 1000) fail("window_frames", "must be 1 to 1000");
  if (contradicting_frames < 1 || contradicting_frames > window_frames)
    fail("contradicting_frames", "must be 1 to window_frames");
  if (missing_support_frames < 1 || missing_support_frames > window_frames)
    fail("missing_support_frames", "must be 1 to window_frames");
  if (nis_window < 1 || nis_window > 60) fail("nis_window", "must be 1 to 60");
  if (!(nis_probability > 0.5 && nis_probability < 1))
    fail("nis_probability", "must be between 0.5 and 1");
  if (omni_failures < 1 || omni_failures > 100) fail("omni_failures", "must be 1 to 100");
  if (omni_strong_expected < 1) fail("omni_strong_expected", "must be at least 1");
  if (!(omni_strong_fraction >= 0 && omni_strong_fraction < 1))
    fail("omni_strong_fraction", "must be 0 to 1");
}

void OmniCheckOptions::validate() const {
  auto fail = [](const char* field, const char* msg) {
    throw InputError({"", "omni check options", field}, msg);
  };
  if (!(max_theta_deg > 0 && max_theta_deg < 90)) fail("max_theta_deg", "must be 0 to 90");
  if (!(detection_sigma_deg > 0 && detection_sigma_deg < 10))
    fail("detection_sigma_deg", "must be 0 to 10");
  if (!(tilt_sigma_deg >= 0 && tilt_sigma_deg < 10)) fail("tilt_sigma_deg", "must be 0 to 10");
  if (!(max_position_sigma > 0)) fail("max_position_sigma", "must be positive");
  if (min_expected < 1) fail("min_expected", "must be at least 1");
  if (!(min_match_fraction > 0 && min_match_fraction <= 1))
    fail("min_match_fraction", "must be 0 to 1");
}

OmniCheck::OmniCheck(const graph::TopologicalMap& map, const CameraDescription& camera,
                     const OmniCheckOptions& options)
    : map_(&map),
      mount_R_(camera.mount.rotation()),
      mount_t_(camera.mount.xyz),
      o_(options),
      configured_tilt_deg_(options.tilt_sigma_deg),
      lamp_height_(detail::usual_lamp_height(map, camera.mount.xyz.z())),
      min_blob_per_cos_(detail::spurious_blob_limit(map, camera.mount.xyz.z())) {
  o_.validate();
  if (!is_fisheye(camera.model))
    throw Error("the omni check needs a fisheye camera, '" + camera.name + "' is not");
  for (const auto& n : map.nodes())
    for (const auto& l : n.lamps) lamps_.push_back(&l);
}

OmniCheckResult OmniCheck::check(const Pose2& pose, const Eigen::Matrix3d& P,
                                 const std::vector<vision::OmniBlob>& blobs) const {
  OmniCheckResult r;
  const double sigma_xy = std::sqrt(std::max(P(0, 0), P(1, 1)));
  const double sigma_yaw = std::sqrt(P(2, 2));
  if (!(sigma_xy <= o_.max_position_sigma) || !(sigma_yaw < 0.35)) return r;
  const double max_theta = o_.max_theta_deg * M_PI / 180;
  // Predicted rays in the camera frame (level floor: bumps are in the tolerance).
  const double c = std::cos(pose.yaw()), s = std::sin(pose.yaw());
  struct Predicted {
    Vector3d ray;
    double tolerance;
  };
  std::vector<Predicted> predicted;
  std::vector<Vector3d> all;
  std::vector<double> all_tolerance;
  for (const graph::Lamp* l : lamps_) {
    const Vector3d d = l->xyz - Vector3d(pose.x(), pose.y(), 0);
    const Vector3d base(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
    const Vector3d cam = mount_R_.transpose() * (base - mount_t_);
    const double range = cam.norm();
    if (!(range > 0.1)) continue;
    const Vector3d ray = cam / range;
    const double theta = std::acos(std::clamp(ray.z(), -1.0, 1.0));
    if (theta > max_theta + 0.2) continue;
    const double det = o_.detection_sigma_deg * M_PI / 180, tilt = o_.tilt_sigma_deg * M_PI / 180;
    const double pos = sigma_xy / range, yaw = sigma_yaw * std::sin(theta);
    const double tolerance = 3 * std::sqrt(det * det + tilt * tilt + pos * pos + yaw * yaw);
    all.push_back(ray);
    all_tolerance.push_back(tolerance);
    if (theta <= max_theta) predicted.push_back({ray, tolerance});
  }
  // Lamps too close to another in direction are left out: their blobs merge.
  std::vector<Predicted> clear;
  for (const auto& p : predicted) {
    bool crowded = false;
    for (const Vector3d& q : all) {
      const double a = std::acos(std::clamp(p.ray.dot(q), -1.0, 1.0));
      if (a > 1e-9 && a < 2 * p.tolerance + 0.05) crowded = true;
    }
    if (!crowded) clear.push_back(p);
  }
  // The blobs some map lamp explains; and, of the others, those whose ray meets the ceiling
  // inside one of the map's places. A blob beyond every place says nothing against the estimate:
  // a map built from one drive holds the corridors it took, not the building, and at a junction
  // the drive passed straight through, the other corridors' lamps are most of the view (the
  // robot, tracked 1 cm off, was called lost there, then fixed 17 m off; docs/hypotheses.md).
  const auto explained = [&](const vision::OmniBlob& b) {
    for (std::size_t k = 0; k < all.size(); ++k)
      if (std::acos(std::clamp(all[k].dot(b.ray), -1.0, 1.0)) <=
          all_tolerance[k] + b.angular_radius)
        return true;
    return false;
  };
  const auto in_map = [&](const vision::OmniBlob& b) {
    const std::optional<Vector3d> base =
        detail::ceiling_point(mount_R_, mount_t_, b.ray, lamp_height_);
    return !base || map_->node_containing(pose.transform_from(base->head<2>())) != nullptr;
  };
  std::vector<const vision::OmniBlob*> used;
  for (const auto& b : blobs) {
    if (b.theta > max_theta + 0.1 ||
        detail::is_spurious_blob(min_blob_per_cos_, b.theta, b.angular_radius))
      continue;
    if (explained(b)) {
      ++r.explained_blobs;
    } else if (!o_.count_beyond_map && !in_map(b)) {
      ++r.beyond_map;
      continue;
    }
    used.push_back(&b);
  }
  r.blobs = static_cast<int>(used.size());
  r.expected = static_cast<int>(clear.size());
  const bool lamp_side = r.expected >= o_.min_expected, blob_side = r.blobs >= o_.min_expected;
  if (!lamp_side && !blob_side) return r;
  // One-to-one: candidate pairs inside their tolerance, nearest first.
  struct Pair {
    double angle;
    int p, b;
  };
  std::vector<Pair> pairs;
  for (int i = 0; i < r.expected; ++i)
    for (int j = 0; j < r.blobs; ++j) {
      const double a = std::acos(std::clamp(clear[i].ray.dot(used[j]->ray), -1.0, 1.0));
      // A big blob (a near lamp's bloom, lamps merged) has its centroid anywhere inside it.
      if (a <= clear[i].tolerance + used[j]->angular_radius) pairs.push_back({a, i, j});
    }
  std::sort(pairs.begin(), pairs.end(),
            [](const Pair& a, const Pair& b) { return a.angle < b.angle; });
  std::vector<char> p_used(clear.size(), 0), b_used(used.size(), 0);
  for (const Pair& q : pairs) {
    if (p_used[q.p] || b_used[q.b]) continue;
    p_used[q.p] = b_used[q.b] = 1;
    ++r.matched;
  }
  // Each side speaks when it has enough to say: the lamps predicted, the blobs seen.
  r.conclusive = true;
  r.lamp_side = lamp_side;
  r.blob_side = blob_side;
  r.consistent = (!lamp_side || r.match_fraction() >= o_.min_match_fraction) &&
                 (!blob_side || r.explained_fraction() >= o_.min_match_fraction);
  return r;
}

void OmniCheck::scale_tilt(double factor) {
  if (!(factor >= 1 && std::isfinite(factor)))
    throw InputError({"", "omni check", "tilt factor"}, "must be at least 1");
  o_.tilt_sigma_deg = configured_tilt_deg_ * factor;
}

KidnapMonitor::KidnapMonitor(const KidnapMonitorOptions& options) : o_(options) {
  o_.validate();
  nis_limit_ = chi_square_quantile(o_.nis_probability, 3 * o_.nis_window);
}

void KidnapMonitor::reset() {
  window_.clear();
  nis_.clear();
  nis_sum_ = 0;
  omni_bad_ = 0;
}

const char* to_string(ModeCause cause) {
  switch (cause) {
    case ModeCause::ceiling_contradicts:
      return "ceiling_contradicts";
    case ModeCause::innovations_do_not_fit:
      return "innovations_do_not_fit";
    case ModeCause::omni_disagrees:
      return "omni_disagrees";
    case ModeCause::omni_locates_elsewhere:
      return "omni_locates_elsewhere";
    case ModeCause::odometry_gap:
      return "odometry_gap";
    case ModeCause::moved_unseen:
      return "moved_unseen";
    case ModeCause::hypotheses_undecided:
      return "hypotheses_undecided";
    case ModeCause::initialized:
      return "initialized";
    case ModeCause::global_fix:
      return "global_fix";
    case ModeCause::confirmed:
      return "confirmed";
  }
  return "?";
}

std::optional<LossVerdict> KidnapMonitor::ceiling(const CeilingEvidence& e) {
  ++counts_.frames;
  counts_.unexplained_lamps += e.unexplained;
  counts_.missing_lamps += e.expected_missing;
  if (e.contradicts()) ++counts_.contradicting_frames;
  window_.push_back(e);
  while (static_cast<int>(window_.size()) > o_.window_frames) window_.pop_front();
  int contradicting = 0, missing = 0, unexplained = 0;
  for (const auto& w : window_) {
    contradicting += w.contradicts() ? 1 : 0;
    missing += (w.expected_missing > 0 && w.labelled == 0) ? 1 : 0;
    unexplained += w.unexplained;
  }
  const bool lost = contradicting >= o_.contradicting_frames ||
                    (contradicting >= 2 && missing >= o_.missing_support_frames);
  if (!lost) return std::nullopt;
  ++counts_.losses;
  std::string why = std::to_string(contradicting) + " of the last " +
                    std::to_string(window_.size()) + " ceiling frames contradict the map (" +
                    std::to_string(unexplained) + " lamps where the map has none";
  if (missing > 0) why += ", " + std::to_string(missing) + " frames missing predicted lamps";
  why += ")";
  reset();
  return LossVerdict{ModeCause::ceiling_contradicts, why};
}

std::optional<LossVerdict> KidnapMonitor::innovation(double d2) {
  if (!std::isfinite(d2)) d2 = 1e9;
  nis_.push_back(d2);
  nis_sum_ += d2;
  while (static_cast<int>(nis_.size()) > o_.nis_window) {
    nis_sum_ -= nis_.front();
    nis_.pop_front();
  }
  if (static_cast<int>(nis_.size()) < o_.nis_window || nis_sum_ <= nis_limit_) return std::nullopt;
  ++counts_.nis_alarms;
  ++counts_.losses;
  const std::string why = "the last " + std::to_string(o_.nis_window) +
                          " measurements do not fit (NIS sum " + std::to_string(nis_sum_) + " > " +
                          std::to_string(nis_limit_) + ")";
  reset();
  return LossVerdict{ModeCause::innovations_do_not_fit, why};
}

std::optional<LossVerdict> KidnapMonitor::omni(const OmniCheckResult& r) {
  if (!r.conclusive) return std::nullopt;
  ++counts_.omni_checks;
  if (r.consistent) {
    omni_bad_ = 0;
    return std::nullopt;
  }
  ++counts_.omni_inconsistent;
  // Both ways wrong: most predicted lamps unseen and most blobs where no lamp is predicted.
  const bool strong = r.blobs >= o_.omni_strong_expected &&
                      r.explained_fraction() <= o_.omni_strong_fraction &&
                      (!r.lamp_side || r.match_fraction() <= o_.omni_strong_fraction);
  if (++omni_bad_ < o_.omni_failures && !strong) return std::nullopt;
  ++counts_.losses;
  const std::string why = "the omnidirectional view does not match the estimate (" +
                          std::to_string(r.matched) + " of " + std::to_string(r.expected) +
                          " predicted lamps seen, " + std::to_string(omni_bad_) +
                          " checks in a row)";
  reset();
  return LossVerdict{ModeCause::omni_disagrees, why};
}

}  // namespace lampnav::fusion
