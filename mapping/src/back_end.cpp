#include "back_end.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace lampnav::mapping {

namespace {

// Odometry between two keyframes: the relative pose the wheels measured (one arc of a
// differential drive, the right wheel's travel times 1 + d and the left's times 1 - d), against
// the one the estimates give, weighted by the noise of that much travel. Estimating d takes out
// the curving drift of one wheel a few tenths of a percent larger than the other. The common
// scale is not estimated: a camera looking up cannot tell a building from a smaller one with a
// lower ceiling, so the wheels' calibration sets the map's scale.
struct OdometryFactor {
  OdometryFactor(double d_left, double d_right, double semi_axis, double sigma_xy, double sigma_yaw)
      : dl(d_left), dr(d_right), b(semi_axis), sxy(sigma_xy), syaw(sigma_yaw) {}

  template <class T>
  bool operator()(const T* a, const T* c2, const T* scale, T* r) const {
    using std::cos;
    using std::sin;
    const T l = (T(1) - scale[0]) * T(dl), rr = (T(1) + scale[0]) * T(dr);
    const T ds = (l + rr) / T(2), dth = (rr - l) / T(2 * b);
    const T mx = ds * cos(dth / T(2)), my = ds * sin(dth / T(2));
    const T c = cos(a[2]), s = sin(a[2]);
    const T ex = c2[0] - a[0], ey = c2[1] - a[1];
    const T lx = c * ex + s * ey;  // the second keyframe in the first's frame
    const T ly = -s * ex + c * ey;
    T e = c2[2] - a[2] - dth;
    e = atan2(sin(e), cos(e));  // wrapped, smoothly
    r[0] = (lx - mx) / T(sxy);
    r[1] = (ly - my) / T(sxy);
    r[2] = e / T(syaw);
    return true;
  }
  double dl, dr, b, sxy, syaw;
};

// How far `angle` is from being square to `axis` (modulo 90 degrees), signed, in (-pi/4, pi/4].
template <class T>
T off_square(const T& angle, const T& axis) {
  using std::atan2, std::cos, std::sin;
  const T e = T(4) * (angle - axis);
  return atan2(sin(e), cos(e)) / T(4);
}

// Lamps mounted square to the building: a rectangular lamp's axis is the building's axis, or
// at right angles to it (modulo 90 degrees). A Manhattan-world prior, as indoor SLAM uses; it
// holds the heading where the wheels alone would drift along a corridor never driven twice.
struct SquareFactor {
  explicit SquareFactor(double sigma) : sigma_rad(sigma) {}
  template <class T>
  bool operator()(const T* lamp, const T* axis, T* r) const {
    r[0] = off_square(lamp[3], axis[0]) / T(sigma_rad);
    return true;
  }
  double sigma_rad;
};

// Two lamps of a row: the direction from one to the other square to the row's axis.
struct RowFactor {
  explicit RowFactor(double sigma) : sigma_rad(sigma) {}
  template <class T>
  bool operator()(const T* a, const T* b, const T* axis, T* r) const {
    r[0] = off_square(T(atan2(b[1] - a[1], b[0] - a[0])), axis[0]) / T(sigma_rad);
    return true;
  }
  double sigma_rad;
};

// Lamps of one kind hang at one height (a flat ceiling), robustly: a lamp the drive saw from
// one side only, or while turning on the spot, borrows the height of its kind; one truly higher
// pays a bounded price (Huber) and keeps its own. The same between two kinds' heights (`at` 0):
// kinds under one ceiling.
struct HeightFactor {
  explicit HeightFactor(double sigma, int at = 2) : s(sigma), i(at) {}
  template <class T>
  bool operator()(const T* lamp, const T* height, T* r) const {
    r[0] = (lamp[i] - height[0]) / T(s);
    return true;
  }
  double s;
  int i;  // the height's place in the first block
};

// The wheels differ little: d stays near 0.
struct ScalePrior {
  explicit ScalePrior(double sigma) : s(sigma) {}
  template <class T>
  bool operator()(const T* scale, T* r) const {
    r[0] = scale[0] / T(s);
    return true;
  }
  double s;
};

// Where a carried robot's part of the drive was placed (by its lamps' fit to the map before it):
// the keyframe's only tie to the rest until lamps both parts saw tie them in the solve.
struct PlacedPrior {
  PlacedPrior(const std::array<double, 3>& placed, double sigma_xy, double sigma_yaw)
      : p(placed), sxy(sigma_xy), syaw(sigma_yaw) {}
  template <class T>
  bool operator()(const T* pose, T* r) const {
    r[0] = (pose[0] - T(p[0])) / T(sxy);
    r[1] = (pose[1] - T(p[1])) / T(sxy);
    const T e = pose[2] - T(p[2]);
    r[2] = atan2(sin(e), cos(e)) / T(syaw);
    return true;
  }
  std::array<double, 3> p;
  double sxy, syaw;
};

// A lamp's centre in the ceiling image: predicted by the camera geometry shared with the
// localizer (numeric derivatives: one model, not a copy of it templated for autodiff).
struct CentreFactor {
  CentreFactor(const fusion::CeilingGeometry& g, const Eigen::Vector2d& n, double sigma)
      : geometry(&g), measured(n), sigma_n(sigma) {}
  bool operator()(const double* pose, const double* lamp, double* r) const {
    const auto p = geometry->predict(Pose2(pose[0], pose[1], pose[2]),
                                     Eigen::Vector3d(lamp[0], lamp[1], lamp[2]));
    if (!p) return false;
    r[0] = (p->x() - measured.x()) / sigma_n;
    r[1] = (p->y() - measured.y()) / sigma_n;
    return true;
  }
  const fusion::CeilingGeometry* geometry;
  Eigen::Vector2d measured;
  double sigma_n;
};

// A rectangular lamp's axis in the image (modulo pi).
struct AxisFactor {
  AxisFactor(const fusion::CeilingGeometry& g, double orientation, double sigma)
      : geometry(&g), measured(orientation), sigma_rad(sigma) {}
  bool operator()(const double* pose, const double* lamp, double* r) const {
    const auto o = geometry->predict_orientation(
        Pose2(pose[0], pose[1], pose[2]), Eigen::Vector3d(lamp[0], lamp[1], lamp[2]), lamp[3]);
    if (!o) return false;
    r[0] = wrap_angle(2 * (*o - measured)) / 2 / sigma_rad;
    return true;
  }
  const fusion::CeilingGeometry* geometry;
  double measured, sigma_rad;
};

}  // namespace

