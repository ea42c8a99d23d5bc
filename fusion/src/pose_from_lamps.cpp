#include "lampnav/fusion/pose_from_lamps.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/chi_square.hpp"

namespace lampnav::fusion {

using Eigen::Matrix2d;
using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

void PoseMeasurementOptions::validate() const {
  auto positive = [](double v, const char* field) {
    if (!(v > 0 && std::isfinite(v)))
      throw InputError({"", "pose measurement options", field}, "must be positive");
  };
  positive(pixel_sigma, "pixel_sigma");
  positive(completed_pixel_sigma, "completed_pixel_sigma");
  positive(orientation_sigma, "orientation_sigma");
  positive(completed_orientation_sigma, "completed_orientation_sigma");
  positive(map_sigma, "map_sigma");
  if (!(consistency_probability > 0.5 && consistency_probability < 1))
    throw InputError({"", "pose measurement options", "consistency_probability"},
                     "must be between 0.5 and 1");
  if (!(tilt_sigma >= 0 && tilt_sigma < 0.5))
    throw InputError({"", "pose measurement options", "tilt_sigma"}, "must be 0 to 0.5 rad");
}

namespace {

struct Term {
  Vector2d map_xy;    // lamp centre in the map
  Vector2d base;      // where the detection puts it in the base frame
  Matrix2d base_cov;  // its covariance (pixel noise through the geometry)
  bool has_axis = false;
  double map_yaw = 0;   // the lamp's axis in the map
  double base_yaw = 0;  // the detected axis in the base frame
  double axis_var = 0;
};

std::vector<LampId> lamp_ids(const std::vector<LabelledLamp>& lamps) {
  std::vector<LampId> ids;
  for (const auto& l : lamps)
    if (l.lamp && l.detection.view != vision::LampView::partial) ids.push_back(l.lamp->id);
  return ids;
}

// One round lamp: a point seen at `base` in the robot's frame, which puts the robot at
// p(yaw) = lamp - R(yaw) base for whatever the heading is. Written as a pose measurement at the
// predicted heading whose covariance is free (kFreeHeadingSigma) along the direction in which
// (p, yaw) moves together, (dp/dyaw, 1): its information is then that of the two-dof point
// constraint, linearized at the prediction. That direction is the robot turning about the lamp,
// which one lamp cannot see (the wheels move the robot in its own frame): the heading comes from
// the next lamp, which the position held at this one now places.
PoseMeasurement point_measurement(const Term& t, const std::vector<LabelledLamp>& lamps,
                                  const Pose2& predicted, Stamp stamp,
                                  const PoseMeasurementOptions& o, double tilt_shift) {
  constexpr double kFreeHeadingSigma = 10.0;  // rad: information 1e-2, nothing beside a prior's
  const double c = std::cos(predicted.yaw()), s = std::sin(predicted.yaw());
  Matrix2d R, dR;
  R << c, -s, s, c;
  dR << -s, -c, c, -s;
  const Matrix2d position_cov =
      R * t.base_cov * R.transpose() +
      (o.map_sigma * o.map_sigma + tilt_shift * tilt_shift) * Matrix2d::Identity();
  Vector3d j;
  j << -dR * t.base, 1.0;
  PoseMeasurement m;
  m.stamp = stamp;
  const Vector2d p = t.map_xy - R * t.base;
  m.pose = Pose2(p.x(), p.y(), predicted.yaw());
  m.covariance = kFreeHeadingSigma * kFreeHeadingSigma * j * j.transpose();
  m.covariance.topLeftCorner<2, 2>() += position_cov;
  m.heading_measured = false;
  m.lamps = lamp_ids(lamps);
  return m;
}

}  // namespace

std::optional<PoseMeasurement> measure_pose(const CeilingGeometry& geometry,
                                            const vision::PinholeCamera& camera,
                                            const std::vector<LabelledLamp>& lamps,
                                            const Pose2& predicted, Stamp stamp,
                                            const PoseMeasurementOptions& o, std::string* why,
                                            PoseRefusal* refusal) {
  if (refusal) *refusal = PoseRefusal::none;
  auto refuse = [&](PoseRefusal kind, const std::string& reason) -> std::optional<PoseMeasurement> {
    if (why) *why = reason;
    if (refusal) *refusal = kind;
    return std::nullopt;
  };
  std::vector<Term> terms;
  double height_sum = 0;
  for (const auto& l : lamps) {
    const auto& d = l.detection;
    if (!l.lamp || d.view == vision::LampView::partial) continue;
    const bool completed = d.view == vision::LampView::completed;
    const double sp = completed ? o.completed_pixel_sigma : o.pixel_sigma;
    Term t;
    Matrix2d J;
    const auto b = geometry.base_point(d.centre, l.lamp->xyz.z(), &J);
    if (!b) continue;
    t.map_xy = l.lamp->xyz.head<2>();
    t.base = *b;
    // The centre's error in the normalized plane: the pixel's, through the lens where it is seen;
    // and a floor bump's beyond what it moves every lamp alike (added to the fit's covariance
    // below), which grows off the axis: a wide lens's corner lamp moves several times as far.
    const Matrix2d T = CeilingGeometry::tilt_jacobian(d.centre);
    const Matrix2d n_cov = camera.normalized_covariance(d.centre, sp) +
                           o.tilt_sigma * o.tilt_sigma * (T * T.transpose() - Matrix2d::Identity());
    t.base_cov = J * n_cov * J.transpose();
    if (l.lamp->shape == graph::LampShape::rectangle && l.lamp->length > l.lamp->width) {
      const auto dir = geometry.base_direction(d.centre, d.orientation, l.lamp->xyz.z());
      if (dir) {
        t.has_axis = true;
        t.map_yaw = l.lamp->yaw;
        t.base_yaw = *dir;
        const double so = completed ? o.completed_orientation_sigma : o.orientation_sigma;
        t.axis_var = so * so;
      }
    }
    terms.push_back(t);
    height_sum += l.lamp->xyz.z();
  }
  if (terms.empty())
    return refuse(PoseRefusal::no_usable_lamp, "no fully visible or completed labelled lamp");
  int axes = 0;
  for (const auto& t : terms) axes += t.has_axis;
  const double tilt_shift = height_sum / terms.size() * o.tilt_sigma;
  if (terms.size() == 1 && axes == 0) {
    if (!o.round_lamp_position)
      return refuse(PoseRefusal::round_lamp_no_heading, "one round lamp does not give the heading");
    return point_measurement(terms.front(), lamps, predicted, stamp, o, tilt_shift);
  }

  // Initial heading: a lamp's axis, on the branch (of two, pi apart) nearest the prediction;
  // without axes, the direction between the first two lamps.
  double yaw = predicted.yaw();
  if (axes > 0) {
    for (const auto& t : terms) {
      if (!t.has_axis) continue;
      const double y0 = t.map_yaw - t.base_yaw;
      yaw = predicted.yaw() + wrap_axis_angle(y0 - predicted.yaw());
      break;
    }
  } else {
    const Vector2d dm = terms[1].map_xy - terms[0].map_xy, db = terms[1].base - terms[0].base;
    yaw = std::atan2(dm.y(), dm.x()) - std::atan2(db.y(), db.x());
  }
  auto rot = [](double a) {
    Matrix2d R;
    R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    return R;
  };
  Vector2d t0 = Vector2d::Zero();
  for (const auto& t : terms) t0 += t.map_xy - rot(yaw) * t.base;
  Vector3d x(t0.x() / terms.size(), t0.y() / terms.size(), yaw);

  // Gauss-Newton on (x, y, yaw): position residuals m - (t + R b), axis residuals wrapped mod pi.
  Matrix3d H = Matrix3d::Zero();
  double chi2 = 0;
  for (int it = 0; it < 8; ++it) {
    H.setZero();
    Vector3d g = Vector3d::Zero();
    chi2 = 0;
    const Matrix2d R = rot(x.z());
    Matrix2d dR;
    dR << -std::sin(x.z()), -std::cos(x.z()), std::cos(x.z()), -std::sin(x.z());
    for (const auto& t : terms) {
      const Vector2d e = t.map_xy - x.head<2>() - R * t.base;
      Eigen::Matrix<double, 2, 3> J;
      J.leftCols<2>() = -Matrix2d::Identity();
      J.col(2) = -dR * t.base;
      const Matrix2d W =
          (R * t.base_cov * R.transpose() + o.map_sigma * o.map_sigma * Matrix2d::Identity())
              .inverse();
      H += J.transpose() * W * J;
      g += J.transpose() * W * e;
      chi2 += e.dot(W * e);
      if (t.has_axis) {
        const double r = wrap_axis_angle(t.map_yaw - x.z() - t.base_yaw);
        H(2, 2) += 1.0 / t.axis_var;
        g(2) += -r / t.axis_var;
        chi2 += r * r / t.axis_var;
      }
    }
    const Vector3d step = -H.ldlt().solve(g);
    if (!step.allFinite())
      return refuse(PoseRefusal::undetermined, "the lamps do not determine the pose");
    x += step;
    if (step.head<2>().norm() < 1e-9 && std::fabs(step.z()) < 1e-10) break;
  }
  const int dof = static_cast<int>(2 * terms.size()) + axes - 3;
  const double limit = dof <= 0 ? 0 : chi_square_quantile(o.consistency_probability, dof);
  if (dof > 0 && chi2 > limit)
    return refuse(PoseRefusal::labels_disagree,
                  "the lamps disagree on the pose (chi2 " + std::to_string(chi2) + " over " +
                      std::to_string(dof) + " dof): a lamp is mislabelled");
  PoseMeasurement m;
  m.stamp = stamp;
  m.pose = Pose2(x.x(), x.y(), wrap_angle(x.z()));
  m.covariance = H.inverse();
  // A tilt moves the view of every lamp alike, by the lamp height times the angle.
  m.covariance.topLeftCorner<2, 2>() += tilt_shift * tilt_shift * Matrix2d::Identity();
  m.covariance = 0.5 * (m.covariance + m.covariance.transpose()).eval();
  m.chi2 = chi2;
  m.dof = std::max(dof, 0);
  m.lamps = lamp_ids(lamps);
  return m;
}

}  // namespace lampnav::fusion
