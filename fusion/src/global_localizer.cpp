// Global localization: options, least squares with the floor's tilt, ranking and ambiguity,
// and the API. A pose scored against the blobs: pose_score.cpp; the methods: lamp_pairs.cpp and
// paper_method.cpp.

#include "lampnav/fusion/global_localizer.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <utility>

#include "ceiling_rays.hpp"
#include "global_localizer_impl.hpp"
#include "lampnav/core/error.hpp"
#include "spurious_blobs.hpp"

namespace lampnav::fusion {

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
  check(q.graph_margin_m >= 0 && q.graph_margin_m <= 5, "pairs.graph_margin_m", "must be 0 to 5");
  check(q.seed_centroid_shift >= 0 && q.seed_centroid_shift <= 1, "pairs.seed_centroid_shift",
        "must be between 0 and 1");
  check(q.pair_max_theta_deg > 0 && q.pair_max_theta_deg < 90, "pairs.pair_max_theta_deg",
        "must be between 0 and 90");
  check(q.pair_max_blobs >= 2 && q.pair_max_blobs <= 64, "pairs.pair_max_blobs", "must be 2 to 64");
  check(q.screen_max_theta_deg > 0 && q.screen_max_theta_deg < 90, "pairs.screen_max_theta_deg",
        "must be between 0 and 90");
  check(q.max_theta_deg > 0 && q.max_theta_deg <= 180, "pairs.max_theta_deg",
        "must be between 0 and 180");
  check(q.expect_max_theta_deg > 0 && q.expect_max_theta_deg <= q.max_theta_deg,
        "pairs.expect_max_theta_deg", "must be between 0 and max_theta_deg");
  check(q.detection_sigma_deg > 0 && q.tilt_sigma_deg >= 0, "pairs.detection_sigma_deg",
        "sigmas must be positive");
  check(q.miss_cost >= 0 && q.spurious_cost >= 0 && q.ambiguity_margin >= 0, "pairs.miss_cost",
        "costs must not be negative");
  check(q.cover_sigmas >= 0 && q.cover_sigmas <= 10, "pairs.cover_sigmas", "must be 0 to 10");
  check(q.far_blob_cost_max >= 0, "pairs.far_blob_cost_max", "must not be negative");
  check(q.distinct_m > 0 && q.distinct_deg > 0, "pairs.distinct_m", "must be positive");
  check(q.candidates >= 1 && q.refined >= 1 && q.refined <= q.candidates, "pairs.candidates",
        "must be positive, with refined <= candidates");
  check(max_hypotheses >= 1, "max_hypotheses", "must be positive");
}

using namespace detail;

GlobalLocalizer::Impl::Impl(const graph::TopologicalMap& m, const CameraDescription& camera,
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
  index_lamps();
}

void GlobalLocalizer::Impl::index_lamps() {
  const LampPairOptions& q = o.pairs;
  std::map<std::pair<long, long>, int> class_ids;
  max_height = 0;
  for (std::size_t i = 0; i < lamps.size(); ++i) {
    lamp_index[lamps[i]] = static_cast<int>(i);
    const double h = lamps[i]->xyz.z() - mount_t.z();
    max_height = std::max(max_height, h);
    const std::pair<long, long> key{std::lround(h / 0.05), std::lround(lamps[i]->length / 0.05)};
    auto it = class_ids.find(key);
    if (it == class_ids.end()) {
      it = class_ids.emplace(key, static_cast<int>(classes.size())).first;
      classes.push_back({key.first * 0.05, key.second * 0.05});
    }
    class_of.push_back(it->second);
  }
  usual_height = detail::usual_lamp_height(*map, mount_t.z());
  spurious_limit = spurious_blob_limit(*map, mount_t.z());
  // Two seeds lie within pair_max_theta of the axis: no further apart than twice that reach.
  const double offset = mount_t.head<2>().norm();
  const double reach = max_height * std::tan(q.pair_max_theta_deg * kDeg) + offset;
  std::map<std::pair<int, int>, std::vector<LampPair>> groups;
  for (std::size_t i = 0; i < lamps.size(); ++i)
    for (const graph::Lamp* other : map->lamps_within(lamps[i]->xyz.head<2>(), 2 * reach)) {
      const int l = lamp_index.at(other);
      if (l == static_cast<int>(i)) continue;
      const Vector2d v = other->xyz.head<2>() - lamps[i]->xyz.head<2>();
      const double d = v.norm();
      if (d < 0.2) continue;  // too close to give a heading
      groups[{class_of[i], class_of[l]}].push_back(
          {d, std::atan2(v.y(), v.x()), static_cast<int>(i), l});
    }
  for (auto& [key, v] : groups) {
    std::sort(v.begin(), v.end(), [](const LampPair& a, const LampPair& b) {
      return a.distance < b.distance ||
             (a.distance == b.distance && (a.a < b.a || (a.a == b.a && a.b < b.b)));
    });
    pair_groups.emplace_back(key, std::move(v));
  }
  // Lamps further off the axis than max_theta are not scored; the margin covers the lamp's own
  // size and a pose off by a metre.
  double longest = 0;
  for (const auto* l : lamps) longest = std::max(longest, l->length);
  const double theta = std::min(q.max_theta_deg * kDeg, 89.5 * kDeg);
  view_radius = max_height * std::tan(theta) + offset + longest + 1.0;
  grid_lamps();
}