int axis_for(MappingProblem& pb, double yaw, double gate) {
  int best = -1;
  double best_off = gate;
  for (std::size_t a = 0; a < pb.axes.size(); ++a) {
    const double off = std::abs(off_square(yaw, pb.axes[a]));
    if (off <= best_off) {
      best_off = off;
      best = static_cast<int>(a);
    }
  }
  if (best >= 0) return best;
  pb.axes.push_back(yaw);
  return static_cast<int>(pb.axes.size()) - 1;
}

namespace {

// A member's direction as solved: a lamp's yaw, a row's from one lamp to the other.
double direction(const MappingProblem& pb, const AxisMember& m) {
  if (!m.row) return pb.lamps[static_cast<std::size_t>(m.index)][3];
  const auto& row = pb.rows[static_cast<std::size_t>(m.index)];
  const auto& f = pb.lamps[static_cast<std::size_t>(row.from)];
  const auto& t = pb.lamps[static_cast<std::size_t>(row.to)];
  return std::atan2(t[1] - f[1], t[0] - f[0]);
}

// How many kinds (or height groups) numbered from 0 `ids` names: its largest plus one.
std::size_t count_of(const std::vector<int>& ids) {
  return ids.empty() ? 0 : static_cast<std::size_t>(*std::max_element(ids.begin(), ids.end())) + 1;
}

}  // namespace

