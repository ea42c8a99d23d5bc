#include "omni_ways.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <unordered_map>

#include <Eigen/Eigenvalues>

#include "lampnav/core/error.hpp"

namespace lampnav::mapping {

using Eigen::Vector2d;
using Eigen::Vector3d;

void OmniLampsOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"omni lamp options", "", field}, what);
  };
  check(max_distance_m > 0 && max_distance_m <= 50, "max_distance_m", "must be 0 to 50 m");
  check(cluster_m > 0 && cluster_m <= 5, "cluster_m", "must be 0 to 5 m");
  check(max_gate_m >= cluster_m && max_gate_m <= 10, "max_gate_m", "must be cluster_m to 10 m");
  check(max_sigma_m > 0, "max_sigma_m", "must be positive");
  check(tilt_sigma_deg >= 0 && tilt_sigma_deg < 10, "tilt_sigma_deg", "must be 0 to 10 degrees");
  check(min_views >= 1, "min_views", "must be at least 1");
  check(max_keyframe_gap_s > 0, "max_keyframe_gap_s", "must be positive");
  check(max_turn > 0, "max_turn", "must be positive");
  check(fit_gate_deg > 0 && fit_gate_deg < 30, "fit_gate_deg", "must be 0 to 30 degrees");
  check(fit_min_lamps >= 2, "fit_min_lamps", "must be at least 2");
  check(fit_min_theta >= 0 && fit_min_theta < fit_max_theta && fit_max_theta <= M_PI,
        "fit_min_theta", "must be 0 to fit_max_theta, which must be at most pi");
}

namespace {

// The floor's tilt under one view (and the pose's yaw error): the small turn w (rad) of the base
// about the floor below it that best takes the mapped lamps P (level base frame) to the blobs seen
// nearest where they should be (within gate_rad). A bump tilts the robot about its wheels, so the
// camera at t moves with it (1.6 cm for half a degree 1.8 m up: a degree in the direction of a lamp
// 0.9 m above it): it sees P along P - w x P - t, and a direction q moves by
// (I - q q^T) (P x w) / |P - t|. Least squares over at least `min` matches; zero without them.
Vector3d view_turn(const std::vector<Vector3d>& blobs, const std::vector<Vector3d>& lamps,
                   const Vector3d& t, double gate_rad, int min) {
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Vector3d Atb = Vector3d::Zero();
  int matched = 0;
  const double cos_gate = std::cos(gate_rad);
  for (const Vector3d& P : lamps) {
    const Vector3d q = P - t;
    const double range = q.norm();
    const Vector3d u = q / range;
    const Vector3d* best = nullptr;
    double best_cos = cos_gate;
    for (const Vector3d& d : blobs)
      if (d.dot(u) > best_cos) {
        best_cos = d.dot(u);
        best = &d;
      }
    if (!best) continue;
    Eigen::Matrix3d cross;  // P x w = cross w
    cross << 0, -P.z(), P.y(), P.z(), 0, -P.x(), -P.y(), P.x(), 0;
    const Eigen::Matrix3d A = (Eigen::Matrix3d::Identity() - u * u.transpose()) * cross / range;
    AtA += A.transpose() * A;
    Atb += A.transpose() * (*best - u);
    ++matched;
  }
  if (matched < min) return Vector3d::Zero();
  return AtA.ldlt().solve(Atb);
}

}  // namespace