void GlobalLocalizer::Impl::grid_lamps() {
  lamp_xy.clear();
  lamp_cos_yaw.clear();
  lamp_sin_yaw.clear();
  for (const auto* l : lamps) {
    lamp_xy.push_back(l->xyz.head<2>());
    lamp_cos_yaw.push_back(std::cos(l->yaw));
    lamp_sin_yaw.push_back(std::sin(l->yaw));
  }
  // At most 2^18 cells whatever the map's extent.
  constexpr double kMaxCells = 1 << 18;
  grid = detail::FlatGrid(lamp_xy, 0.5 * view_radius, kMaxCells);
  fine_grid = detail::FlatGrid(lamp_xy, 1.0, kMaxCells);
}

void GlobalLocalizer::Impl::lamps_in_view(const Pose2& pose, double radius,
                                          std::vector<int>& out) const {
  out.clear();
  if (lamps.size() <= 256 && radius <= 0) {
    out.resize(lamps.size());
    for (std::size_t i = 0; i < lamps.size(); ++i) out[i] = static_cast<int>(i);
    return;
  }
  const double r = radius > 0 ? radius : view_radius;
  const Vector2d p = pose.translation();
  grid.visit(p, r, [&](int i) {
    // The map's own test (TopologicalMap::visit_lamps_within), to the bit.
    if ((lamp_xy[i] - p).squaredNorm() <= r * r) out.push_back(i);
  });
  std::sort(out.begin(), out.end());  // the map's order, so that results do not depend on cells
}

Vector3d GlobalLocalizer::Impl::camera_point(const Pose2& pose, const Vector3d& lamp,
                                             const Tilt& tilt) const {
  return CameraView(*this, pose, tilt).point(lamp);
}

GlobalLocalizer::Impl::CameraView::CameraView(const Impl& impl, const Pose2& pose, const Tilt& tilt)
    : impl_(&impl),
      pose_(pose),
      c_(std::cos(pose.yaw())),
      s_(std::sin(pose.yaw())),
      tilted_(tilt.roll != 0 || tilt.pitch != 0),
      tilt_inverse_(tilted_ ? tilt.inverse_rotation() : Matrix3d::Identity()) {}

Vector3d GlobalLocalizer::Impl::CameraView::point(const Vector3d& lamp) const {
  const Vector3d d(lamp.x() - pose_.x(), lamp.y() - pose_.y(), lamp.z());
  Vector3d base(c_ * d.x() + s_ * d.y(), -s_ * d.x() + c_ * d.y(), d.z());
  if (tilted_) base = tilt_inverse_ * base;
  return impl_->mount_Rt * (base - impl_->mount_t);
}

std::vector<StraySighting> GlobalLocalizer::Impl::stray_sightings(
    const Pose2& pose, const Evaluation& e, const std::vector<BlobRay>& blobs) const {
  std::vector<StraySighting> out;
  for (const int j : e.strays)
    if (const std::optional<StraySighting> s = sighting(pose, blobs[j].ray)) out.push_back(*s);
  return out;
}

std::vector<GlobalLocalizer::Impl::BlobRay> GlobalLocalizer::Impl::blob_rays(
    const vision::OmniDetection& d, double max_theta) const {
  std::vector<BlobRay> out;
  for (std::size_t j = 0; j < d.blobs.size(); ++j) {
    const auto& b = d.blobs[j];
    if (b.theta <= max_theta) out.push_back({b.ray, b.theta, b.angular_radius, int(j), &b});
  }
  return out;
}