std::vector<AxisMember> strained_members(const MappingProblem& pb, double trigger,
                                         const std::vector<AxisMember>& tried) {
  // Every lamp and row with an axis, in the order the drive placed them (a row where its second
  // lamp was), with how far off its axis it lies (signed).
  struct Off {
    AxisMember m;
    int axis, order;
    double off;
  };
  std::vector<Off> all;
  auto add = [&](const AxisMember& m, int axis, int order) {
    all.push_back(
        {m, axis, order, off_square(direction(pb, m), pb.axes[static_cast<std::size_t>(axis)])});
  };
  for (std::size_t i = 0; i < pb.lamps.size(); ++i)
    if (pb.axis_of[i] >= 0) add({false, static_cast<int>(i)}, pb.axis_of[i], static_cast<int>(i));
  for (std::size_t r = 0; r < pb.rows.size(); ++r)
    add({true, static_cast<int>(r)}, pb.rows[r].axis, pb.rows[r].to);
  std::stable_sort(all.begin(), all.end(),
                   [](const Off& a, const Off& b) { return a.order < b.order; });
  auto was_tried = [&](const AxisMember& m) {
    return std::any_of(tried.begin(), tried.end(),
                       [&](const AxisMember& t) { return t.row == m.row && t.index == m.index; });
  };
  // The one furthest off, not tried yet.
  std::size_t worst = all.size();
  double worst_off = trigger;
  for (std::size_t k = 0; k < all.size(); ++k) {
    if (std::abs(all[k].off) > worst_off && !was_tried(all[k].m)) {
      worst_off = std::abs(all[k].off);
      worst = k;
    }
  }
  if (worst == all.size()) return {};
  // With the members of its axis placed before and after it that lie off it the same way: a
  // corridor's lamps, one after the other. Those pulled the other way stay.
  const Off& w = all[worst];
  std::vector<AxisMember> group = {w.m};
  for (const int step : {-1, 1}) {
    for (auto k = static_cast<std::ptrdiff_t>(worst) + step;
         k >= 0 && k < static_cast<std::ptrdiff_t>(all.size()); k += step) {
      const Off& o = all[static_cast<std::size_t>(k)];
      if (o.axis != w.axis) continue;
      if (o.off * w.off <= 0 || std::abs(o.off) < trigger / 3) break;
      group.push_back(o.m);
    }
  }
  return group;
}

std::vector<int> strained_heights(const MappingProblem& pb, double trigger,
                                  const std::vector<int>& tried) {
  const auto off = [&](std::size_t i) {
    const auto g = static_cast<std::size_t>(pb.height_group[i]);
    return g < pb.group_height.size() ? pb.lamps[i][2] - pb.group_height[g] : 0.0;
  };
  std::size_t worst = pb.lamps.size();
  double worst_off = trigger;
  for (std::size_t i = 0; i < pb.lamps.size(); ++i)
    if (std::abs(off(i)) > worst_off &&
        std::find(tried.begin(), tried.end(), static_cast<int>(i)) == tried.end()) {
      worst_off = std::abs(off(i));
      worst = i;
    }
  if (worst == pb.lamps.size()) return {};
  // The landmarks are in the order the drive placed them: a corridor's, one after the other.
  // Those of other kinds between them are passed over; one of its kind lying the other way, or
  // close to the shared height, ends the group.
  std::vector<int> group = {static_cast<int>(worst)};
  const double w = off(worst);
  for (const int step : {-1, 1}) {
    for (auto k = static_cast<std::ptrdiff_t>(worst) + step;
         k >= 0 && k < static_cast<std::ptrdiff_t>(pb.lamps.size()); k += step) {
      const auto i = static_cast<std::size_t>(k);
      if (pb.height_group[i] != pb.height_group[worst]) continue;
      if (off(i) * w <= 0 || std::abs(off(i)) < trigger / 3) break;
      group.push_back(static_cast<int>(i));
    }
  }
  return group;
}

void release_height(MappingProblem& pb, const std::vector<int>& lamps) {
  const auto group = static_cast<int>(std::max(count_of(pb.kind), count_of(pb.height_group)));
  double sum = 0;
  for (const int i : lamps) {
    pb.height_group[static_cast<std::size_t>(i)] = group;
    sum += pb.lamps[static_cast<std::size_t>(i)][2];
  }
  pb.group_height.resize(static_cast<std::size_t>(group) + 1, 0.0);
  pb.group_height[static_cast<std::size_t>(group)] = sum / static_cast<double>(lamps.size());
}

void leave_axis(MappingProblem& pb, const std::vector<AxisMember>& group) {
  pb.axes.push_back(direction(pb, group.front()));
  const int axis = static_cast<int>(pb.axes.size()) - 1;
  for (const AxisMember& m : group) {
    if (m.row)
      pb.rows[static_cast<std::size_t>(m.index)].axis = axis;
    else
      pb.axis_of[static_cast<std::size_t>(m.index)] = axis;
  }
}

