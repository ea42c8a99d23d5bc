// Method `default`: pairs of blobs matched to pairs of map lamps spaced alike vote for poses;
// those inside the graph's regions are scored, the best refined, ranked and weighed.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "global_localizer_impl.hpp"

namespace lampnav::fusion {

using namespace detail;

GlobalLocalization GlobalLocalizer::Impl::lamp_pairs(const vision::OmniDetection& d) const {
  const LampPairOptions& q = o.pairs;
  GlobalLocalization out;
  out.method = GlobalMethod::lamp_pairs;
  const std::vector<BlobRay> blobs = blob_rays(d, q.max_theta_deg * kDeg);
  out.blobs = static_cast<int>(blobs.size());
  // Detections for pairs: nearest the optical axis, where a ray says most about position.
  std::vector<BlobRay> seeds;
  for (const BlobRay& b : blobs)
    if (b.theta <= q.pair_max_theta_deg * kDeg && (mount_R * b.ray).z() > 0.05) seeds.push_back(b);
  std::sort(seeds.begin(), seeds.end(),
            [](const BlobRay& a, const BlobRay& b) { return a.theta < b.theta; });
  if (seeds.size() > std::size_t(q.pair_max_blobs)) seeds.resize(q.pair_max_blobs);
  if (seeds.size() < 2) {
    out.why = std::to_string(seeds.size()) + " lamp(s) within " +
              std::to_string(int(q.pair_max_theta_deg)) +
              " degrees of the optical axis: a pose needs two";
    return out;
  }
  // Where each seed puts each lamp, in the base frame, were it that lamp.
  const double sa = std::hypot(q.detection_sigma_deg, q.tilt_sigma_deg) * kDeg;
  const std::size_t nl = lamps.size(), ns = seeds.size();
  std::vector<Vector2d> at(ns * nl);
  std::vector<double> sigma(ns * nl, -1);
  for (std::size_t j = 0; j < ns; ++j) {
    const Vector3d rb = mount_R * seeds[j].ray;
    for (std::size_t i = 0; i < nl; ++i) {
      const double h = lamps[i]->xyz.z() - mount_t.z();
      if (h < 0.2) continue;
      const double s = h / rb.z();
      at[j * nl + i] = mount_t.head<2>() + s * rb.head<2>();
      const double sj = h * sa / (rb.z() * rb.z()) + 0.1 * lamps[i]->length;
      // A seed that puts the lamp no better than this says nothing of the pose.
      if (sj <= 0.5) sigma[j * nl + i] = sj;
    }
  }
  // Vote: every pair of seeds matched to a pair of lamps at the same spacing is a pose.
  struct Cell {
    int votes = 0;
    double x = 0, y = 0, c = 0, s = 0;
  };
  std::unordered_map<std::int64_t, Cell> cells;
  const double cell_m = 0.25, cell_rad = 3 * kDeg;
  for (std::size_t j = 0; j < ns; ++j)
    for (std::size_t k = j + 1; k < ns; ++k)
      for (std::size_t i = 0; i < nl; ++i) {
        if (sigma[j * nl + i] < 0) continue;
        const Vector2d& qi = at[j * nl + i];
        for (std::size_t l = 0; l < nl; ++l) {
          if (l == i || sigma[k * nl + l] < 0) continue;
          const Vector2d& ql = at[k * nl + l];
          const Vector2d D = lamps[l]->xyz.head<2>() - lamps[i]->xyz.head<2>();
          const Vector2d dq = ql - qi;
          const double dn = dq.norm(), Dn = D.norm();
          const double tol = 3 * std::hypot(sigma[j * nl + i], sigma[k * nl + l]) + 0.02;
          if (std::abs(dn - Dn) > tol || Dn < 0.2) continue;
          const double yaw = wrap_angle(std::atan2(D.y(), D.x()) - std::atan2(dq.y(), dq.x()));
          const double c = std::cos(yaw), s = std::sin(yaw);
          const Vector2d mid_q = 0.5 * (qi + ql);
          const Vector2d mid_L = 0.5 * (lamps[l]->xyz.head<2>() + lamps[i]->xyz.head<2>());
          const Vector2d p =
              mid_L - Vector2d(c * mid_q.x() - s * mid_q.y(), s * mid_q.x() + c * mid_q.y());
          const std::int64_t key = (std::int64_t(std::floor(p.x() / cell_m)) * 1000003 +
                                    std::int64_t(std::floor(p.y() / cell_m))) *
                                       1009 +
                                   std::int64_t(std::floor((yaw + M_PI) / cell_rad));
          Cell& cell = cells[key];
          ++cell.votes;
          cell.x += p.x();
          cell.y += p.y();
          cell.c += c;
          cell.s += s;
        }
      }
  std::vector<std::pair<int, Pose2>> voted;
  voted.reserve(cells.size());
  for (const auto& [key, cell] : cells)
    voted.emplace_back(cell.votes,
                       Pose2(cell.x / cell.votes, cell.y / cell.votes, std::atan2(cell.s, cell.c)));
  std::sort(voted.begin(), voted.end(), [](const auto& a, const auto& b) {
    if (a.first != b.first) return a.first > b.first;
    const Vector3d u = a.second.vector(), v = b.second.vector();
    return std::lexicographical_compare(u.data(), u.data() + 3, v.data(), v.data() + 3);
  });
  // The graph: a robot stands in a node's region.
  std::vector<std::pair<double, Pose2>> scored;
  int outside = 0;
  for (const auto& [votes, pose] : voted) {
    if (int(scored.size()) >= q.candidates) break;
    if (q.restrict_to_graph && has_regions && !node_of(pose)) {
      ++outside;
      continue;
    }
    scored.emplace_back(evaluate(pose, {}, 0.3, 3 * kDeg, q.tilt_sigma_deg * kDeg, blobs).cost,
                        pose);
  }
  out.merit_evaluations = static_cast<int>(scored.size());
  if (scored.empty()) {
    out.why = voted.empty() ? "no pair of map lamps is spaced like any pair of the " +
                                  std::to_string(ns) + " lamps seen"
                            : "every pose the lamps suggest lies outside the map's regions";
    return out;
  }
  std::stable_sort(scored.begin(), scored.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  if (scored.size() > std::size_t(q.refined)) scored.resize(q.refined);
  std::vector<PoseHypothesis> refined;
  for (const auto& [cost, pose] : scored) {
    PoseHypothesis h = refine(pose, 0.3, 3 * kDeg, blobs);
    if (q.restrict_to_graph && has_regions && !node_of(h.pose)) continue;
    refined.push_back(std::move(h));
  }
  finish(out, refined, d);
  return out;
}

}  // namespace lampnav::fusion
