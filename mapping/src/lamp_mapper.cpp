#include "lampnav/mapping/lamp_mapper.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "back_end.hpp"
#include "lampnav/core/error.hpp"
#include "lampnav/fusion/ceiling_geometry.hpp"
#include "lampnav/fusion/ekf.hpp"
#include "lampnav/fusion/odometry_track.hpp"
#include "lampnav/mapping/lamp_kinds.hpp"
#include "lampnav/vision/camera_models.hpp"
#include "median.hpp"

namespace lampnav::mapping {

graph::Lamp MappedLamp::as_map_lamp(LampId id, const Pose2& motion) const {
  graph::Lamp out;
  out.id = std::move(id);
  out.xyz = xyz;
  out.xyz.head<2>() = motion.transform_from(xyz.head<2>());
  out.shape = shape;
  out.length = length;
  out.width = width;
  out.yaw = wrap_angle(yaw + motion.yaw());
  out.yaw_given = shape == graph::LampShape::rectangle;
  return out;
}

using Eigen::Vector2d;
using Eigen::Vector3d;

void LampMapperOptions::validate() const {
  auto check = [](bool ok, const char* field, const char* what) {
    if (!ok) throw InputError({"lamp mapper options", "", field}, what);
  };
  check(gate_m > 0 && gate_m < 5, "gate_m", "must be 0 to 5 m");
  check(track_gate > 0 && track_gate < 1, "track_gate", "must be 0 to 1");
  check(height_guess_m > 0 && height_guess_m < 50, "height_guess_m", "must be 0 to 50 m");
  check(keyframe_m > 0 && keyframe_m < 10, "keyframe_m", "must be 0 to 10 m");
  check(solve_every_m > 0, "solve_every_m", "must be positive");
  check(pixel_sigma_px > 0, "pixel_sigma_px", "must be positive");
  check(orientation_sigma > 0, "orientation_sigma", "must be positive");
  check(odometry_sigma_per_m > 0, "odometry_sigma_per_m", "must be positive");
  check(odometry_yaw_sigma_per_m > 0, "odometry_yaw_sigma_per_m", "must be positive");
  check(carry_sigma_m > 0, "carry_sigma_m", "must be positive");
  check(carry_sigma_yaw > 0, "carry_sigma_yaw", "must be positive");
  check(huber_sigmas > 0, "huber_sigmas", "must be positive");
  check(wheel_scale_sigma > 0 && wheel_scale_sigma < 0.5, "wheel_scale_sigma", "must be 0 to 0.5");
  check(square_sigma > 0, "square_sigma", "must be positive");
  check(square_gate_rad > 0 && square_gate_rad < M_PI / 4, "square_gate_rad",
        "must be between 0 and pi/4");
  check(square_release_rad > 0 && square_release_rad <= M_PI / 4, "square_release_rad",
        "must be above 0 and at most pi/4 (never)");
  check(square_release_chi2 > 0, "square_release_chi2", "must be positive");
  check(row_sigma > 0, "row_sigma", "must be positive");
  check(row_max_m > 0, "row_max_m", "must be positive");
  check(row_max_turn_rad >= 0 && row_max_turn_rad < M_PI / 4, "row_max_turn_rad",
        "must be between 0 and pi/4");
  check(shared_height_sigma >= 0, "shared_height_sigma", "must not be negative");
  check(height_release_m >= 0, "height_release_m", "must not be negative");
  check(height_release_chi2 > 0, "height_release_chi2", "must be positive");
  check(kind_tie_sigma >= 0, "kind_tie_sigma", "must not be negative");
  check(kind_tie_max_m > kind_tie_sigma, "kind_tie_max_m", "must be above kind_tie_sigma");
  check(min_sightings >= 1, "min_sightings", "must be at least 1");
  check(min_sightings_near >= 1 && min_sightings_near <= min_sightings, "min_sightings_near",
        "must be 1 to min_sightings");
  check(placed_sigma_m > 0, "placed_sigma_m", "must be positive");
  check(merge_m >= 0 && merge_m < gate_m + 1, "merge_m", "must be 0 to the gate plus 1 m");
  check(max_iterations >= 1, "max_iterations", "must be at least 1");
  check(window_m > 0, "window_m", "must be positive");
  for (const auto& k : kinds) k.validate();
  check(whole_every_m > 0, "whole_every_m", "must be positive");
}

// A landmark seen again after this much travel away from it closes a loop.
constexpr double kRevisitM = 20.0;
// Lamps are followed from the last keyframe only when it is at most this many keyframe steps
// back (frames lost in between): further, a wrong height would move the prediction too far.
constexpr double kFollowSteps = 3.0;
// At most this many groups of lamps or rows are tried off their axis after one solve (each
// costs a solve).
constexpr int kMaxReleases = 12;

struct LampMapper::Impl {
  LampMapperOptions o;
  CameraDescription camera;
  fusion::CeilingGeometry geometry;
  double focal_px;
  fusion::OdometryTrack track;
  std::vector<std::pair<Stamp, std::array<double, 2>>> wheel_log;  // cumulative readings
  MappingProblem pb;
  std::vector<Stamp> stamps;  // per keyframe
  // Per landmark, the lengths and widths of its sightings, seen from unit distance (one each per
  // sighting: their count is the landmark's sightings).
  std::vector<std::vector<double>> sizes, widths;
  // The height a new lamp of each kind is first placed at: the guess, then the median of the
  // solved lamps of its kind. Placed far from its height, a lamp would move across the ceiling as
  // the robot passes under it and be taken for another.
  std::vector<double> new_height;
  std::vector<double> last_seen_travel;  // per landmark
  struct LastRound {
    int lamp = -1;
    double robot_yaw = 0, travel_m = 0;
  };
  std::vector<LastRound> last_round;  // per kind: the last round lamp placed (rows)
  double next_solve_m;
  bool revisited = false;  // a landmark seen again after a loop since the last whole solve
  double last_whole_m = -1e9;
  std::optional<Pose2> carried_to;  // set by carried(): the next keyframe's pose
  MappingResult result;