SolveReport solve(MappingProblem& pb, const fusion::CeilingGeometry& geometry,
                  const LampMapperOptions& o, double focal_px, std::size_t first_free) {
  const auto t0 = std::chrono::steady_clock::now();
  const bool whole = first_free == 0;
  // The lamps the free keyframes see; their other sightings anchor them to the fixed past.
  std::vector<bool> in_window(pb.lamps.size(), whole);
  for (const auto& s : pb.sightings)
    if (static_cast<std::size_t>(s.keyframe) >= first_free) in_window[s.lamp] = true;

  ceres::Problem::Options po;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  ceres::HuberLoss huber(o.huber_sigmas);
  ceres::HuberLoss row_loss(1.0);  // a lamp hung off its row's line pays linearly
  auto add_pose = [&](std::size_t k) {
    double* p = pb.poses[k].data();
    if (problem.HasParameterBlock(p)) return;
    problem.AddParameterBlock(p, 3);
    if (k == 0 || k < first_free) problem.SetParameterBlockConstant(p);
  };

  problem.AddParameterBlock(&pb.wheel_difference, 1);
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<ScalePrior, 1, 1>(new ScalePrior(o.wheel_scale_sigma)),
      nullptr, &pb.wheel_difference);
  if (!whole) problem.SetParameterBlockConstant(&pb.wheel_difference);
  for (const auto& c : pb.carries) {
    if (c.keyframe < std::max<std::size_t>(1, first_free)) continue;
    add_pose(c.keyframe);
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PlacedPrior, 3, 3>(
                                 new PlacedPrior(c.placed, o.carry_sigma_m, o.carry_sigma_yaw)),
                             nullptr, pb.poses[c.keyframe].data());
  }
  for (std::size_t k = std::max<std::size_t>(1, first_free); k < pb.poses.size(); ++k) {
    if (pb.carried_to(k)) continue;  // the wheels did not see the carry
    const double d = std::max(1e-3, pb.travel[k] - pb.travel[k - 1]);
    const double sxy = std::max(5e-4, o.odometry_sigma_per_m * std::sqrt(d));
    const double syaw = std::max(2e-4, o.odometry_yaw_sigma_per_m * std::sqrt(d));
    add_pose(k - 1);
    add_pose(k);
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<OdometryFactor, 3, 3, 3, 1>(
            new OdometryFactor(pb.wheels[k][0] - pb.wheels[k - 1][0],
                               pb.wheels[k][1] - pb.wheels[k - 1][1], pb.semi_axis, sxy, syaw)),
        nullptr, pb.poses[k - 1].data(), pb.poses[k].data(), &pb.wheel_difference);
  }
  // One shared height per kind of lamp, estimated by every solve: a windowed
  // one that held it at the mean of the heights as they stood would pull the lamps towards the
  // height new lamps are first placed at, and under a ceiling higher than that guess the map's
  // heights would creep up only as fast as windows passed.
  // (A group of lamps released from its kind's height has a shared height of its own.)
  const std::size_t kinds = count_of(pb.height_group);
  std::vector<double> kind_height(kinds, 0.0);
  std::vector<int> kind_count(kinds, 0);
  for (std::size_t i = 0; i < pb.lamps.size(); ++i) {
    kind_height[static_cast<std::size_t>(pb.height_group[i])] += pb.lamps[i][2];
    ++kind_count[static_cast<std::size_t>(pb.height_group[i])];
  }
  ceres::HuberLoss height_loss(1.0);
  ceres::TukeyLoss tie_loss(o.kind_tie_sigma > 0 ? o.kind_tie_max_m / o.kind_tie_sigma : 1.0);
  if (o.shared_height_sigma > 0) {
    for (std::size_t k = 0; k < kinds; ++k)
      if (kind_count[k]) kind_height[k] /= kind_count[k];
    std::vector<bool> in_problem(kinds, false);
    for (std::size_t i = 0; i < pb.lamps.size(); ++i) {
      if (!in_window[i]) continue;
      const auto k = static_cast<std::size_t>(pb.height_group[i]);
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<HeightFactor, 1, 4, 1>(
                                   new HeightFactor(o.shared_height_sigma)),
                               &height_loss, pb.lamps[i].data(), &kind_height[k]);
      in_problem[k] = true;
    }
    // Each kind's height tied to the most common kind's (the first); a group released from its
    // kind's height is not.
    for (std::size_t k = 1; k < std::min(kinds, count_of(pb.kind)) && o.kind_tie_sigma > 0; ++k)
      if (in_problem[k] && in_problem[0])
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<HeightFactor, 1, 1, 1>(
                                     new HeightFactor(o.kind_tie_sigma, 0)),
                                 &tie_loss, &kind_height[k], &kind_height[0]);
  }
  if (o.square_lamps) {
    // An axis is free in a whole solve (within 45 degrees of where it was: mod 90, it must not
    // wander to the next) and in a window that holds all of its lamps; else the fixed past holds
    // it.
    std::vector<bool> used(pb.axes.size(), false), held(pb.axes.size(), false);
    for (std::size_t i = 0; i < pb.lamps.size(); ++i) {
      const int a = pb.axis_of[i];
      if (a < 0) continue;
      if (!in_window[i]) {
        held[a] = true;
        continue;
      }
      used[a] = true;
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<SquareFactor, 1, 4, 1>(new SquareFactor(o.square_sigma)),
          nullptr, pb.lamps[i].data(), &pb.axes[a]);
    }
    for (const auto& row : pb.rows) {
      const bool a_in = in_window[row.from], b_in = in_window[row.to];
      if (!a_in && !b_in) {
        held[row.axis] = true;
        continue;
      }
      // The lamp outside the window is fixed with the past, and holds the axis with it.
      for (const int i : {row.from, row.to}) {
        if (in_window[i]) continue;
        held[row.axis] = true;
        problem.AddParameterBlock(pb.lamps[i].data(), 4);
        problem.SetParameterBlockConstant(pb.lamps[i].data());
      }
      used[row.axis] = true;
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<RowFactor, 1, 4, 4, 1>(new RowFactor(o.row_sigma)),
          &row_loss, pb.lamps[row.from].data(), pb.lamps[row.to].data(), &pb.axes[row.axis]);
    }
    for (std::size_t a = 0; a < pb.axes.size(); ++a) {
      if (!used[a]) continue;
      if (held[a]) {
        problem.SetParameterBlockConstant(&pb.axes[a]);
      } else {
        problem.SetParameterLowerBound(&pb.axes[a], 0, pb.axes[a] - M_PI / 4);
        problem.SetParameterUpperBound(&pb.axes[a], 0, pb.axes[a] + M_PI / 4);
      }
    }
  }
  const double sigma_n = o.pixel_sigma_px / focal_px;
  std::vector<bool> has_axis(pb.lamps.size(), false);
  std::vector<const MappingProblem::Sighting*> used;
  for (const auto& s : pb.sightings) {
    if (!in_window[s.lamp]) continue;
    used.push_back(&s);
    add_pose(s.keyframe);
    problem.AddResidualBlock(
        new ceres::NumericDiffCostFunction<CentreFactor, ceres::CENTRAL, 2, 3, 4>(
            new CentreFactor(geometry, s.centre, sigma_n)),
        &huber, pb.poses[s.keyframe].data(), pb.lamps[s.lamp].data());
    if (pb.rectangle[s.lamp]) {
      has_axis[s.lamp] = true;
      problem.AddResidualBlock(
          new ceres::NumericDiffCostFunction<AxisFactor, ceres::CENTRAL, 1, 3, 4>(
              new AxisFactor(geometry, s.orientation, o.orientation_sigma)),
          &huber, pb.poses[s.keyframe].data(), pb.lamps[s.lamp].data());
    }
  }
  // A disc has no axis: its yaw is not in the problem.
  for (std::size_t i = 0; i < pb.lamps.size(); ++i) {
    if (in_window[i] && !has_axis[i] && problem.HasParameterBlock(pb.lamps[i].data()))
      problem.SetManifold(pb.lamps[i].data(), new ceres::SubsetManifold(4, {3}));
  }

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  so.max_num_iterations = o.max_iterations;
  so.num_threads = 2;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  pb.group_height = kind_height;

  SolveReport rep;
  double sum = 0;
  std::size_t n = 0;
  for (const auto* s : used) {
    const auto& q = pb.poses[s->keyframe];
    const auto& l = pb.lamps[s->lamp];
    const auto p = geometry.predict(Pose2(q[0], q[1], q[2]), Eigen::Vector3d(l[0], l[1], l[2]));
    if (!p) continue;
    sum += ((*p - s->centre) * focal_px).squaredNorm();
    ++n;
  }
  rep.rms_px = n ? std::sqrt(sum / n) : 0.0;
  rep.chi2 = 2 * summary.final_cost;
  rep.converged = summary.termination_type == ceres::CONVERGENCE;
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep;
}

}  // namespace lampnav::mapping