double GlobalLocalizer::Impl::blob_half_size(int lamp, const Vector3d& sight, double range) const {
  // Half the angle the lamp spans along and across itself, as seen along `sight` (the unit
  // vector from the camera to it, in the map): a lamp seen end-on far off-axis spans little,
  // one overhead much; and the bloom around it.
  const graph::Lamp& l = *lamps[lamp];
  const double c = lamp_cos_yaw[lamp], s = lamp_sin_yaw[lamp];
  const double along = c * sight.x() + s * sight.y(), across = -s * sight.x() + c * sight.y();
  const double w = l.width > 0 ? l.width : l.length;
  const double half = 0.5 * std::max(l.length * std::sqrt(std::max(0.0, 1 - along * along)),
                                     w * std::sqrt(std::max(0.0, 1 - across * across)));
  return half / range + kBloom;
}

GlobalLocalizer::Impl::Solution GlobalLocalizer::Impl::solve(Pose2 pose, Tilt tilt,
                                                             const Evaluation& e,
                                                             const std::vector<BlobRay>& blobs,
                                                             bool with_tilt) const {
  // A held tilt leaves the pose's three unknowns alone: a third of the work of five.
  return with_tilt ? solve_for<5>(pose, tilt, e, blobs) : solve_for<3>(pose, tilt, e, blobs);
}

template <int N>
GlobalLocalizer::Impl::Solution GlobalLocalizer::Impl::solve_for(
    Pose2 pose, Tilt tilt, const Evaluation& e, const std::vector<BlobRay>& blobs) const {
  static_assert(N == 3 || N == 5, "the pose, with or without the floor's tilt");
  using MatrixNd = Eigen::Matrix<double, N, N>;
  using VectorNd = Eigen::Matrix<double, N, 1>;
  const double det = o.pairs.detection_sigma_deg * kDeg;
  const double tilt_prior = 1.0 / std::pow(std::max(1e-6, o.pairs.tilt_sigma_deg * kDeg), 2);
  MatrixNd JtJ = MatrixNd::Identity();
  double cost = 0;
  for (int iter = 0; iter < 8; ++iter) {
    JtJ.setZero();
    cost = 0;
    VectorNd Jtr = VectorNd::Zero();
    const double c = std::cos(pose.yaw()), s = std::sin(pose.yaw());
    Matrix3d Rz_t, dRz_t;
    Rz_t << c, s, 0, -s, c, 0, 0, 0, 1;
    dRz_t << -s, c, 0, -c, -s, 0, 0, 0, 0;
    const Matrix3d T = tilt.inverse_rotation();
    std::pair<Matrix3d, Matrix3d> dT;  // by roll and by pitch, when they are unknowns
    if constexpr (N == 5) dT = tilt.inverse_rotation_derivatives();
    // A lamp at offset d from the robot (in the map) is at A d - c0 in the camera; the
    // derivatives by yaw and by the tilt's two angles are as linear in d.
    const Matrix3d A = mount_Rt * T * Rz_t, A_by_yaw = mount_Rt * T * dRz_t;
    const Vector3d c0 = mount_Rt * mount_t;
    Matrix3d A_by_roll, A_by_pitch;
    if constexpr (N == 5) {
      A_by_roll = mount_Rt * dT.first * Rz_t;
      A_by_pitch = mount_Rt * dT.second * Rz_t;
    }
    // A lamp's point moves alike for every lamp as the robot moves along x or y.
    const Vector3d d_by_x = -A.col(0), d_by_y = -A.col(1);
    for (const auto& [li, bj] : e.matches) {
      const Vector3d L = lamps[li]->xyz;
      const Vector3d d(L.x() - pose.x(), L.y() - pose.y(), L.z());
      const Vector3d cpt = A * d - c0;
      const double n = cpt.norm();
      const Vector3d ray = cpt / n;
      Eigen::Matrix<double, 3, N> dc;
      dc.col(0) = d_by_x;
      dc.col(1) = d_by_y;
      dc.col(2) = A_by_yaw * d;
      if constexpr (N == 5) {
        dc.col(3) = A_by_roll * d;
        dc.col(4) = A_by_pitch * d;
      }
      // The unit ray's derivative: the point's, less its part along the ray, over the range.
      const Eigen::Matrix<double, 3, N> J = (dc - ray * (ray.transpose() * dc)) / n;
      const Vector3d r = blobs[bj].ray - ray;
      const double face = face_sigma(*lamps[li], n);
      const double s2 =
          det * det + face * face + 0.01 * blobs[bj].angular_radius * blobs[bj].angular_radius;
      // Huber: a blob off by more than 2 sigma (a bloom's split part, a half-hidden lamp)
      // pulls with a constant force instead of dragging the pose and the tilt.
      const double z = r.norm() / std::sqrt(s2);
      const double w = (z > 2 ? 2 / z : 1.0) / s2;
      cost += z > 2 ? 4 * z - 4 : z * z;
      JtJ.noalias() += w * J.transpose() * J;
      Jtr.noalias() += w * J.transpose() * r;
    }
    if constexpr (N == 5) {  // the prior pulls toward a level floor
      cost += tilt_prior * (tilt.roll * tilt.roll + tilt.pitch * tilt.pitch);
      JtJ(3, 3) += tilt_prior;
      JtJ(4, 4) += tilt_prior;
      Jtr(3) -= tilt_prior * tilt.roll;
      Jtr(4) -= tilt_prior * tilt.pitch;
    }
    const VectorNd step = (JtJ + 1e-12 * MatrixNd::Identity()).ldlt().solve(Jtr);
    if (!step.allFinite()) break;
    pose = Pose2(pose.x() + step(0), pose.y() + step(1), wrap_angle(pose.yaw() + step(2)));
    if constexpr (N == 5) {
      tilt.roll += step(3);
      tilt.pitch += step(4);
    }
    if (step.template head<2>().norm() < 1e-5 &&
        step.template tail<N - 2>().cwiseAbs().maxCoeff() < 1e-7)
      break;
  }
  const MatrixNd cov = (JtJ + 1e-12 * MatrixNd::Identity()).inverse();
  if constexpr (N == 5)
    return {pose, tilt, cov.template topLeftCorner<3, 3>(), cov.template bottomRightCorner<2, 2>(),
            cost};
  else  // held: known exactly
    return {pose, tilt, cov, Eigen::Matrix2d::Zero(), cost};
}