  Impl(const RobotDescription& robot, const LampMapperOptions& options)
      : o(options),
        camera(ceiling_of(robot)),
        geometry(camera),
        focal_px(vision::PinholeCamera::intrinsics(camera).fx),
        track(robot.semi_axis, std::chrono::hours(24 * 365)),
        new_height(std::max<std::size_t>(2, options.kinds.size()), options.height_guess_m),
        next_solve_m(options.solve_every_m) {
    o.validate();
    pb.semi_axis = robot.semi_axis;
    last_round.resize(new_height.size());
  }

  static CameraDescription ceiling_of(const RobotDescription& robot) {
    const CameraDescription* c = robot.find_camera("ceiling_camera");
    if (!c)
      throw InputError({"robot.json", "", "cameras"},
                       "no camera named \"ceiling_camera\": the map is built from its lamps");
    if (!vision::PinholeCamera::takes(c->model))
      throw InputError({"robot.json", "camera ceiling_camera", "model"},
                       "the ceiling camera must be a pinhole or kannala_brandt camera (as the lamp "
                       "detector needs)");
    return *c;
  }

  // The pose estimate at `t`: the last keyframe's estimate moved by the wheels' travel since
  // (the filter's mid-point arc, as the odometry factor takes it), each wheel corrected by the
  // difference the last whole solve estimated, so that between solves the estimate does not
  // curve with the wheels' drift.
  Pose2 estimate(Stamp t) const {
    const auto& q = pb.poses.back();
    const auto w = wheels_at(t);
    const double d = pb.wheel_difference;
    const Eigen::Vector3d x = fusion::predict_motion(
        Eigen::Vector3d(q[0], q[1], q[2]), (1 - d) * (w[0] - pb.wheels.back()[0]),
        (1 + d) * (w[1] - pb.wheels.back()[1]), pb.semi_axis);
    return Pose2(x.x(), x.y(), x.z());
  }

