#include "lampnav/fusion/global_localizer.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <unordered_map>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/merit.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::fusion {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

const char* to_string(GlobalMethod m) { return m == GlobalMethod::paper ? "paper" : "default"; }

std::optional<GlobalMethod> parse_global_method(const std::string& name) {
  if (name == "paper") return GlobalMethod::paper;
  if (name == "default") return GlobalMethod::lamp_pairs;
  return std::nullopt;
}

void GlobalLocalizerOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"", "global localizer options", field}, what);
  };
  const PaperMethodOptions& p = paper;
  check(p.initial_poses >= 1 && p.initial_poses <= 1000000, "paper.initial_poses",
        "must be 1 to 1000000");
  check(p.particles >= 1 && p.particles <= p.initial_poses, "paper.particles",
        "must be 1 to initial_poses");
  check(p.iterations >= 0 && p.iterations <= 1000, "paper.iterations", "must be 0 to 1000");
  check(p.best_fraction >= 0 && p.next_fraction >= 0 && p.best_fraction + p.next_fraction <= 1,
        "paper.best_fraction",
        "best and next fractions must be non-negative, summing to 1 at most");
  check(p.best_children >= 0 && p.best_children <= 100, "paper.best_children", "must be 0 to 100");
  check(p.kept_fraction >= 0 && p.kept_fraction <= 1, "paper.kept_fraction", "must be 0 to 1");
  check(p.noise_xy_m >= 0 && p.noise_yaw_deg >= 0, "paper.noise", "must not be negative");
  check(p.threshold_px > 0, "paper.threshold_px", "must be positive");
  const LampPairOptions& q = pairs;
  check(q.pair_max_theta_deg > 0 && q.pair_max_theta_deg < 90, "pairs.pair_max_theta_deg",
        "must be between 0 and 90");
  check(q.pair_max_blobs >= 2 && q.pair_max_blobs <= 64, "pairs.pair_max_blobs", "must be 2 to 64");
  check(q.max_theta_deg > 0 && q.max_theta_deg <= 180, "pairs.max_theta_deg",
        "must be between 0 and 180");
  check(q.expect_max_theta_deg > 0 && q.expect_max_theta_deg <= q.max_theta_deg,
        "pairs.expect_max_theta_deg", "must be between 0 and max_theta_deg");
  check(q.detection_sigma_deg > 0 && q.tilt_sigma_deg >= 0, "pairs.detection_sigma_deg",
        "sigmas must be positive");
  check(q.miss_cost >= 0 && q.spurious_cost >= 0 && q.ambiguity_margin >= 0, "pairs.miss_cost",
        "costs must not be negative");
  check(q.distinct_m > 0 && q.distinct_deg > 0, "pairs.distinct_m", "must be positive");
  check(q.candidates >= 1 && q.refined >= 1 && q.refined <= q.candidates, "pairs.candidates",
        "must be positive, with refined <= candidates");
  check(max_hypotheses >= 1, "max_hypotheses", "must be positive");
}

namespace {

struct BlobRay {
  Vector3d ray;  // camera frame
  double theta, angular_radius;
  int index;  // into the detection's blobs
};

// One pose scored against the blobs.
struct Evaluation {
  double cost = std::numeric_limits<double>::infinity();
  int expected = 0, missing = 0, unexplained = 0;
  std::vector<std::pair<int, int>> matches;  // (lamp index, blob index into BlobRay list)
};

// The floor's tilt of the base (rad), a nuisance estimated with each pose.
struct Tilt {
  double roll = 0, pitch = 0;
  // body^T without yaw: Rx(-roll) Ry(-pitch), and its derivatives by roll and pitch.
  Matrix3d inverse_rotation() const {
    return (Eigen::AngleAxisd(-roll, Vector3d::UnitX()) *
            Eigen::AngleAxisd(-pitch, Vector3d::UnitY()))
        .toRotationMatrix();
  }
  std::pair<Matrix3d, Matrix3d> inverse_rotation_derivatives() const {
    const double cr = std::cos(roll), sr = std::sin(roll);
    const double cp = std::cos(pitch), sp = std::sin(pitch);
    Matrix3d Rx, dRx, Ry, dRy;  // Rx(-roll), Ry(-pitch) and their derivatives
    Rx << 1, 0, 0, 0, cr, sr, 0, -sr, cr;
    dRx << 0, 0, 0, 0, -sr, cr, 0, -cr, -sr;
    Ry << cp, 0, -sp, 0, 1, 0, sp, 0, cp;
    dRy << -sp, 0, -cp, 0, 0, 0, cp, 0, -sp;
    return {dRx * Ry, Rx * dRy};
  }
};

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

bool distinct(const Pose2& a, const Pose2& b, double metres, double degrees) {
  return (a.translation() - b.translation()).norm() > metres ||
         std::abs(wrap_angle(a.yaw() - b.yaw())) > degrees * kDeg;
}

}  // namespace