PoseHypothesis GlobalLocalizer::Impl::refine(Pose2 pose, double position_sigma, double yaw_sigma,
                                             const std::vector<BlobRay>& blobs, int rounds,
                                             bool with_tilt, const Tilt& held,
                                             Tilt* tilt_out) const {
  const double tilt_sigma = o.pairs.tilt_sigma_deg * kDeg;
  Tilt tilt = held;
  Evaluation e = evaluate(pose, tilt, position_sigma, yaw_sigma, tilt_sigma, blobs);
  Matrix3d cov = Vector3d(position_sigma * position_sigma, position_sigma * position_sigma,
                          yaw_sigma * yaw_sigma)
                     .asDiagonal();
  double ts = tilt_sigma;
  for (int round = 0; round < rounds && e.matches.size() >= 2; ++round) {
    // The tilt is estimated only when it explains the directions clearly better (by more
    // than chi-square's 95 % point for its two degrees of freedom) than a level floor.
    const Solution level = solve(pose, held, e, blobs, false);
    const Solution tilted = with_tilt && tilt_sigma > 0 ? solve(pose, tilt, e, blobs, true) : level;
    const Solution& sol = tilted.cost + 6.0 < level.cost ? tilted : level;
    pose = sol.pose;
    tilt = sol.tilt;
    cov = sol.covariance;
    const double ps = std::min(position_sigma, std::max(0.03, std::sqrt(cov(0, 0) + cov(1, 1))));
    const double ys = std::min(yaw_sigma, std::max(0.5 * kDeg, std::sqrt(cov(2, 2))));
    ts = &sol == &level ? tilt_sigma : std::min(tilt_sigma, std::sqrt(sol.tilt_covariance.trace()));
    // Matched again with the tolerance the solution earned, for the next round (after the last,
    // the score below matches anew). When the lamps and blobs matched are those just solved on,
    // the next round would start at its own solution: the pose has converged.
    if (round + 1 < rounds) {
      Evaluation next = evaluate(pose, tilt, ps, ys, ts, blobs);
      const bool converged = next.matches == e.matches;
      e = std::move(next);
      if (converged) break;
    }
  }
  // Scored with one common tolerance, so hypotheses compare.
  e = evaluate(pose, tilt, 0.05, 0.5 * kDeg, ts, blobs, 0, true);
  PoseHypothesis h;
  h.pose = pose;
  h.covariance = cov;
  h.score = e.cost;
  h.expected = e.expected;
  h.missing = e.missing;
  h.unexplained = e.unexplained;
  for (const int li : e.missed) h.missed.push_back(lamps[li]);
  h.strays = stray_sightings(pose, e, blobs);
  for (const auto& [li, bj] : e.matches) {
    const double ang = std::acos(std::clamp(
        camera_point(pose, lamps[li]->xyz, tilt).normalized().dot(blobs[bj].ray), -1.0, 1.0));
    h.matches.push_back({lamps[li], blobs[bj].index, ang / kDeg});
  }
  for (const auto& [li, c] : e.lamp_costs) h.lamp_costs.emplace_back(lamps[li], c);
  std::sort(h.matches.begin(), h.matches.end(),
            [](const LampMatch& a, const LampMatch& b) { return a.blob < b.blob; });
  if (tilt_out) *tilt_out = tilt;
  return h;
}