  // The kind of a lamp seen whole: the nearest learnt kind, or long (0) or round (1).
  int kind_of(const vision::LampDetection& d) const {
    if (o.kinds.empty()) return d.length > kLongLamp * d.width ? 0 : 1;
    return nearest_kind(o.kinds, d.length, d.width);
  }
  bool is_rectangle(int kind) const {
    return o.kinds.empty() ? kind == 0 : o.kinds[static_cast<std::size_t>(kind)].rectangle;
  }

  double travel_at(Stamp t) const { return track.travel(track.first_stamp(), t); }

  // Cumulative wheel travel at `t`, interpolated between readings.
  std::array<double, 2> wheels_at(Stamp t) const {
    auto it = std::lower_bound(wheel_log.begin(), wheel_log.end(), t,
                               [](const auto& w, Stamp s) { return w.first < s; });
    if (it == wheel_log.end()) return wheel_log.back().second;
    if (it == wheel_log.begin() || it->first == t) return it->second;
    const auto& a = *(it - 1);
    const double f = to_seconds(t - a.first) / to_seconds(it->first - a.first);
    return {a.second[0] + f * (it->second[0] - a.second[0]),
            a.second[1] + f * (it->second[1] - a.second[1])};
  }

  void add_frame(Stamp t, const std::vector<vision::LampDetection>& lamps) {
    if (track.empty()) return;
    const Pose2 odo = track.at(t);
    const double travel = travel_at(t);
    const bool first = pb.poses.empty();
    if (!first && !carried_to && travel - pb.travel.back() < o.keyframe_m) return;
    const bool carry = carried_to.has_value();
    if (carry) last_round.assign(last_round.size(), {});  // no row across a carry
    const Pose2 est = carry ? *carried_to : first ? odo : estimate(t);
    carried_to.reset();
    const int kf = static_cast<int>(pb.poses.size());
    if (carry) pb.carries.push_back({pb.poses.size(), {est.x(), est.y(), est.yaw()}});
    pb.poses.push_back({est.x(), est.y(), est.yaw()});
    pb.odometry.push_back(odo);
    pb.wheels.push_back(wheels_at(t));
    pb.travel.push_back(travel);
    stamps.push_back(t);
    std::vector<bool> taken(pb.lamps.size(), false);
    // The last keyframe's sightings, the last ones in the problem so far: a lamp still in view
    // is followed across the image from there, when that keyframe is near enough.
    const std::size_t last_end = pb.sightings.size();
    std::size_t last_first = last_end;
    if (kf > 0 && !carry && travel - pb.travel[kf - 1] <= kFollowSteps * o.keyframe_m) {
      while (last_first > 0 && pb.sightings[last_first - 1].keyframe == kf - 1) --last_first;
    }
    for (const auto& d : lamps) {
      if (d.view != vision::LampView::full) continue;
      // Where the lamp is on the ceiling, at the height of what it joins (or its kind's).
      const int kind = kind_of(d);
      const bool rect = is_rectangle(kind);
      const double z0 = new_height[static_cast<std::size_t>(kind)];
      const auto base = geometry.base_point(d.centre, z0);
      if (!base) continue;
      const Vector2d at = est.transform_from(*base);
      const double reach = o.gate_m + 2.0 * base->norm() + 0.5;
      int best = followed(d.centre, kind, est, last_first, last_end, taken);
      double best_d = o.gate_m;
      for (std::size_t i = 0; best < 0 && i < pb.lamps.size(); ++i) {
        if (taken[i] || pb.kind[i] != kind) continue;
        if (!o.close_loops && travel - last_seen_travel[i] > kRevisitM) continue;
        // Far from the guess even for a lamp three times as high above the camera: not a
        // candidate (the placement below moves with the height, by the offset from the robot).
        if ((at - Vector2d(pb.lamps[i][0], pb.lamps[i][1])).norm() > reach) continue;
        // Place the candidate with its own height: parallax matters at a metre of offset.
        const auto b = geometry.base_point(d.centre, pb.lamps[i][2]);
        if (!b) continue;
        const Vector2d p = est.transform_from(*b);
        const double dist = (p - Vector2d(pb.lamps[i][0], pb.lamps[i][1])).norm();
        if (dist < best_d) {
          best_d = dist;
          best = static_cast<int>(i);
        }
      }
      if (best < 0) {
        best = static_cast<int>(pb.lamps.size());
        double yaw = 0;
        if (rect) {
          if (const auto dir = geometry.base_direction(d.centre, d.orientation, z0))
            yaw = wrap_angle(*dir + est.yaw());
        }
        pb.lamps.push_back({at.x(), at.y(), z0, yaw});
        pb.rectangle.push_back(rect);
        pb.axis_of.push_back(rect && o.square_lamps ? axis_for(pb, yaw, o.square_gate_rad) : -1);
        if (!rect && o.square_lamps) add_row(best, kind, at, est, travel);
        pb.kind.push_back(kind);
        pb.height_group.push_back(kind);
        sizes.emplace_back();
        widths.emplace_back();
        last_seen_travel.push_back(travel);
        taken.push_back(false);
      }
      taken[best] = true;
      if (travel - last_seen_travel[best] > kRevisitM) {
        ++result.revisits;
        revisited = true;
      }
      last_seen_travel[best] = travel;
      sizes[best].push_back(d.length);
      widths[best].push_back(d.width);
      pb.sightings.push_back({kf, best, d.centre, d.orientation});
    }
    if (travel >= next_solve_m) {
      // A loop closed since the last solve moves the whole drive; otherwise only the last
      // stretch is free.
      std::size_t first_free = 0;
      if (!revisited || travel < last_whole_m + o.whole_every_m) {
        first_free = pb.travel.size();
        while (first_free > 1 && pb.travel[first_free - 1] > travel - o.window_m) --first_free;
        // The first keyframe is the map frame, fixed in every solve: a window from the second
        // on is the whole drive, and solved as such (the wheels' difference with it).
        if (first_free <= 1) first_free = 0;
      }
      run_solve(first_free);
      if (first_free == 0) {
        revisited = false;
        last_whole_m = travel;
      }
      next_solve_m = travel + o.solve_every_m;
    }
  }

