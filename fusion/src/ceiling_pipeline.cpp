#include "lampnav/fusion/ceiling_pipeline.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/chi_square.hpp"
#include "lampnav/vision/camera_models.hpp"

namespace lampnav::fusion {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

const char* to_string(LabelOutcome outcome) {
  switch (outcome) {
    case LabelOutcome::labelled:
      return "labelled";
    case LabelOutcome::no_candidate:
      return "no lamp expected there";
    case LabelOutcome::ambiguous:
      return "ambiguous";
    case LabelOutcome::partial_view:
      return "partial view";
  }
  return "?";
}

void LabellerOptions::validate() const {
  auto fail = [](const char* field, const char* msg) {
    throw InputError({"", "labeller options", field}, msg);
  };
  if (!(gate_probability > 0.5 && gate_probability < 1))
    fail("gate_probability", "must be between 0.5 and 1");
  if (!(pixel_sigma > 0)) fail("pixel_sigma", "must be positive");
  if (!(orientation_sigma > 0)) fail("orientation_sigma", "must be positive");
  if (!(tilt_sigma >= 0 && tilt_sigma < 0.5)) fail("tilt_sigma", "must be 0 to 0.5 rad");
  if (!(map_sigma > 0)) fail("map_sigma", "must be positive");
  if (!(candidate_radius > 0)) fail("candidate_radius", "must be positive");
  if (!(shape_tolerance > 0)) fail("shape_tolerance", "must be positive");
}

void CeilingPipelineOptions::validate() const {
  detector.validate();
  tracker.validate();
  labeller.validate();
  measurement.validate();
}

LampLabeller::LampLabeller(const graph::TopologicalMap& map, const CameraDescription& camera,
                           const LabellerOptions& options)
    : map_(&map), geometry_(camera), model_(camera), o_(options) {
  o_.validate();
  gate_ = chi_square_quantile(o_.gate_probability, 3);
  // How far from the camera a lamp of the map can be seen: the image's farthest corner in the
  // normalized plane (at most 3, 72 degrees off the axis), at the highest lamp, and a metre for
  // the pose's error.
  const double corner = model_.corner_radius();
  double top = 0;
  for (const auto& node : map.nodes())
    for (const auto& l : node.lamps) top = std::max(top, l.xyz.z());
  reach_m_ = std::min(corner, 3.0) * std::max(0.0, top - geometry_.mount_origin().z()) +
             std::hypot(camera.mount.xyz.x(), camera.mount.xyz.y()) + 1.0;
}

void LampLabeller::set_tilt_sigma(double rad) {
  LabellerOptions o = o_;
  o.tilt_sigma = rad;
  o.validate();
  o_ = o;
}

std::vector<const graph::Lamp*> LampLabeller::candidates(const Pose2& predicted) const {
  const graph::Node* here = map_->node_containing(predicted.translation());
  if (!here) return map_->lamps_within(predicted.translation(), o_.candidate_radius);
  std::vector<NodeId> nodes{here->id};
  for (const auto* e : map_->out_edges(here->id)) nodes.push_back(e->end);
  for (const auto* e : map_->in_edges(here->id)) nodes.push_back(e->start);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  std::vector<const graph::Lamp*> out;
  for (NodeId id : nodes)
    for (const auto& l : map_->node(id).lamps) out.push_back(&l);
  // And every lamp the camera can see from there: a wide lens at a junction sees the lamps of
  // the corridors beyond it, two places away.
  map_->visit_lamps_within(predicted.translation(), reach_m_, [&](const graph::Lamp& l) {
    if (!std::binary_search(nodes.begin(), nodes.end(), l.node)) out.push_back(&l);
  });
  return out;
}

LabelResult LampLabeller::label(const vision::LampDetection& d, const Pose2& predicted,
                                const Matrix3d& P, const std::set<LampId>& taken) const {
  LabelResult r;
  if (d.view == vision::LampView::partial) {
    r.outcome = LabelOutcome::partial_view;  // its centre is not the lamp's: wait for more
    return r;
  }
  double best = 1e300;
  for (const graph::Lamp* lamp : candidates(predicted)) {
    if (taken.count(lamp->id)) continue;
    Eigen::Matrix<double, 2, 3> Hn;
    const auto n = geometry_.predict(predicted, lamp->xyz, &Hn);
    if (!n) continue;
    ++r.candidates;
    const double dz = lamp->xyz.z() - geometry_.mount_origin().z();
    if (d.view == vision::LampView::full && d.length > 0 && dz > 0) {
      // Identical lamps are told apart by geometry; different ones by their size too.
      const double tol = o_.shape_tolerance;
      const double wide = lamp->width > 0 ? lamp->width : lamp->length;
      if (std::abs(d.length * dz - lamp->length) > tol * lamp->length ||
          std::abs(d.width * dz - wide) > tol * std::max(wide, 0.5 * lamp->length))
        continue;
    }
    const double sm = o_.map_sigma / dz;
    // Innovation on (centre, axis). The axis turns with the heading one for one (an upward
    // camera); round lamps have no axis and are gated on the centre alone.
    const bool axis = lamp->shape == graph::LampShape::rectangle && lamp->length > lamp->width;
    Eigen::Matrix<double, 3, 3> H = Eigen::Matrix3d::Zero();
    H.topRows<2>() = Hn;
    Vector3d nu = Vector3d::Zero();
    nu.head<2>() = d.centre - *n;
    Matrix3d R = Matrix3d::Zero();
    // A pixel spans more of the normalized plane, and a floor bump moves a lamp further, off
    // the axis than on it (a wide lens's edge: several times).
    const Eigen::Matrix2d T = CeilingGeometry::tilt_jacobian(*n);
    R.topLeftCorner<2, 2>() = model_.normalized_covariance(*n, o_.pixel_sigma) +
                              o_.tilt_sigma * o_.tilt_sigma * T * T.transpose() +
                              sm * sm * Eigen::Matrix2d::Identity();
    if (axis) {
      const auto o = geometry_.predict_orientation(predicted, lamp->xyz, lamp->yaw);
      const Pose2 turned(predicted.x(), predicted.y(), predicted.yaw() + 1e-6);
      const auto o2 = geometry_.predict_orientation(turned, lamp->xyz, lamp->yaw);
      if (!o || !o2) continue;
      H(2, 2) = wrap_axis_angle(*o2 - *o) / 1e-6;
      nu(2) = wrap_axis_angle(d.orientation - *o);
      R(2, 2) = o_.orientation_sigma * o_.orientation_sigma;
    } else {
      R(2, 2) = 1.0;
      H(2, 2) = 0;
    }
    const Matrix3d S = H * P * H.transpose() + R;
    const double d2 = nu.dot(S.ldlt().solve(nu));
    if (d2 < gate_) ++r.in_gate;
    if (d2 < best) {
      best = d2;
      r.lamp = lamp;
      r.d2 = d2;
    }
  }
  if (r.in_gate == 1) {
    r.outcome = LabelOutcome::labelled;
  } else {
    r.outcome = r.in_gate == 0 ? LabelOutcome::no_candidate : LabelOutcome::ambiguous;
    r.lamp = nullptr;
  }
  return r;
}

namespace {

// A kind of lamp: shape, then length and width in mm (a disc's width is its diameter).
using LampKind = std::tuple<graph::LampShape, long, long>;

LampKind kind_of(const graph::Lamp& l) {
  return {l.shape, std::lround(l.length * 1000), std::lround(l.width * 1000)};
}

LampKind kind_of(const vision::LampShapePrior& p) {
  return {p.rectangle ? graph::LampShape::rectangle : graph::LampShape::disc,
          std::lround(p.length * 1000), std::lround(p.width * 1000)};
}

}  // namespace

vision::LampShapePrior shape_prior_for(const graph::TopologicalMap& map,
                                       const CameraDescription& camera) {
  const double cam_z = camera.mount.xyz.z();
  auto above = [&](const graph::Lamp& l) { return l.xyz.z() - cam_z > 0.1; };
  // The kind the robot drives under: counted over the places routes go through, not the rooms
  // (an office's rooms often hold more lamps, of another kind, than its corridors). A map whose
  // every lamp is in a room counts them all.
  std::map<LampKind, int> count;
  for (const bool rooms_too : {false, true}) {
    for (const auto& n : map.nodes())
      if (rooms_too || n.place != graph::Place::room)
        for (const auto& l : n.lamps)
          if (above(l)) ++count[kind_of(l)];
    if (!count.empty()) break;
  }
  if (count.empty())
    throw InputError({map.name(), "lamps", ""}, "no lamp is above the ceiling camera");
  // The most common kind (the first in order on a tie: rectangles before discs).
  const LampKind kind =
      std::max_element(count.begin(), count.end(), [](const auto& a, const auto& b) {
        return a.second < b.second;
      })->first;
  // Its lamps' heights above the camera, wherever they are.
  std::vector<double> heights;
  for (const auto& n : map.nodes())
    for (const auto& l : n.lamps)
      if (above(l) && kind_of(l) == kind) heights.push_back(l.xyz.z() - cam_z);
  const auto [lo, hi] = std::minmax_element(heights.begin(), heights.end());
  vision::LampShapePrior p;
  p.rectangle = std::get<0>(kind) == graph::LampShape::rectangle;
  p.length = std::get<1>(kind) / 1000.0;
  p.width = p.rectangle ? std::get<2>(kind) / 1000.0 : p.length;
  p.min_distance = *lo;
  p.max_distance = *hi;
  std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
  p.nominal_distance = heights[heights.size() / 2];
  return p;
}

bool detects(const vision::LampShapePrior& prior, const graph::Lamp& lamp) {
  return kind_of(lamp) == kind_of(prior);
}

struct CeilingPipeline::Impl {
  CameraDescription camera;
  CeilingPipelineOptions o;
  vision::LampTracker tracker;
  LampLabeller labeller;
  CeilingGeometry geometry;
  vision::PinholeCamera model;
  std::map<int, const graph::Lamp*> label_of_track;
  double measurement_tilt;  // the pose measurement's tilt spread (set_floor_swing)