struct GlobalLocalizer::Impl {
  const graph::TopologicalMap* map;
  GlobalLocalizerOptions o;
  vision::FisheyeCamera model;
  CeilingMapProjection projection;
  Matrix3d mount_R, mount_Rt;  // camera -> base, base -> camera
  Vector3d mount_t;
  std::vector<const graph::Lamp*> lamps;
  std::vector<const graph::Node*> regions;  // nodes with a region, for the paper's uniform poses
  std::vector<double> region_cdf;
  bool has_regions = false;

  Impl(const graph::TopologicalMap& m, const CameraDescription& camera,
       const GlobalLocalizerOptions& opt)
      : map(&m),
        o(opt),
        model(camera),
        projection(m, camera),
        mount_R(camera.mount.rotation()),
        mount_Rt(mount_R.transpose()),
        mount_t(camera.mount.xyz),
        lamps(projection.lamps()) {
    o.validate();
    double total = 0;
    for (const auto& n : m.nodes()) {
      if (n.region.size() < 3 || !(n.region.area() > 0)) continue;
      regions.push_back(&n);
      total += n.region.area();
      region_cdf.push_back(total);
    }
    has_regions = !regions.empty();
  }

  const graph::Node* node_of(const Pose2& p) const { return map->node_containing(p.translation()); }

  // ---------------------------------------------------------------------------------------
  // Rays: the direction of a lamp in the camera frame from a robot pose (level floor).