  // The landmark of sightings [first, end) (an earlier keyframe's) that a lamp at normalized
  // `centre` is, followed across the image: its sighting there moved by the robot's motion
  // since, at the landmark's height (a wrong height moves it by only the keyframe step over the
  // height); -1 when none is within the tracking gate.
  int followed(const Vector2d& centre, int kind, const Pose2& est, std::size_t first,
               std::size_t end, const std::vector<bool>& taken) const {
    int best = -1;
    double best_d = o.track_gate;
    for (std::size_t k = first; k < end; ++k) {
      const auto& s = pb.sightings[k];
      const int i = s.lamp;
      if (taken[i] || pb.kind[i] != kind) continue;
      const auto b = geometry.base_point(s.centre, pb.lamps[i][2]);
      if (!b) continue;
      const auto& q = pb.poses[s.keyframe];
      const Vector2d p = Pose2(q[0], q[1], q[2]).transform_from(*b);
      const auto seen = geometry.predict(est, Vector3d(p.x(), p.y(), pb.lamps[i][2]));
      if (!seen) continue;
      const double dist = (*seen - centre).norm();
      if (dist < best_d) {
        best_d = dist;
        best = i;
      }
    }
    return best;
  }

  // A round lamp just placed at `at` (landmark `lamp`), with the last one of its kind placed
  // before it: a row when the drive placed them one after the other (within `row_max_m` of
  // travel, no carry between), near each other, turning little between them, and the one lies
  // ahead of the other along the drive.
  void add_row(int lamp, int kind, const Vector2d& at, const Pose2& robot, double travel_m) {
    auto& last = last_round[static_cast<std::size_t>(kind)];
    if (last.lamp >= 0 && travel_m - last.travel_m <= o.row_max_m) {
      const auto& a = pb.lamps[static_cast<std::size_t>(last.lamp)];
      const Vector2d d = at - Vector2d(a[0], a[1]);
      const double dir = std::atan2(d.y(), d.x());
      // Along the drive, not across it (a hall's lamps beside its lane).
      if (d.norm() > 0.5 && d.norm() <= o.row_max_m &&
          std::abs(wrap_angle(robot.yaw() - last.robot_yaw)) <= o.row_max_turn_rad &&
          std::abs(wrap_angle(2 * (dir - robot.yaw()))) / 2 <= o.square_gate_rad)
        pb.rows.push_back({last.lamp, lamp, axis_for(pb, dir, o.square_gate_rad)});
    }
    last = {lamp, robot.yaw(), travel_m};
  }

