// The hypothesis set's options checked, and its enums in words (hypothesis_set.hpp).
#include <string>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/hypothesis_set.hpp"

namespace lampnav::fusion {

const char* to_string(HypothesisOrigin o) { return o == HypothesisOrigin::kept ? "kept" : "omni"; }

const char* to_string(HypothesisVerdict v) {
  switch (v) {
    case HypothesisVerdict::empty:
      return "empty";
    case HypothesisVerdict::incomplete:
      return "incomplete";
    case HypothesisVerdict::ambiguous:
      return "ambiguous";
    case HypothesisVerdict::symmetric:
      return "symmetric";
    case HypothesisVerdict::decided:
      return "decided";
  }
  return "?";
}

void HypothesisSetOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"", "hypothesis set options", field}, what);
  };
  check(publish_posterior > 0.5 && publish_posterior < 1, "publish_posterior",
        "must be between 0.5 and 1");
  check(publish_ratio >= 1, "publish_ratio", "must be at least 1");
  check(min_omni_frames >= 1, "min_omni_frames", "must be at least 1");
  check(partial_view_travel_m >= 0 && std::isfinite(partial_view_travel_m), "partial_view_travel_m",
        "must be a finite distance, at least 0");
  check(max_hypotheses >= 1 && max_hypotheses <= 100000, "max_hypotheses", "must be 1 to 100000");
  check(place_gate_m > 0 && place_gate_deg > 0, "place_gate_m", "must be positive");
  check(place_cost_max >= frame_cost_cap, "place_cost_max", "must be at least frame_cost_cap");
  check(stale_places_cost > 0, "stale_places_cost", "must be positive");
  check(place_allowance >= 0 && place_allowance < frame_cost_cap, "place_allowance",
        "must be in [0, frame_cost_cap)");
  check(drop_ratio > 0 && drop_ratio < 1e-3, "drop_ratio", "must be in (0, 0.001)");
  check(birth_ratio >= drop_ratio && birth_ratio < 1, "birth_ratio", "must be in [drop_ratio, 1)");
  check(symmetry_check_max >= 2, "symmetry_check_max", "must be at least 2");
  check(station_m >= 0, "station_m", "must not be negative");
  check(enumerate_every_m >= 0 && enumerate_every_deg >= 0, "enumerate_every_m",
        "must not be negative");
  check(frame_cost_cap > 0, "frame_cost_cap", "must be positive");
  check(odd_image_misfit > 0, "odd_image_misfit", "must be positive");
  check(odd_image_misfit_per_lamp >= 0 && std::isfinite(odd_image_misfit_per_lamp),
        "odd_image_misfit_per_lamp", "must be finite and not negative");
  check(odd_image_search_m >= 0 && odd_image_search_m <= 5, "odd_image_search_m",
        "must be 0 to 5 m");
  check(odd_image_search_deg > 0 && odd_image_search_deg <= 45, "odd_image_search_deg",
        "must be more than 0 and at most 45 degrees");
  check(odd_image_search_hypotheses >= 1, "odd_image_search_hypotheses", "must be at least 1");
  check(odd_image_cost > 0, "odd_image_cost", "must be positive");
  check(contradiction_cost >= 0 && std::isfinite(contradiction_cost), "contradiction_cost",
        "must be finite and not negative");
  check(ceiling_cost_cap > 0, "ceiling_cost_cap", "must be positive");
  check(birth_sigma_m > 0 && birth_sigma_deg > 0, "birth_sigma_m", "must be positive");
  check(kept_prior > 0 && kept_prior < 1, "kept_prior", "must be in (0, 1)");
  check(merge_m > 0 && merge_deg > 0, "merge_m", "must be positive");
  check(sigma_m > 0 && sigma_per_m >= 0 && sigma_yaw_deg > 0 && sigma_yaw_deg_per_m >= 0, "sigma_m",
        "odometry sigmas must be positive");
  check(wall_margin_m >= 0, "wall_margin_m", "must not be negative");
  check(omni_bump_sigma_m >= 0 && omni_bump_sigma_deg >= 0, "omni_bump_sigma_m",
        "must not be negative");
  check(ceiling_miss_cost >= 0 && ceiling_spurious_cost >= 0, "ceiling_miss_cost",
        "must not be negative");
  check(ceiling_label_sigma_m >= 0 && std::isfinite(ceiling_label_sigma_m), "ceiling_label_sigma_m",
        "must be finite and not negative");
  check(lamp_out_cost >= 0, "lamp_out_cost", "must not be negative");
  check(unmapped_lamp_cost >= 0, "unmapped_lamp_cost", "must not be negative");
  check(stray_radius_m > 0, "stray_radius_m", "must be positive");
  check(stray_reach_max_m >= 0, "stray_reach_max_m", "must not be negative");
  check(far_stray_cost_max >= 0, "far_stray_cost_max", "must not be negative");
  check(beyond_map_blob_cost >= 0 && std::isfinite(beyond_map_blob_cost), "beyond_map_blob_cost",
        "must be finite and not negative");
  check(map_sigma_m >= 0, "map_sigma_m", "must not be negative");
  check(row_beside_m >= 0 && row_beside_m <= 10, "row_beside_m", "must be 0 to 10 m");
  check(row_beside_min_lamps >= 3, "row_beside_min_lamps", "must be at least 3");
  check(row_beside_memory_m >= 0 && std::isfinite(row_beside_memory_m), "row_beside_memory_m",
        "must be a finite distance, at least 0");
  check(row_beside_images >= 1 && row_beside_images <= 20, "row_beside_images",
        "must be 1 to 20 images");
  check(row_beside_reach_m > 0 && std::isfinite(row_beside_reach_m), "row_beside_reach_m",
        "must be a positive distance");
  check(unexplained_window >= 1 && unexplained_window <= 32, "unexplained_window",
        "must be 1 to 32 frames");
  check(publish_unexplained_frames >= 0 && publish_unexplained_frames <= unexplained_window,
        "publish_unexplained_frames", "must be 0 to unexplained_window");
  check(fit_gate_probability > 0 && fit_gate_probability < 1, "fit_gate_probability",
        "must be in (0, 1)");
  check(omni_tie_cost >= 0 && omni_tie_cost < frame_cost_cap, "omni_tie_cost",
        "must be in [0, frame_cost_cap)");
}

}  // namespace lampnav::fusion