  // Labels a frame's lamps and measures the pose; `tracked`: a track keeps its label.
  CeilingObservation label(Stamp stamp, const vision::TrackedFrame& frame, const Pose2& predicted,
                           const Matrix3d& P, bool tracked);

  Impl(const graph::TopologicalMap& m, const CameraDescription& c,
       const CeilingPipelineOptions& opt)
      : camera(c),
        o(opt),
        tracker(c, shape_prior_for(m, c), opt.detector, opt.tracker),
        labeller(m, c, opt.labeller),
        geometry(c),
        model(c),
        measurement_tilt(opt.measurement.tilt_sigma) {
    o.validate();
  }
};

CeilingPipeline::CeilingPipeline(const graph::TopologicalMap& map, const CameraDescription& camera,
                                 const CeilingPipelineOptions& options)
    : impl_(std::make_unique<Impl>(map, camera, options)) {}
CeilingPipeline::~CeilingPipeline() = default;

void CeilingPipeline::set_floor_swing(double rad) {
  if (!(rad >= 0 && rad < 0.5))
    throw InputError({"", "ceiling pipeline", "floor swing"}, "must be 0 to 0.5 rad");
  Impl& m = *impl_;
  m.labeller.set_tilt_sigma(std::max(m.o.labeller.tilt_sigma, rad));
  m.measurement_tilt = std::max(m.o.measurement.tilt_sigma, rad);
}
CeilingPipeline::CeilingPipeline(CeilingPipeline&&) noexcept = default;

void CeilingPipeline::reset() {
  impl_->tracker.reset();
  impl_->label_of_track.clear();
}

CeilingObservation CeilingPipeline::process(Stamp stamp, const vision::ImageView& image,
                                            const Pose2& predicted, const Matrix3d& P) {
  Impl& m = *impl_;
  return m.label(stamp, m.tracker.process(image), predicted, P, true);
}

CeilingObservation CeilingPipeline::process(Stamp stamp,
                                            const std::vector<vision::LampDetection>& lamps,
                                            const Pose2& predicted, const Matrix3d& P) {
  vision::TrackedFrame frame;
  for (const auto& d : lamps) frame.lamps.push_back({0, 1, true, d});
  return impl_->label(stamp, frame, predicted, P, false);
}

CeilingObservation CeilingPipeline::Impl::label(Stamp stamp, const vision::TrackedFrame& frame,
                                                const Pose2& predicted, const Matrix3d& P,
                                                bool tracked) {
  CeilingObservation out;
  out.stamp = stamp;
  out.detection = frame.stats;
  out.ended_tracks = frame.ended;
  for (int id : frame.ended) label_of_track.erase(id);
  // Lamps held by live tracks are not offered to new ones (one lamp, one track).
  std::set<LampId> taken;
  for (const auto& t : frame.lamps) {
    const auto it = label_of_track.find(t.track_id);
    if (tracked && it != label_of_track.end()) taken.insert(it->second->id);
  }
  std::vector<LabelledLamp> labelled;
  for (const auto& t : frame.lamps) {
    ObservedLamp ob;
    ob.track_id = t.track_id;
    ob.detection = t.detection;
    const auto it = tracked ? label_of_track.find(t.track_id) : label_of_track.end();
    if (it != label_of_track.end()) {
      ob.lamp = it->second;
      ob.outcome = LabelOutcome::labelled;
    } else {
      const LabelResult r = labeller.label(t.detection, predicted, P, taken);
      ob.outcome = r.outcome;
      if (r.outcome == LabelOutcome::labelled) {
        ob.lamp = r.lamp;
        if (tracked) label_of_track[t.track_id] = r.lamp;
        taken.insert(r.lamp->id);
      }
    }
    if (ob.lamp && ob.detection.view != vision::LampView::partial)
      labelled.push_back({ob.lamp, ob.detection});
    out.lamps.push_back(ob);
  }
  if (!labelled.empty()) {
    std::string why;
    PoseMeasurementOptions mo = o.measurement;
    mo.tilt_sigma = measurement_tilt;
    out.measurement =
        measure_pose(geometry, model, labelled, predicted, stamp, mo, &why, &out.no_measurement);
    if (!out.measurement) out.no_measurement_reason = why;
  } else if (!out.lamps.empty()) {
    out.no_measurement_reason = "no labelled lamp in full view";
    out.no_measurement = PoseRefusal::no_usable_lamp;
  }
  return out;
}

std::vector<const graph::Lamp*> unseen_lamps(const graph::TopologicalMap& map,
                                             const vision::PinholeCamera& cam,
                                             const CeilingGeometry& geometry,
                                             const vision::LampShapePrior& detected,
                                             const std::vector<vision::LampDetection>& lamps,
                                             const Pose2& pose, const Eigen::Matrix3d& P) {
  std::vector<const graph::Lamp*> missing;
  const double sigma = std::sqrt(std::max(P(0, 0), P(1, 1)));
  if (sigma > 0.3) return missing;
  const double fx = cam.parameters().fx;
  for (const graph::Lamp* l : map.lamps_within(pose.translation(), 4.0)) {
    if (!detects(detected, *l)) continue;  // a lamp of another kind is not looked for
    const auto n = geometry.predict(pose, l->xyz);
    if (!n) continue;
    const double h = std::max(0.5, l->xyz.z() - geometry.mount_origin().z());
    // Margin: 3 sigma of position, 3 sigma of heading over a 2 m lever, and most of the lamp.
    const double margin = fx * (3 * sigma + std::sqrt(P(2, 2)) * 3 * 2.0 + 0.6 * l->length) / h;
    const Eigen::Vector2d px = cam.pixel_of_normalized(*n);
    if (px.x() < margin || px.y() < margin || px.x() > cam.width() - 1 - margin ||
        px.y() > cam.height() - 1 - margin)
      continue;
    bool seen = false;
    for (const auto& d : lamps)
      if ((d.centre_px - px).norm() < margin + 0.5 * fx * l->length / h) seen = true;
    if (!seen) missing.push_back(l);
  }
  return missing;
}

}  // namespace lampnav::fusion