  // Tries, one after another (at most kMaxReleases), the groups `strained(tried)` names, each
  // freed by `release`: kept when the solve then fits the drive better by at least `chi2` (more
  // than the freedom gained explains by chance), else the problem is put back.
  template <class Member, class Strained, class Release>
  void try_releases(SolveReport& r, const LampMapperOptions& so, std::size_t first_free,
                    double chi2, Strained strained, Release release) {
    std::vector<Member> tried;
    for (int k = 0; r.converged && k < kMaxReleases; ++k) {
      const std::vector<Member> group = strained(tried);
      if (group.empty()) break;
      tried.insert(tried.end(), group.begin(), group.end());
      const MappingProblem before = pb;
      release(group);
      const SolveReport trial = solve(pb, geometry, so, focal_px, first_free);
      ++result.solves;
      result.solve_seconds += trial.seconds;
      if (r.chi2 - trial.chi2 >= chi2) {
        r = trial;
      } else {
        pb = before;
      }
    }
  }

  void run_solve(std::size_t first_free = 0, int iterations = 0) {
    if (pb.poses.size() < 2) return;
    LampMapperOptions so = o;
    if (iterations > 0) so.max_iterations = iterations;
    SolveReport r = solve(pb, geometry, so, focal_px, first_free);
    ++result.solves;
    result.solve_seconds += r.seconds;
    // A corridor a little off the grid, whose first lamp the wheels placed within the gate of
    // the grid's axis: its lamps are pulled square, and the camera's sightings turn the poses
    // that saw them. Such a group, one after the other, leaves for an axis of its own.
    if (o.square_lamps)
      try_releases<AxisMember>(
          r, so, first_free, o.square_release_chi2,
          [&](const std::vector<AxisMember>& tried) {
            return strained_members(pb, o.square_release_rad, tried);
          },
          [&](const std::vector<AxisMember>& group) { leave_axis(pb, group); });
    // A corridor whose lamps hang apart from the rest of their kind (a lower or higher ceiling
    // there): pulled to the kind's height, they misfit the drive's views; such a group, one after
    // the other, gets a height of its own.
    if (o.shared_height_sigma > 0 && o.height_release_m > 0)
      try_releases<int>(
          r, so, first_free, o.height_release_chi2,
          [&](const std::vector<int>& tried) {
            return strained_heights(pb, o.height_release_m, tried);
          },
          [&](const std::vector<int>& group) { release_height(pb, group); });
    result.final_rms_px = r.rms_px;
    learn_new_height();
  }

  // The keyframes a landmark at height z must be seen at to be kept (LampMapperOptions).
  int sightings_needed(double z) const {
    const double each = (z - geometry.mount_origin().z()) * o.pixel_sigma_px / focal_px;
    const double n = std::ceil(std::pow(std::max(0.0, each) / o.placed_sigma_m, 2));
    return static_cast<int>(std::clamp(n, double(o.min_sightings_near), double(o.min_sightings)));
  }

