// Global localization: one pose scored against an omni image's blobs (the lamps the pose predicts
// in view, paired with the blobs, what is missed and what is left unexplained). The search, the
// least squares and the API: global_localizer.cpp.

#include <algorithm>
#include <cmath>
#include <vector>

#include "ceiling_rays.hpp"
#include "global_localizer_impl.hpp"
#include "spurious_blobs.hpp"

namespace lampnav::fusion {

using detail::kDeg;

namespace {

// A lamp as a pose predicts it in the omni view, and a lamp-blob pair (evaluate()).
struct Predicted {
  Eigen::Vector3d ray;
  double z, sigma, half_size;  // z: the cosine of the angle off the axis
  int lamp;
  bool matched = false;
};
struct Pair {
  double cost;
  int p, b;
};

// evaluate()'s working storage, one per thread and kept between calls: seed 5066 of the
// 1,000-node kidnaps scores some 155,000 poses in its 105 m, and malloc and free took about 5 %
// of its time (perf) before.
struct EvaluationScratch {
  std::vector<int> in_view;
  std::vector<Predicted> pred;
  std::vector<Pair> pairs, taken, left;
  std::vector<char> explained, b_used;
  std::vector<double> blob_term, nearest;
  std::vector<int> nearest_lamp;
  std::vector<int> first_of_lamp, first_of_blob;
  detail::RayGrid grid;
};
thread_local EvaluationScratch scratch;

}  // namespace

GlobalLocalizer::Impl::Evaluation GlobalLocalizer::Impl::evaluate(
    const Pose2& pose, const Tilt& tilt, double position_sigma, double yaw_sigma, double tilt_sigma,
    const std::vector<BlobRay>& blobs, double screen_theta, bool itemized) const {
  const LampPairOptions& q = o.pairs;
  const double max_theta = screen_theta > 0 ? screen_theta : q.max_theta_deg * kDeg;
  const double expect_theta = screen_theta > 0 ? screen_theta : q.expect_max_theta_deg * kDeg;
  const double radius = screen_theta > 0
                            ? max_height * std::tan(std::min(screen_theta, 89.0 * kDeg)) +
                                  mount_t.head<2>().norm() + 3.0
                            : 0.0;
  const double det = q.detection_sigma_deg * kDeg;
  const double cos_limit = std::cos(std::min(M_PI, max_theta + 0.1));
  // Angles off the axis compared as cosines: no arc cosine per lamp.
  const double cos_max = std::cos(max_theta), cos_expect = std::cos(expect_theta);
  EvaluationScratch& x = scratch;
  std::vector<Predicted>& pred = x.pred;
  pred.clear();
  const Vector2d mount_xy = pose.transform_from(mount_t.head<2>());
  const Vector3d camera_at(mount_xy.x(), mount_xy.y(), mount_t.z());
  const CameraView view(*this, pose, tilt);
  lamps_in_view(pose, radius, x.in_view);
  for (const int i : x.in_view) {
    const Vector3d c = view.point(lamps[i]->xyz);
    const double range = c.norm();
    if (!(range > 0.1)) continue;
    const Vector3d ray = c / range;
    if (ray.z() < cos_limit) continue;
    const double z = std::clamp(ray.z(), -1.0, 1.0);
    const double face = face_sigma(*lamps[i], range);
    // A turn moves a ray by the sine of its angle off the axis.
    const double pos = position_sigma / range, yaw = yaw_sigma * std::sqrt(1 - z * z);
    const double sigma =
        std::sqrt(det * det + tilt_sigma * tilt_sigma + pos * pos + yaw * yaw + face * face);
    const Vector3d sight = (lamps[i]->xyz - camera_at) / range;
    pred.push_back({ray, z, sigma, blob_half_size(i, sight, range), i});
  }
  // Lamp-blob pairs within 3 sigma. A blob far out in the image is small, and only the blobs
  // near a lamp's ray are tried: those of the ray grid's cells within its reach (taken with the
  // largest small blob), and the large blobs (a lamp overhead), each against every lamp.
  std::vector<Pair>& pairs = x.pairs;
  pairs.clear();
  std::vector<char>& explained = x.explained;
  explained.assign(blobs.size(), 0);
  std::vector<double>& blob_term = x.blob_term;
  blob_term.resize(blobs.size());
  std::vector<double>& nearest = x.nearest;  // each blob's least d2 to a lamp (explained ones)
  nearest.assign(blobs.size(), 9.0);
  std::vector<int>& nearest_lamp = x.nearest_lamp;  // and its lamp (index into lamps)
  nearest_lamp.assign(blobs.size(), -1);
  for (std::size_t j = 0; j < blobs.size(); ++j)
    blob_term[j] = 0.25 * blobs[j].angular_radius * blobs[j].angular_radius;
  detail::RayGrid& near = x.grid;
  near.build(blobs);
  for (std::size_t i = 0; i < pred.size(); ++i) {
    const double sigma2 = pred[i].sigma * pred[i].sigma;
    near.visit(pred[i].ray, 3 * std::sqrt((1 + 1e-9) * (sigma2 + near.largest_term())), [&](int j) {
      const double s2 = sigma2 + blob_term[j];
      const double chord2 = (pred[i].ray - blobs[j].ray).squaredNorm();
      if (chord2 > 9.0 * (1 + 1e-9) * s2) return;  // beyond 3 sigma, rounding aside
      const double d2 = chord2 / s2;
      if (d2 <= 9.0) {
        explained[j] = 1;
        if (d2 < nearest[j] || nearest_lamp[j] < 0) {
          nearest[j] = d2;
          nearest_lamp[j] = pred[i].lamp;
        }
        if (pred[i].z >= cos_max) pairs.push_back({d2, int(i), int(j)});
      }
    });
  }
  // One to one, nearest first: the pairs in order, each taken unless its lamp or blob is. A pair
  // that is the first of its lamp's and of its blob's is always taken, and the pairs it shuts
  // out are all after it: those are taken at once, and only the pairs left are sorted (most
  // lamps have one blob near, so a few). The pairs taken are then summed in order, as before.
  // `before` orders every pair, so the order the grid found them in does not matter.
  const auto before = [](const Pair& a, const Pair& b) {
    return a.cost < b.cost || (a.cost == b.cost && (a.p < b.p || (a.p == b.p && a.b < b.b)));
  };
  std::vector<int>& first_of_lamp = x.first_of_lamp;
  std::vector<int>& first_of_blob = x.first_of_blob;
  first_of_lamp.assign(pred.size(), -1);
  first_of_blob.assign(blobs.size(), -1);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    int& fl = first_of_lamp[pairs[k].p];
    if (fl < 0 || before(pairs[k], pairs[fl])) fl = int(k);
    int& fb = first_of_blob[pairs[k].b];
    if (fb < 0 || before(pairs[k], pairs[fb])) fb = int(k);
  }
  std::vector<char>& b_used = x.b_used;
  b_used.assign(blobs.size(), 0);
  std::vector<Pair>& taken = x.taken;
  std::vector<Pair>& left = x.left;
  taken.clear();
  left.clear();
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (first_of_lamp[pairs[k].p] == int(k) && first_of_blob[pairs[k].b] == int(k)) {
      taken.push_back(pairs[k]);
      pred[pairs[k].p].matched = true;
      b_used[pairs[k].b] = 1;
    }
  for (const Pair& p : pairs)
    if (!pred[p.p].matched && !b_used[p.b]) left.push_back(p);
  std::sort(left.begin(), left.end(), before);
  for (const Pair& p : left) {
    if (pred[p.p].matched || b_used[p.b]) continue;
    pred[p.p].matched = true;
    b_used[p.b] = 1;
    taken.push_back(p);
  }
  std::sort(taken.begin(), taken.end(), before);
  Evaluation e;
  e.cost = 0;
  e.matches.reserve(taken.size());
  // Blobs in clear view cost their match. Past it, where lamps may go unmatched at no cost
  // (hidden, merged with a neighbour's bloom near the horizon), each blob costs its distance to
  // the nearest lamp, matched or not. Were only the matches to cost there, a place whose far view
  // matched fewer blobs would cost less: under a 4 m ceiling, with 200 blobs a frame, a twin 40 m
  // off matched 50 fewer than the truth and cost 2 to 4 less a frame. A far blob's cost is
  // capped (far_blob_cost_max): one that fits its lamp badly may be a light no lamp explains.
  for (const Pair& p : taken) {
    if (blobs[p.b].ray.z() >= cos_expect) {
      e.cost += p.cost;
      if (itemized) e.lamp_costs.emplace_back(pred[p.p].lamp, p.cost);
    }
    e.matches.emplace_back(pred[p.p].lamp, p.b);
  }
  for (std::size_t j = 0; j < blobs.size(); ++j)
    if (explained[j] && blobs[j].ray.z() < cos_expect) {
      const double c = std::min(nearest[j], q.far_blob_cost_max);
      e.cost += c;
      if (itemized) e.lamp_costs.emplace_back(nearest_lamp[j], c);
    }
  // A lamp in clear view is missing when no blob matched it; one crowded by its neighbours only
  // when no blob lies over it either: within the lamp's size and cover_sigmas of its direction's
  // sigma, widened by the blob's own size (a merged blob spans its lamps). Lamps whose blobs may
  // merge in the image are not expected to match a blob of their own, only to lie under some
  // blob (a merged blob's centre may fall between them); crowding is asked of the unmatched
  // only. Angles between unit rays are taken as chords (|a - b| = 2 sin(angle / 2)): within 1 %
  // of the angle below 14 degrees, where it matters, and no arc cosine.
  const auto crowded = [&](std::size_t a) {
    for (std::size_t b = 0; b < pred.size(); ++b) {
      const double limit = pred[a].half_size + pred[b].half_size + 6 * det + 0.02;
      if (b != a && (pred[a].ray - pred[b].ray).squaredNorm() < limit * limit) return true;
    }
    return false;
  };
  // A streak (lamps of a row merged) lies over the lamps along it, to its ends: the disc of its
  // area covers the middle of a streak running from overhead to the horizon, and the far lamps
  // of the robot's own corridor, under it, were counted missing where a twin place with no lamps
  // there was not (a regular building, docs/hypotheses.md, "Streaks").
  const auto covered = [&](const Predicted& p) {
    const double reach = p.half_size + q.cover_sigmas * p.sigma;
    for (const BlobRay& b : blobs) {
      const double cover = reach + b.angular_radius;
      if ((p.ray - b.ray).squaredNorm() < cover * cover) return true;
      if (!b.blob->streak) continue;
      const double width = reach + b.blob->streak_half_width;
      for (const Vector3d& end : b.blob->streak_ends)
        if (detail::distance_to_segment(p.ray, b.ray, end) < width) return true;
    }
    return false;
  };
  for (std::size_t a = 0; a < pred.size(); ++a) {
    const Predicted& p = pred[a];
    if (p.z < cos_expect) continue;
    ++e.expected;
    if (!p.matched && !(crowded(a) && covered(p))) {
      ++e.missing;
      e.missed.push_back(p.lamp);
    }
  }
  for (std::size_t j = 0; j < blobs.size(); ++j)
    if (!b_used[j] && !explained[j]) {
      ++e.unexplained;
      if (itemized) e.strays.push_back(static_cast<int>(j));
    }
  e.cost += q.miss_cost * e.missing + q.spurious_cost * e.unexplained;
  if (tilt_sigma > 0)
    e.cost +=
        (tilt.roll * tilt.roll + tilt.pitch * tilt.pitch) / std::pow(q.tilt_sigma_deg * kDeg, 2);
  return e;
}

}  // namespace lampnav::fusion