std::vector<Vector2d> lamps_seen_around(const std::vector<OmniView>& views,
                                        const std::vector<KeyframePose>& keyframes,
                                        const CameraDescription& camera, double height_m,
                                        const std::vector<Eigen::Vector3d>& mapped,
                                        const OmniLampsOptions& o) {
  o.validate();
  const Eigen::Matrix3d R = camera.mount.rotation();
  const Vector3d& t0 = camera.mount.xyz;
  const double rise = height_m - t0.z();
  if (!(rise > 0.1)) return {};  // lamps at or below the camera: their rays tell no place
  const double tilt = o.tilt_sigma_deg * M_PI / 180;
  struct Sighting {
    Vector2d at;
    double spread;  // m, one sigma on the ceiling from the floor's tilt
    int view;
  };
  std::vector<Sighting> sightings;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const auto pose = pose_at(keyframes, views[v].stamp, o.max_keyframe_gap_s, o.max_turn);
    if (!pose || views[v].detection.flooded) continue;
    // The blobs' rays in the base frame, and those of one lamp each for the tilt: not split out
    // of a bloom, and off the axis within the fit's band (a bloom's centroid lies off its lamp).
    std::vector<Vector3d> rays, clean;
    for (const vision::OmniBlob& b : views[v].detection.blobs) {
      rays.push_back(R * b.ray);
      if (!b.from_bloom && b.theta > o.fit_min_theta && b.theta < o.fit_max_theta)
        clean.push_back(rays.back());
    }
    std::vector<Vector3d> near;  // the mapped lamps, level base frame
    for (const Vector3d& l : mapped) {
      const Vector2d in_base = pose->transform_to(l.head<2>());
      const Vector3d P(in_base.x(), in_base.y(), l.z());
      if (P.z() - t0.z() > 0.1 && (P - t0).head<2>().norm() <= o.max_distance_m) near.push_back(P);
    }
    const Vector3d w = view_turn(clean, near, t0, o.fit_gate_deg * M_PI / 180, o.fit_min_lamps);
    const Vector3d camera_at = t0 + w.cross(t0);  // level frame
    for (Vector3d d : rays) {
      d += w.cross(d);  // into the level frame
      if (!(d.z() > 1e-3)) continue;
      const double t = (height_m - camera_at.z()) / d.z();
      const double distance = t * d.head<2>().norm(), slant = distance / rise;
      if (distance > o.max_distance_m) continue;
      sightings.push_back({pose->transform_from((camera_at + t * d).head<2>()),
                           rise * (1 + slant * slant) * tilt, static_cast<int>(v)});
    }
  }
  // The surest sightings first: each starts a lamp or joins the nearest within its gate.
  std::stable_sort(sightings.begin(), sightings.end(),
                   [](const Sighting& x, const Sighting& y) { return x.spread < y.spread; });
  struct Cluster {
    Vector2d sum = Vector2d::Zero();  // weighted by 1 / spread^2
    double weight = 0;
    std::vector<int> views;
    Vector2d mean() const { return sum / weight; }
  };
  std::vector<Cluster> clusters;
  // Clusters by the cell of their first sighting; cells as large as the widest gate, so that a
  // sighting's cluster is in its own cell or a neighbour.
  std::unordered_map<std::int64_t, std::vector<int>> cells;
  auto cell = [&](double x) { return static_cast<std::int64_t>(std::floor(x / o.max_gate_m)); };
  auto key = [](std::int64_t i, std::int64_t j) { return i * 2000003 + j; };
  for (const Sighting& s : sightings) {
    const std::int64_t ci = cell(s.at.x()), cj = cell(s.at.y());
    const double gate = std::clamp(3 * s.spread, o.cluster_m, o.max_gate_m);
    int best = -1;
    double best_d = gate;
    for (std::int64_t i = ci - 1; i <= ci + 1; ++i)
      for (std::int64_t j = cj - 1; j <= cj + 1; ++j) {
        const auto it = cells.find(key(i, j));
        if (it == cells.end()) continue;
        for (const int c : it->second) {
          const double dist = (clusters[c].mean() - s.at).norm();
          if (dist < best_d) {
            best_d = dist;
            best = c;
          }
        }
      }
    if (best < 0) {
      best = static_cast<int>(clusters.size());
      clusters.emplace_back();
      cells[key(ci, cj)].push_back(best);
    }
    Cluster& c = clusters[best];
    const double w = 1 / (s.spread * s.spread + 1e-6);
    c.sum += w * s.at;
    c.weight += w;
    c.views.push_back(s.view);
  }
  std::vector<Vector2d> out;
  for (Cluster& c : clusters) {
    std::sort(c.views.begin(), c.views.end());
    const auto distinct = std::unique(c.views.begin(), c.views.end()) - c.views.begin();
    // The mean's own spread: one sighting overhead, or many from afar (a few far sightings a
    // bump threw past the gate of their lamp make no lamp).
    if (distinct >= o.min_views && 1 / std::sqrt(c.weight) <= o.max_sigma_m)
      out.push_back(c.mean());
  }
  return out;
}

std::vector<LampRow> lamp_rows(const std::vector<Vector2d>& lamps, int min_lamps, double across_m,
                               double max_gap_m) {
  const int n = static_cast<int>(lamps.size());
  std::vector<LampRow> rows;
  std::set<std::pair<int, int>> in_a_row;  // pairs of lamps in a row found already
  std::vector<std::pair<double, int>> on;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const Vector2d ij = lamps[j] - lamps[i];
      const double gap = ij.norm();
      if (gap > max_gap_m || gap < 1e-6 || in_a_row.count({i, j})) continue;
      const Vector2d u = ij / gap;
      on.clear();
      for (int k = 0; k < n; ++k) {
        const Vector2d e = lamps[k] - lamps[i];
        if (std::abs(u.x() * e.y() - u.y() * e.x()) <= across_m) on.emplace_back(u.dot(e), k);
      }
      std::sort(on.begin(), on.end());
      // The lamps on the line, consecutive ones at most max_gap_m apart, through i.
      std::size_t at = 0;
      while (on[at].second != i) ++at;
      std::size_t a = at, b = at;
      while (a > 0 && on[a].first - on[a - 1].first <= max_gap_m) --a;
      while (b + 1 < on.size() && on[b + 1].first - on[b].first <= max_gap_m) ++b;
      if (static_cast<int>(b - a + 1) < min_lamps) continue;
      for (std::size_t k = a; k < b; ++k)
        for (std::size_t l = k + 1; l <= b && on[l].first - on[k].first <= max_gap_m; ++l)
          in_a_row.insert(std::minmax(on[k].second, on[l].second));
      // The line fitted to the row's lamps (their principal axis), and its ends on it.
      Vector2d mean = Vector2d::Zero();
      for (std::size_t k = a; k <= b; ++k) mean += lamps[on[k].second];
      mean /= static_cast<double>(b - a + 1);
      Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
      for (std::size_t k = a; k <= b; ++k) {
        const Vector2d e = lamps[on[k].second] - mean;
        scatter += e * e.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
      Vector2d axis = eig.eigenvectors().col(1);
      if (axis.dot(u) < 0) axis = -axis;
      const auto on_line = [&](std::size_t k) {
        return Vector2d(mean + axis * axis.dot(lamps[on[k].second] - mean));
      };
      rows.push_back({on_line(a), on_line(b), static_cast<int>(b - a + 1)});
    }
  return rows;
}

}  // namespace lampnav::mapping