  // Each kind's median solved height, over the landmarks seen often enough to be kept.
  void learn_new_height() {
    for (std::size_t kind = 0; kind < new_height.size(); ++kind) {
      std::vector<double> z;
      for (std::size_t i = 0; i < pb.lamps.size(); ++i) {
        if (pb.kind[i] == static_cast<int>(kind) &&
            static_cast<int>(sizes[i].size()) >= o.min_sightings &&
            pb.lamps[i][2] > geometry.mount_origin().z())
          z.push_back(pb.lamps[i][2]);
      }
      if (!z.empty()) new_height[kind] = median(z);
    }
  }
};

LampMapper::LampMapper(const RobotDescription& robot, const LampMapperOptions& options)
    : impl_(std::make_unique<Impl>(robot, options)) {}
LampMapper::~LampMapper() = default;
LampMapper::LampMapper(LampMapper&&) noexcept = default;

void LampMapper::wheels(Stamp stamp, double left, double right) {
  Impl& m = *impl_;
  if (!std::isfinite(left) || !std::isfinite(right)) return;
  if (m.wheel_log.empty()) {
    m.track.add(stamp, 0, 0);
  } else {
    const auto& [last_stamp, last] = m.wheel_log.back();
    if (stamp <= last_stamp) return;
    m.track.add(stamp, left - last[0], right - last[1]);
  }
  m.wheel_log.push_back({stamp, {left, right}});
}

void LampMapper::ceiling(Stamp stamp, const std::vector<vision::LampDetection>& lamps) {
  impl_->add_frame(stamp, lamps);
}

void LampMapper::carried(const Pose2& pose) { impl_->carried_to = pose; }

MappingResult LampMapper::finish() {
  Impl& m = *impl_;
  MappingProblem& pb = m.pb;
  m.run_solve(0, 4 * m.o.max_iterations);
  // Landmarks of one kind that the solve brought together are one lamp (a lamp first seen again
  // with more drift than the gate): their sightings move to the first, and the problem is solved
  // again.
  // (Without loop closure, no merging either: that is what it would leave.)
  std::vector<int> into(pb.lamps.size(), -1);
  bool merged = false;
  for (std::size_t i = 0; m.o.close_loops && i < pb.lamps.size(); ++i) {
    if (into[i] >= 0) continue;
    for (std::size_t j = i + 1; j < pb.lamps.size(); ++j) {
      if (into[j] >= 0 || pb.kind[i] != pb.kind[j]) continue;
      const Vector2d d(pb.lamps[i][0] - pb.lamps[j][0], pb.lamps[i][1] - pb.lamps[j][1]);
      if (d.norm() < m.o.merge_m) {
        into[j] = static_cast<int>(i);
        ++m.result.merged;
        merged = true;
      }
    }
  }
  if (merged) {
    for (auto& s : pb.sightings) {
      if (into[s.lamp] >= 0) {
        const int to = into[s.lamp];
        m.sizes[to].insert(m.sizes[to].end(), m.sizes[s.lamp].begin(), m.sizes[s.lamp].end());
        m.widths[to].insert(m.widths[to].end(), m.widths[s.lamp].begin(), m.widths[s.lamp].end());
        m.sizes[s.lamp].clear();
        m.widths[s.lamp].clear();
        s.lamp = to;
      }
    }
    m.run_solve();
  }
  // Sightings per landmark, counted by keyframe.
  std::vector<int> seen(pb.lamps.size(), 0);
  for (const auto& s : pb.sightings) ++seen[s.lamp];
  MappingResult& out = m.result;
  out.sightings = pb.sightings.size();
  for (std::size_t i = 0; i < pb.lamps.size(); ++i) {
    if (into[i] >= 0) continue;
    if (seen[i] < m.sightings_needed(pb.lamps[i][2])) {
      ++out.dropped;
      continue;
    }
    MappedLamp l;
    l.xyz = Vector3d(pb.lamps[i][0], pb.lamps[i][1], pb.lamps[i][2]);
    l.shape = pb.rectangle[i] ? graph::LampShape::rectangle : graph::LampShape::disc;
    // Sizes were seen from unit distance: at the solved one.
    const double scale = l.xyz.z() - m.geometry.mount_origin().z();
    l.length = median(m.sizes[i]) * scale;
    l.width = pb.rectangle[i] ? median(m.widths[i]) * scale : l.length;
    l.yaw = pb.rectangle[i] ? wrap_angle(2 * pb.lamps[i][3]) / 2 : 0.0;
    l.sightings = seen[i];
    out.lamps.push_back(l);
  }
  for (std::size_t k = 0; k < pb.poses.size(); ++k) {
    out.keyframes.push_back({m.stamps[k], Pose2(pb.poses[k][0], pb.poses[k][1], pb.poses[k][2]),
                             pb.odometry[k], pb.travel[k]});
  }
  return out;
}

}  // namespace lampnav::mapping