  // The lamp in the camera frame from a robot pose, the base tilted by the floor (roll about
  // x, then pitch about y, as conventions.md orders roll-pitch-yaw).
  Vector3d camera_point(const Pose2& pose, const Vector3d& lamp, const Tilt& tilt = {}) const {
    const double c = std::cos(pose.yaw()), s = std::sin(pose.yaw());
    const Vector3d d(lamp.x() - pose.x(), lamp.y() - pose.y(), lamp.z());
    Vector3d base(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
    if (tilt.roll != 0 || tilt.pitch != 0) base = tilt.inverse_rotation() * base;
    return mount_Rt * (base - mount_t);
  }

  std::vector<BlobRay> blob_rays(const vision::OmniDetection& d, double max_theta) const {
    std::vector<BlobRay> out;
    for (std::size_t j = 0; j < d.blobs.size(); ++j) {
      const auto& b = d.blobs[j];
      if (b.theta <= max_theta) out.push_back({b.ray, b.theta, b.angular_radius, int(j)});
    }
    return out;
  }

  // A blob's centroid is not quite the projection of the lamp's centre (the lens bends a near
  // lamp's face unevenly): a tenth of the lamp's angular size (rad).
  static double face_sigma(const graph::Lamp& l, double range) { return 0.1 * l.length / range; }
  // Half the angular size of a lamp's blob (the IR bloom makes it larger than the lamp).
  static double blob_half_size(const graph::Lamp& l, double range) {
    return 0.8 * l.length / range;
  }

  // Scores a pose known within (position_sigma, yaw_sigma) and a floor tilt known within
  // tilt_sigma: predicted lamps matched one-to-one to blobs, nearest first, within 3 sigma.
  Evaluation evaluate(const Pose2& pose, const Tilt& tilt, double position_sigma, double yaw_sigma,
                      double tilt_sigma, const std::vector<BlobRay>& blobs) const {
    const LampPairOptions& q = o.pairs;
    const double max_theta = q.max_theta_deg * kDeg, expect_theta = q.expect_max_theta_deg * kDeg;
    const double det = q.detection_sigma_deg * kDeg;
    const double cos_limit = std::cos(std::min(M_PI, max_theta + 0.1));
    struct Predicted {
      Vector3d ray;
      double theta, sigma, half_size;
      int lamp;
      bool crowded = false, matched = false;
    };
    std::vector<Predicted> pred;
    for (std::size_t i = 0; i < lamps.size(); ++i) {
      const Vector3d c = camera_point(pose, lamps[i]->xyz, tilt);
      const double range = c.norm();
      if (!(range > 0.1)) continue;
      const Vector3d ray = c / range;
      if (ray.z() < cos_limit) continue;
      const double theta = std::acos(std::clamp(ray.z(), -1.0, 1.0));
      const double face = face_sigma(*lamps[i], range);
      const double pos = position_sigma / range, yaw = yaw_sigma * std::sin(theta);
      const double sigma =
          std::sqrt(det * det + tilt_sigma * tilt_sigma + pos * pos + yaw * yaw + face * face);
      pred.push_back({ray, theta, sigma, blob_half_size(*lamps[i], range), int(i)});
    }
    // Lamps whose blobs merge in the image are not expected on their own. Angles between unit
    // rays are taken as chords (|a - b| = 2 sin(angle / 2)): within 1 % of the angle below 14
    // degrees, where it matters, and no arc cosine.
    for (std::size_t a = 0; a < pred.size(); ++a)
      for (std::size_t b = a + 1; b < pred.size(); ++b) {
        const double limit = pred[a].half_size + pred[b].half_size + 6 * det + 0.02;
        if ((pred[a].ray - pred[b].ray).squaredNorm() < limit * limit)
          pred[a].crowded = pred[b].crowded = true;
      }
    struct Pair {
      double cost;
      int p, b;
    };
    std::vector<Pair> pairs;
    std::vector<char> explained(blobs.size(), 0);
    for (std::size_t i = 0; i < pred.size(); ++i)
      for (std::size_t j = 0; j < blobs.size(); ++j) {
        const double s2 = pred[i].sigma * pred[i].sigma +
                          0.25 * blobs[j].angular_radius * blobs[j].angular_radius;
        const double d2 = (pred[i].ray - blobs[j].ray).squaredNorm() / s2;
        if (d2 <= 9.0) {
          explained[j] = 1;
          if (pred[i].theta <= max_theta) pairs.push_back({d2, int(i), int(j)});
        }
      }
    std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
      return a.cost < b.cost || (a.cost == b.cost && (a.p < b.p || (a.p == b.p && a.b < b.b)));
    });
    Evaluation e;
    e.cost = 0;
    std::vector<char> b_used(blobs.size(), 0);
    for (const Pair& p : pairs) {
      if (pred[p.p].matched || b_used[p.b]) continue;
      pred[p.p].matched = true;
      b_used[p.b] = 1;
      e.cost += p.cost;
      e.matches.emplace_back(pred[p.p].lamp, p.b);
    }
    for (const Predicted& p : pred) {
      if (p.crowded || p.theta > expect_theta) continue;
      ++e.expected;
      if (!p.matched) ++e.missing;
    }
    for (std::size_t j = 0; j < blobs.size(); ++j)
      if (!b_used[j] && !explained[j]) ++e.unexplained;
    e.cost += q.miss_cost * e.missing + q.spurious_cost * e.unexplained;
    if (tilt_sigma > 0)
      e.cost +=
          (tilt.roll * tilt.roll + tilt.pitch * tilt.pitch) / std::pow(q.tilt_sigma_deg * kDeg, 2);
    return e;
  }

  struct Solution {
    Pose2 pose;
    Tilt tilt;
    Matrix3d covariance;  // of the pose, the tilt marginalized
    Eigen::Matrix2d tilt_covariance;
    double cost = 0;  // robust sum of squared normalized residuals, plus the tilt's prior
  };

  // Gauss-Newton on the matched lamps: the pose (and the floor's tilt, with its prior) whose
  // predicted directions are nearest the seen ones. Tilt and translation both move the lamps in
  // view, but differently: a tilt turns every ray by the same angle, a translation turns a ray
  // by less the further off-axis its lamp is; the wide view tells them apart.
  // Without `with_tilt` the floor is taken as level.
  Solution solve(Pose2 pose, Tilt tilt, const Evaluation& e, const std::vector<BlobRay>& blobs,
                 bool with_tilt) const {
    using Matrix5d = Eigen::Matrix<double, 5, 5>;
    using Vector5d = Eigen::Matrix<double, 5, 1>;
    const double det = o.pairs.detection_sigma_deg * kDeg;
    const double tilt_prior =
        with_tilt ? 1.0 / std::pow(std::max(1e-6, o.pairs.tilt_sigma_deg * kDeg), 2) : 1e16;
    if (!with_tilt) tilt = Tilt{};
    Matrix5d JtJ = Matrix5d::Identity();
    double cost = 0;
    for (int iter = 0; iter < 8; ++iter) {
      JtJ.setZero();
      cost = 0;
      Vector5d Jtr = Vector5d::Zero();
      const double c = std::cos(pose.yaw()), s = std::sin(pose.yaw());
      Matrix3d Rz_t, dRz_t;
      Rz_t << c, s, 0, -s, c, 0, 0, 0, 1;
      dRz_t << -s, c, 0, -c, -s, 0, 0, 0, 0;
      const Matrix3d T = tilt.inverse_rotation();
      const auto [dT_roll, dT_pitch] = tilt.inverse_rotation_derivatives();
      for (const auto& [li, bj] : e.matches) {
        const Vector3d L = lamps[li]->xyz;
        const Vector3d d(L.x() - pose.x(), L.y() - pose.y(), L.z());
        const Vector3d b = Rz_t * d;
        const Vector3d cpt = mount_Rt * (T * b - mount_t);
        const double n = cpt.norm();
        const Vector3d ray = cpt / n;
        const Matrix3d dn = (Matrix3d::Identity() - ray * ray.transpose()) / n;
        Eigen::Matrix<double, 3, 5> dc;
        dc.col(0) = mount_Rt * (T * (Rz_t * Vector3d(-1, 0, 0)));
        dc.col(1) = mount_Rt * (T * (Rz_t * Vector3d(0, -1, 0)));
        dc.col(2) = mount_Rt * (T * (dRz_t * d));
        dc.col(3) = mount_Rt * (dT_roll * b);
        dc.col(4) = mount_Rt * (dT_pitch * b);
        const Eigen::Matrix<double, 3, 5> J = dn * dc;
        const Vector3d r = blobs[bj].ray - ray;
        const double face = face_sigma(*lamps[li], n);
        const double s2 = det * det + face * face + 0.01 * std::pow(blobs[bj].angular_radius, 2);
        // Huber: a blob off by more than 2 sigma (a bloom's split part, a half-hidden lamp)
        // pulls with a constant force instead of dragging the pose and the tilt.
        const double z = r.norm() / std::sqrt(s2);
        const double w = (z > 2 ? 2 / z : 1.0) / s2;
        cost += z > 2 ? 4 * z - 4 : z * z;
        JtJ += w * J.transpose() * J;
        Jtr += w * J.transpose() * r;
      }
      if (with_tilt) cost += tilt_prior * (tilt.roll * tilt.roll + tilt.pitch * tilt.pitch);
      JtJ(3, 3) += tilt_prior;
      JtJ(4, 4) += tilt_prior;
      Jtr(3) -= tilt_prior * tilt.roll;
      Jtr(4) -= tilt_prior * tilt.pitch;
      const Vector5d step = (JtJ + 1e-12 * Matrix5d::Identity()).ldlt().solve(Jtr);
      if (!step.allFinite()) break;
      pose = Pose2(pose.x() + step(0), pose.y() + step(1), wrap_angle(pose.yaw() + step(2)));
      tilt.roll += step(3);
      tilt.pitch += step(4);
      if (step.head<2>().norm() < 1e-5 && step.tail<3>().cwiseAbs().maxCoeff() < 1e-7) break;
    }
    const Matrix5d cov = (JtJ + 1e-12 * Matrix5d::Identity()).inverse();
    return {pose, tilt, cov.topLeftCorner<3, 3>(), cov.bottomRightCorner<2, 2>(), cost};
  }

  // Refines a pose: match, solve, match again with the tolerance the solution earned.
  PoseHypothesis refine(Pose2 pose, double position_sigma, double yaw_sigma,
                        const std::vector<BlobRay>& blobs) const {
    const double tilt_sigma = o.pairs.tilt_sigma_deg * kDeg;
    Tilt tilt;
    Evaluation e = evaluate(pose, tilt, position_sigma, yaw_sigma, tilt_sigma, blobs);
    Matrix3d cov = Vector3d(position_sigma * position_sigma, position_sigma * position_sigma,
                            yaw_sigma * yaw_sigma)
                       .asDiagonal();
    double ts = tilt_sigma;
    for (int round = 0; round < 3 && e.matches.size() >= 2; ++round) {
      // The tilt is estimated only when it explains the directions clearly better (by more
      // than chi-square's 95 % point for its two degrees of freedom) than a level floor.
      const Solution level = solve(pose, tilt, e, blobs, false);
      const Solution tilted = tilt_sigma > 0 ? solve(pose, tilt, e, blobs, true) : level;
      const Solution& sol = tilted.cost + 6.0 < level.cost ? tilted : level;
      pose = sol.pose;
      tilt = sol.tilt;
      cov = sol.covariance;
      const double ps = std::min(position_sigma, std::max(0.03, std::sqrt(cov(0, 0) + cov(1, 1))));
      const double ys = std::min(yaw_sigma, std::max(0.5 * kDeg, std::sqrt(cov(2, 2))));
      ts = &sol == &level ? tilt_sigma
                          : std::min(tilt_sigma, std::sqrt(sol.tilt_covariance.trace()));
      e = evaluate(pose, tilt, ps, ys, ts, blobs);
    }
    // Scored with one common tolerance, so hypotheses compare.
    e = evaluate(pose, tilt, 0.05, 0.5 * kDeg, ts, blobs);
    PoseHypothesis h;
    h.pose = pose;
    h.covariance = cov;
    h.score = e.cost;
    h.expected = e.expected;
    h.missing = e.missing;
    h.unexplained = e.unexplained;
    for (const auto& [li, bj] : e.matches) {
      const double ang = std::acos(std::clamp(
          camera_point(pose, lamps[li]->xyz, tilt).normalized().dot(blobs[bj].ray), -1.0, 1.0));
      h.matches.push_back({lamps[li], blobs[bj].index, ang / kDeg});
    }
    std::sort(h.matches.begin(), h.matches.end(),
              [](const LampMatch& a, const LampMatch& b) { return a.blob < b.blob; });
    return h;
  }

  // The paper's merit of a pose, for every hypothesis whatever its method.
  double paper_merit(const Pose2& pose, const MeritFunction& merit) const {
    std::vector<Vector2d> px;
    projection.project(pose, px);
    return merit(px).value;
  }

  MeritFunction merit_function(const vision::OmniDetection& d) const {
    std::vector<Vector2d> detected;
    for (const auto& b : d.blobs) detected.push_back(b.centroid_px);
    return MeritFunction(std::move(detected), o.paper.threshold_px, model.width(), model.height());
  }

  // ---------------------------------------------------------------------------------------
  // Method `default`.

  GlobalLocalization lamp_pairs(const vision::OmniDetection& d) const {
    const LampPairOptions& q = o.pairs;
    GlobalLocalization out;
    out.method = GlobalMethod::lamp_pairs;
    const std::vector<BlobRay> blobs = blob_rays(d, q.max_theta_deg * kDeg);
    out.blobs = static_cast<int>(blobs.size());
    // Detections for pairs: nearest the optical axis, where a ray says most about position.
    std::vector<BlobRay> seeds;
    for (const BlobRay& b : blobs)
      if (b.theta <= q.pair_max_theta_deg * kDeg && (mount_R * b.ray).z() > 0.05)
        seeds.push_back(b);
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
      voted.emplace_back(
          cell.votes, Pose2(cell.x / cell.votes, cell.y / cell.votes, std::atan2(cell.s, cell.c)));
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

  // Ranks, merges near-duplicates, weighs, places on the graph, and says whether it is ambiguous.
  void finish(GlobalLocalization& out, std::vector<PoseHypothesis> hs,
              const vision::OmniDetection& d) const {
    const LampPairOptions& q = o.pairs;
    std::stable_sort(hs.begin(), hs.end(), [](const PoseHypothesis& a, const PoseHypothesis& b) {
      return a.score < b.score;
    });
    std::vector<PoseHypothesis> kept;
    for (auto& h : hs) {
      if (h.matches.empty()) continue;
      bool dup = false;
      for (const auto& k : kept)
        if (!distinct(h.pose, k.pose, q.distinct_m, q.distinct_deg)) dup = true;
      if (!dup) kept.push_back(std::move(h));
      if (int(kept.size()) >= o.max_hypotheses) break;
    }
    if (kept.empty()) {
      out.why = "no pose explains any of the " + std::to_string(out.blobs) + " lamps seen";
      return;
    }
    const MeritFunction merit = merit_function(d);
    double total = 0;
    int plausible = 0;
    for (auto& h : kept) {
      h.weight = std::exp(-0.5 * (h.score - kept.front().score));
      total += h.weight;
      if (h.score <= kept.front().score + q.ambiguity_margin) ++plausible;
      h.node = node_of(h.pose);
      h.merit = paper_merit(h.pose, merit);
    }
    for (auto& h : kept) h.weight /= total;
    out.hypotheses = std::move(kept);
    out.plausible = plausible;
    out.ambiguous = plausible > 1;
    if (out.ambiguous) {
      std::ostringstream why;
      why << plausible << " distinct poses explain the image almost equally well (a symmetric "
          << "ceiling): more images are needed to choose";
      out.why = why.str();
    }
  }

  // ---------------------------------------------------------------------------------------
  // Method `paper` (Alg. 3).

  Pose2 uniform_pose(ParticleRandom& rng) const {
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

  GlobalLocalization paper(const vision::OmniDetection& d) const {
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
        const double ang = std::acos(std::clamp(
            camera_point(q.pose, lamp->xyz).normalized().dot(d.blobs[bj].ray), -1.0, 1.0));
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
};

GlobalLocalizer::GlobalLocalizer(const graph::TopologicalMap& map, const CameraDescription& camera,
                                 const GlobalLocalizerOptions& options)
    : impl_(std::make_unique<Impl>(map, camera, options)) {}
GlobalLocalizer::~GlobalLocalizer() = default;
GlobalLocalizer::GlobalLocalizer(GlobalLocalizer&&) noexcept = default;

const GlobalLocalizerOptions& GlobalLocalizer::options() const { return impl_->o; }

GlobalLocalization GlobalLocalizer::locate(const vision::OmniDetection& d) const {
  return locate(d, impl_->o.method);
}

GlobalLocalization GlobalLocalizer::locate(const vision::OmniDetection& d,
                                           GlobalMethod method) const {
  GlobalLocalization out;
  out.method = method;
  if (d.flooded) {
    out.why = std::to_string(d.raw_blobs) +
              " bright specks: a flood of light, not lamps (the detector refused the image)";
    return out;
  }
  if (impl_->lamps.empty()) {
    out.why = "the map has no lamps";
    return out;
  }
  if (d.blobs.empty()) {
    out.why = "no lamp in the image";
    return out;
  }
  return method == GlobalMethod::paper ? impl_->paper(d) : impl_->lamp_pairs(d);
}

std::optional<PoseHypothesis> GlobalLocalizer::refine(const Pose2& predicted, double position_sigma,
                                                      double yaw_sigma,
                                                      const vision::OmniDetection& d) const {
  const Impl& m = *impl_;
  if (d.flooded || !(position_sigma > 0) || !(yaw_sigma > 0)) return std::nullopt;
  const std::vector<BlobRay> blobs = m.blob_rays(d, m.o.pairs.max_theta_deg * kDeg);
  PoseHypothesis h = m.refine(predicted, position_sigma, yaw_sigma, blobs);
  if (h.matches.empty()) return std::nullopt;
  h.node = m.node_of(h.pose);
  h.merit = m.paper_merit(h.pose, m.merit_function(d));
  return h;
}

}  // namespace lampnav::fusion
