// Method `paper`: Alg. 3 of paper 1 as published, on the merit function of merit.hpp.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "global_localizer_impl.hpp"

namespace lampnav::fusion {

namespace detail {

// The paper method's random numbers: xoshiro256** seeded by splitmix64, and Gaussians by
// Marsaglia's polar method. Several times cheaper than mt19937_64 with std::normal_distribution,
// which took a tenth of the method's time; the same seed gives the same poses everywhere.
class ParticleRandom {
 public:
  explicit ParticleRandom(std::uint64_t seed) {
    for (auto& w : s_) {
      seed += 0x9e3779b97f4a7c15ULL;
      std::uint64_t z = seed;
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      w = z ^ (z >> 31);
    }
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double gaussian() {
    if (spare_) {
      spare_ = false;
      return spare_value_;
    }
    double u, v, q;
    do {
      u = 2 * uniform() - 1;
      v = 2 * uniform() - 1;
      q = u * u + v * v;
    } while (q >= 1 || q == 0);
    const double f = std::sqrt(-2 * std::log(q) / q);
    spare_value_ = v * f;
    spare_ = true;
    return u * f;
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  std::uint64_t s_[4];
  bool spare_ = false;
  double spare_value_ = 0;
};

}  // namespace detail

using namespace detail;

Pose2 GlobalLocalizer::Impl::uniform_pose(ParticleRandom& rng) const {
  const double yaw = wrap_angle(2 * M_PI * rng.uniform() - M_PI);
  if (!has_regions) {
    // No regions: the box around the lamps.
    Vector2d lo = lamps.front()->xyz.head<2>(), hi = lo;
    for (const auto* l : lamps) {
      lo = lo.cwiseMin(l->xyz.head<2>());
      hi = hi.cwiseMax(l->xyz.head<2>());
    }
    return Pose2(lo.x() + rng.uniform() * (hi.x() - lo.x()),
                 lo.y() + rng.uniform() * (hi.y() - lo.y()), yaw);
  }
  const double a = rng.uniform() * region_cdf.back();
  const std::size_t k = std::min<std::size_t>(
      std::lower_bound(region_cdf.begin(), region_cdf.end(), a) - region_cdf.begin(),
      regions.size() - 1);
  const graph::Polygon& poly = regions[k]->region;
  const auto box = poly.bounds();
  for (int tries = 0; tries < 1000; ++tries) {
    const Vector2d p(box.min.x() + rng.uniform() * (box.max.x() - box.min.x()),
                     box.min.y() + rng.uniform() * (box.max.y() - box.min.y()));
    if (poly.contains(p)) return Pose2(p, yaw);
  }
  return Pose2(poly.centroid(), yaw);
}

GlobalLocalization GlobalLocalizer::Impl::paper(const vision::OmniDetection& d) const {
  const PaperMethodOptions& p = o.paper;
  GlobalLocalization out;
  out.method = GlobalMethod::paper;
  out.blobs = static_cast<int>(d.blobs.size());
  if (d.blobs.empty()) {
    out.why = "no lamp in the image";
    return out;
  }
  const MeritFunction merit = merit_function(d);
  ParticleRandom rng(p.seed);
  struct Particle {
    Pose2 pose;
    Merit m;
  };
  std::vector<Vector2d> px;
  auto evaluate_all = [&](std::vector<Particle>& set) {
    for (Particle& q : set) {
      projection.project(q.pose, px);
      q.m = merit(px);
      ++out.merit_evaluations;
    }
    std::stable_sort(set.begin(), set.end(), [](const Particle& a, const Particle& b) {
      return a.m.value < b.m.value || (a.m.value == b.m.value && a.m.matched > b.m.matched);
    });
  };
  std::vector<Particle> set(p.initial_poses);
  for (Particle& q : set) q.pose = uniform_pose(rng);
  evaluate_all(set);
  set.resize(p.particles);
  const double s_xy = p.noise_xy_m, s_yaw = p.noise_yaw_deg * kDeg;
  auto spawn = [&](const Pose2& parent) {
    return Particle{Pose2(parent.x() + s_xy * rng.gaussian(), parent.y() + s_xy * rng.gaussian(),
                          wrap_angle(parent.yaw() + s_yaw * rng.gaussian())),
                    {}};
  };
  const int n_best = static_cast<int>(std::lround(p.best_fraction * p.particles));
  const int n_next = static_cast<int>(std::lround(p.next_fraction * p.particles));
  const int n_kept = static_cast<int>(std::lround(p.kept_fraction * p.particles));
  for (int it = 0; it < p.iterations; ++it) {
    std::vector<Particle> next(set.begin(), set.begin() + std::min<int>(n_kept, set.size()));
    for (int k = 0; k < n_best && k < int(set.size()); ++k)
      for (int c = 0; c < p.best_children; ++c) next.push_back(spawn(set[k].pose));
    for (int k = n_best; k < n_best + n_next && k < int(set.size()); ++k)
      next.push_back(spawn(set[k].pose));
    evaluate_all(next);
    if (int(next.size()) > p.particles) next.resize(p.particles);
    set = std::move(next);
  }
  if (!std::isfinite(set.front().m.value)) {
    out.why = "no pose matched any of the " + std::to_string(out.blobs) + " lamps seen";
    return out;
  }
  // The argmin (Eq. 6), then the best particles distinct from it, as runners-up.
  std::vector<int> lamp_of;
  std::vector<std::pair<int, int>> matches;
  for (const Particle& q : set) {
    if (int(out.hypotheses.size()) >= o.max_hypotheses) break;
    if (!std::isfinite(q.m.value)) break;
    bool dup = false;
    for (const auto& h : out.hypotheses)
      if (!distinct(q.pose, h.pose, o.pairs.distinct_m, o.pairs.distinct_deg)) dup = true;
    if (dup) continue;
    PoseHypothesis h;
    h.pose = q.pose;
    h.merit = q.m.value;
    h.score = q.m.value;
    projection.project(q.pose, px, &lamp_of);
    merit(px, &matches);
    for (const auto& [pi, bj] : matches) {
      const graph::Lamp* lamp = lamps[lamp_of[pi]];
      const double ang = std::acos(
          std::clamp(camera_point(q.pose, lamp->xyz).normalized().dot(d.blobs[bj].ray), -1.0, 1.0));
      h.matches.push_back({lamp, bj, ang / kDeg});
    }
    h.expected = static_cast<int>(px.size());
    h.missing = h.expected - static_cast<int>(matches.size());
    h.unexplained = out.blobs - static_cast<int>(matches.size());
    // The spread of the particles around it stands for its uncertainty.
    Matrix3d cov = Matrix3d::Zero();
    int n = 0;
    for (const Particle& r : set)
      if (!distinct(r.pose, q.pose, 1.0, 15.0)) {
        const Vector3d e(r.pose.x() - q.pose.x(), r.pose.y() - q.pose.y(),
                         wrap_angle(r.pose.yaw() - q.pose.yaw()));
        cov += e * e.transpose();
        ++n;
      }
    const Vector3d floor(p.noise_xy_m * p.noise_xy_m, p.noise_xy_m * p.noise_xy_m,
                         std::pow(p.noise_yaw_deg * kDeg, 2));
    h.covariance = cov / std::max(1, n);
    h.covariance.diagonal() += 0.25 * floor;
    h.node = node_of(q.pose);
    out.hypotheses.push_back(std::move(h));
  }
  for (auto& h : out.hypotheses) h.weight = 0;
  if (!out.hypotheses.empty()) {
    out.hypotheses.front().weight = 1;
    out.plausible = 1;
  }
  return out;
}

}  // namespace lampnav::fusion