double GlobalLocalizer::Impl::paper_merit(const Pose2& pose, const MeritFunction& merit) const {
  std::vector<Vector2d> px;
  projection.project(pose, px);
  return merit(px).value;
}

MeritFunction GlobalLocalizer::Impl::merit_function(const vision::OmniDetection& d) const {
  std::vector<Vector2d> detected;
  for (const auto& b : d.blobs) detected.push_back(b.centroid_px);
  return MeritFunction(std::move(detected), o.paper.threshold_px, model.width(), model.height());
}

void GlobalLocalizer::Impl::finish(GlobalLocalization& out, std::vector<PoseHypothesis> hs,
                                   const vision::OmniDetection& d, const LampPairOptions& q,
                                   int max_hypotheses, bool with_merit) const {
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
    if (int(kept.size()) >= max_hypotheses) break;
  }
  if (kept.empty()) {
    out.why = "no pose explains any of the " + std::to_string(out.blobs) + " lamps seen";
    return;
  }
  const std::optional<MeritFunction> merit =
      with_merit ? std::optional<MeritFunction>(merit_function(d)) : std::nullopt;
  double total = 0;
  int plausible = 0;
  for (auto& h : kept) {
    h.weight = std::exp(-0.5 * (h.score - kept.front().score));
    total += h.weight;
    if (h.score <= kept.front().score + q.ambiguity_margin) ++plausible;
    h.node = node_of(h.pose);
    h.merit = merit ? paper_merit(h.pose, *merit) : std::numeric_limits<double>::quiet_NaN();
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
  return method == GlobalMethod::paper
             ? impl_->paper(d)
             : impl_->lamp_pairs(d, impl_->o.pairs, impl_->o.max_hypotheses);
}

GlobalLocalization GlobalLocalizer::enumerate(const vision::OmniDetection& d, int cap,
                                              double margin, const EnumerationPrior* prior) const {
  const Impl& m = *impl_;
  if (d.flooded || m.lamps.empty() || d.blobs.empty()) return locate(d, GlobalMethod::lamp_pairs);
  return m.exhaustive(d, std::max(1, cap), std::max(0.0, margin), prior);
}

GlobalLocalizer::PoseScore GlobalLocalizer::score(const Pose2& pose, double position_sigma,
                                                  double yaw_sigma,
                                                  const vision::OmniDetection& d) const {
  const Impl& m = *impl_;
  PoseScore s;
  if (d.flooded) return s;
  const std::vector<BlobRay> blobs = m.blob_rays(d, m.o.pairs.max_theta_deg * kDeg);
  const Evaluation e =
      m.evaluate(pose, {}, std::max(1e-3, position_sigma), std::max(1e-4, yaw_sigma),
                 m.o.pairs.tilt_sigma_deg * kDeg, blobs, 0, true);
  s.cost = e.cost;
  s.expected = e.expected;
  s.missing = e.missing;
  s.unexplained = e.unexplained;
  for (const int li : e.missed) s.missed.push_back(m.lamps[li]);
  s.strays = m.stray_sightings(pose, e, blobs);
  s.matched = static_cast<int>(e.matches.size());
  for (const auto& [li, c] : e.lamp_costs) s.lamp_costs.emplace_back(m.lamps[li], c);
  return s;
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
  // The paper's merit is not computed here (a new merit function per call; callers weigh by
  // score): locate() gives it.
  h.merit = std::numeric_limits<double>::quiet_NaN();
  return h;
}

}  // namespace lampnav::fusion
