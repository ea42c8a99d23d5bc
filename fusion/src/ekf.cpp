#include "lampnav/fusion/ekf.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "lampnav/core/error.hpp"
#include "lampnav/fusion/chi_square.hpp"

namespace lampnav::fusion {

using Eigen::Matrix3d;

void EkfOptions::validate() const {
  auto fail = [](const char* field, const char* msg) {
    throw InputError({"", "EKF options", field}, msg);
  };
  if (!(semi_axis > 0 && semi_axis < 10)) fail("semi_axis", "must be between 0 and 10 m");
  if (!(wheel_variance_per_m > 0 && wheel_variance_per_m < 1))
    fail("wheel_variance_per_m", "must be between 0 and 1 m^2 per m");
  if (!(gate_probability > 0.5 && gate_probability < 1))
    fail("gate_probability", "must be between 0.5 and 1");
  if (history <= Duration::zero() || history > std::chrono::seconds(60))
    fail("history", "must be between 0 and 60 s");
  if (!(max_wheel_speed > 0 && max_wheel_speed < 100))
    fail("max_wheel_speed", "must be between 0 and 100 m/s");
  if (!(wheel_jump_slack >= 0 && wheel_jump_slack < 10))
    fail("wheel_jump_slack", "must be 0 to 10 m");
  if (max_pending == 0 || max_pending > 100000) fail("max_pending", "must be 1 to 100000");
}

const char* to_string(Refusal r) {
  switch (r) {
    case Refusal::not_initialized:
      return "not initialized";
    case Refusal::non_finite:
      return "not finite";
    case Refusal::time_backwards:
      return "time going backwards";
    case Refusal::wheel_jump:
      return "absurd wheel jump";
    case Refusal::bad_covariance:
      return "covariance not positive-definite";
    case Refusal::gated:
      return "outside the validation gate";
    case Refusal::too_old:
      return "older than the history";
    case Refusal::too_new:
      return "too far after the latest odometry";
    case Refusal::duplicate:
      return "duplicate";
  }
  return "?";
}

StateVector predict_motion(const StateVector& x, double dl, double dr, double a) {
  const double ds = (dr + dl) / 2, dth = (dr - dl) / (2 * a), mid = x.z() + dth / 2;
  return StateVector(x.x() + ds * std::cos(mid), x.y() + ds * std::sin(mid),
                     wrap_angle(x.z() + dth));
}

void motion_jacobians(const StateVector& x, double dl, double dr, double a, Matrix3d* jx,
                      Eigen::Matrix<double, 3, 2>* ju) {
  const double ds = (dr + dl) / 2, dth = (dr - dl) / (2 * a), mid = x.z() + dth / 2;
  const double c = std::cos(mid), s = std::sin(mid);
  if (jx) {
    *jx << 1, 0, -ds * s,  //
        0, 1, ds * c,      //
        0, 0, 1;
  }
  if (ju) {
    // d mid / d dl = -1/(4a), d mid / d dr = 1/(4a); d ds / d (dl, dr) = 1/2.
    const double q = ds / (4 * a);
    *ju << c / 2 + q * s, c / 2 - q * s,  //
        s / 2 - q * c, s / 2 + q * c,     //
        -1 / (2 * a), 1 / (2 * a);
  }
}

Matrix3d process_noise(const StateVector& x, double dl, double dr, const EkfOptions& o) {
  Eigen::Matrix<double, 3, 2> ju;
  motion_jacobians(x, dl, dr, o.semi_axis, nullptr, &ju);
  const Eigen::Vector2d c(o.wheel_variance_per_m * std::fabs(dl),
                          o.wheel_variance_per_m * std::fabs(dr));
  return ju * c.asDiagonal() * ju.transpose();
}

double covariance_norm(const StateCovariance& P) { return P.norm(); }

bool is_covariance(const Matrix3d& P) {
  if (!P.allFinite()) return false;
  const double scale = P.cwiseAbs().maxCoeff();
  if (!(scale > 0)) return false;
  if ((P - P.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) return false;
  Eigen::LLT<Matrix3d> llt(P);
  if (llt.info() != Eigen::Success) return false;
  // Positive pivots that are not lost in rounding.
  return llt.matrixL().toDenseMatrix().diagonal().minCoeff() > 1e-12 * std::sqrt(scale);
}

namespace {

// The fraction of the way from `a` to `b` at which `t` lies: how an odometry step spanning a
// capture time is split (state_at and split_at must agree exactly).
double fraction(Stamp a, Stamp b, Stamp t) {
  return static_cast<double>((t - a).count()) / static_cast<double>((b - a).count());
}

}  // namespace

std::size_t PoseEkf::first_after(Stamp t) const {
  return static_cast<std::size_t>(
      std::upper_bound(history_.begin(), history_.end(), t,
                       [](Stamp s, const Entry& e) { return s < e.state.stamp; }) -
      history_.begin());
}

PoseEkf::PoseEkf(const EkfOptions& options) : o_(options) {
  o_.validate();
  gate_ = chi_square_quantile(o_.gate_probability, 3);
  history_.reserve(512);
}

void PoseEkf::initialize(Stamp stamp, const Pose2& pose, const StateCovariance& P) {
  if (!std::isfinite(pose.x()) || !std::isfinite(pose.y()) || !std::isfinite(pose.yaw()))
    throw InputError({"", "initial pose", ""}, "is not finite");
  if (!is_covariance(P))
    throw InputError({"", "initial pose", "covariance"}, "is not symmetric positive-definite");
  history_.clear();
  pending_.clear();
  Entry e;
  e.state.stamp = stamp;
  e.state.x = StateVector(pose.x(), pose.y(), wrap_angle(pose.yaw()));
  e.state.P = 0.5 * (P + P.transpose());
  history_.push_back(e);
}

std::uint64_t PoseEkf::total_refusals() const {
  std::uint64_t n = 0;
  for (auto c : refused_) n += c;
  return n;
}

Refusal PoseEkf::refuse(Refusal r) {
  ++refused_[static_cast<int>(r)];
  return r;
}

void PoseEkf::step(const FilterState& from, double dl, double dr, Stamp to,
                   FilterState* out) const {
  Matrix3d jx;
  Eigen::Matrix<double, 3, 2> ju;
  motion_jacobians(from.x, dl, dr, o_.semi_axis, &jx, &ju);
  const Eigen::Vector2d c(o_.wheel_variance_per_m * std::fabs(dl),
                          o_.wheel_variance_per_m * std::fabs(dr));
  out->stamp = to;
  out->x = predict_motion(from.x, dl, dr, o_.semi_axis);
  const Matrix3d P = jx * from.P * jx.transpose() + ju * c.asDiagonal() * ju.transpose();
  out->P = 0.5 * (P + P.transpose());
}

bool PoseEkf::correct(FilterState* s, const StateVector& z, const StateCovariance& R,
                      double* d2) const {
  StateVector nu = z - s->x;
  nu.z() = wrap_angle(nu.z());
  const Matrix3d S = s->P + R;
  const Eigen::LLT<Matrix3d> llt(S);
  *d2 = nu.dot(llt.solve(nu));
  if (!(*d2 <= gate_)) return false;
  // K = P S^-1; S and P are symmetric, so K^T = S^-1 P.
  const Matrix3d K = llt.solve(s->P).transpose();
  s->x += K * nu;
  s->x.z() = wrap_angle(s->x.z());
  const Matrix3d IK = Matrix3d::Identity() - K;
  const Matrix3d P = IK * s->P * IK.transpose() + K * R * K.transpose();  // Joseph form
  s->P = 0.5 * (P + P.transpose());
  return true;
}

void PoseEkf::rerun_from(std::size_t i) {
  for (std::size_t k = std::max<std::size_t>(i, 1); k < history_.size(); ++k) {
    Entry& e = history_[k];
    const FilterState& prev = history_[k - 1].state;
    if (e.measurement) {
      FilterState s = prev;
      s.stamp = e.state.stamp;
      double d2 = 0;
      e.accepted = correct(&s, e.z, e.R, &d2);
      e.state = e.accepted ? s : prev;
      e.state.stamp = s.stamp;
    } else {
      step(prev, e.d_left, e.d_right, e.state.stamp, &e.state);
    }
  }
}

bool PoseEkf::known_measurement(Stamp stamp) const {
  for (std::size_t i = first_after(stamp); i > 0 && history_[i - 1].state.stamp == stamp; --i)
    if (history_[i - 1].measurement) return true;
  return std::any_of(pending_.begin(), pending_.end(),
                     [&](const Pending& p) { return p.stamp == stamp; });
}

std::optional<FilterState> PoseEkf::state_at(Stamp t) const {
  if (history_.empty() || t < history_.front().state.stamp || t > history_.back().state.stamp)
    return std::nullopt;
  const std::size_t i = first_after(t);
  const Entry& prev = history_[i - 1];
  if (i == history_.size() || prev.state.stamp == t) return prev.state;
  // history_[i] is an input entry spanning t: interpolate its increments linearly in time,
  // exactly as split_at() splits it.
  const Entry& later = history_[i];
  const double f = fraction(prev.state.stamp, later.state.stamp, t);
  FilterState s;
  step(prev.state, f * later.d_left, f * later.d_right, t, &s);
  return s;
}

UpdateResult PoseEkf::update(Stamp t, const Pose2& pose, const StateCovariance& R) {
  UpdateResult r;
  r.stamp = t;
  auto refused = [&](Refusal why) {
    r.status = UpdateResult::Status::refused;
    r.refusal = refuse(why);
    return r;
  };
  if (!initialized()) return refused(Refusal::not_initialized);
  const StateVector z(pose.x(), pose.y(), pose.yaw());
  if (!z.allFinite() || !R.allFinite()) return refused(Refusal::non_finite);
  if (!is_covariance(R)) return refused(Refusal::bad_covariance);
  const Stamp latest = history_.back().state.stamp;
  if (t < history_.front().state.stamp || t < latest - o_.history) return refused(Refusal::too_old);
  if (t > latest + o_.history) return refused(Refusal::too_new);
  if (known_measurement(t)) return refused(Refusal::duplicate);
  if (t > latest) {
    if (pending_.size() >= o_.max_pending) return refused(Refusal::too_new);
    Pending p{t, z, 0.5 * (R + R.transpose())};
    pending_.insert(std::upper_bound(pending_.begin(), pending_.end(), t,
                                     [](Stamp s, const Pending& q) { return s < q.stamp; }),
                    p);
    r.status = UpdateResult::Status::pending;
    return r;
  }

  // Gate against the state at the capture time before touching the history.
  const FilterState prior = *state_at(t);
  FilterState post = prior;
  const StateCovariance Rs = 0.5 * (R + R.transpose());
  if (!correct(&post, z, Rs, &r.mahalanobis2)) return refused(Refusal::gated);

  // Insert the measurement after the history's state at t, and re-run what follows.
  const std::size_t i = split_at(t, prior) + 1;
  Entry m;
  m.state = post;
  m.measurement = true;
  m.accepted = true;
  m.z = z;
  m.R = Rs;
  history_.insert(history_.begin() + static_cast<std::ptrdiff_t>(i), m);
  rerun_from(i + 1);
  r.reapplied_steps = static_cast<int>(history_.size() - 1 - i);
  r.status = UpdateResult::Status::applied;
  ++applied_;
  if (r.reapplied_steps > 0) ++late_;
  return r;
}

std::size_t PoseEkf::split_at(Stamp t, const FilterState& at_t) {
  const std::size_t i = first_after(t);
  if (i == history_.size() || history_[i - 1].state.stamp == t) return i - 1;
  // Split the input entry spanning t exactly as state_at() interpolates it.
  Entry& later = history_[i];
  const double f = fraction(history_[i - 1].state.stamp, later.state.stamp, t);
  Entry first;
  first.state = at_t;
  first.d_left = f * later.d_left;
  first.d_right = f * later.d_right;
  later.d_left -= first.d_left;
  later.d_right -= first.d_right;
  history_.insert(history_.begin() + static_cast<std::ptrdiff_t>(i), first);
  return i;
}

std::optional<Refusal> PoseEkf::restart_at(Stamp t, const Pose2& pose, const StateCovariance& P) {
  if (!initialized()) return refuse(Refusal::not_initialized);
  const StateVector x(pose.x(), pose.y(), wrap_angle(pose.yaw()));
  if (!x.allFinite() || !P.allFinite()) return refuse(Refusal::non_finite);
  if (!is_covariance(P)) return refuse(Refusal::bad_covariance);
  const Stamp latest = history_.back().state.stamp;
  if (t < history_.front().state.stamp || t < latest - o_.history) return refuse(Refusal::too_old);
  if (t > latest + o_.history) return refuse(Refusal::too_new);
  if (t >= latest) {
    initialize(t, pose, P);
    return std::nullopt;
  }
  const std::size_t i = split_at(t, *state_at(t));
  history_.erase(history_.begin(), history_.begin() + static_cast<std::ptrdiff_t>(i));
  // Measurements belonged to the estimate that was wrong: only the odometry is re-applied.
  history_.erase(std::remove_if(history_.begin() + 1, history_.end(),
                                [](const Entry& e) { return e.measurement; }),
                 history_.end());
  pending_.clear();
  history_.front().state = FilterState{t, x, 0.5 * (P + P.transpose())};
  history_.front().measurement = false;
  rerun_from(1);
  return std::nullopt;
}

void PoseEkf::trim() {
  // Lazily, in chunks, so that a step costs O(1) on average; the horizon itself is enforced
  // by update()'s too_old test, not by what happens to be kept.
  if (history_.size() < 512) return;
  const std::size_t after = first_after(history_.back().state.stamp - o_.history);
  const std::ptrdiff_t keep_from =
      std::max<std::ptrdiff_t>(0, static_cast<std::ptrdiff_t>(after) - 1);
  if (keep_from < static_cast<std::ptrdiff_t>(history_.size()) / 2) return;
  history_.erase(history_.begin(), history_.begin() + keep_from);
}

std::optional<Refusal> PoseEkf::predict(Stamp t, double dl, double dr,
                                        std::vector<UpdateResult>* pending_results) {
  if (!initialized()) return refuse(Refusal::not_initialized);
  if (!std::isfinite(dl) || !std::isfinite(dr)) return refuse(Refusal::non_finite);
  const Stamp latest = history_.back().state.stamp;
  if (t < latest || (t == latest && (dl != 0 || dr != 0))) return refuse(Refusal::time_backwards);
  const double dt = to_seconds(t - latest);
  if (std::max(std::fabs(dl), std::fabs(dr)) > o_.max_wheel_speed * dt + o_.wheel_jump_slack)
    return refuse(Refusal::wheel_jump);
  if (t == latest) return std::nullopt;

  Entry e;
  step(history_.back().state, dl, dr, t, &e.state);
  e.d_left = dl;
  e.d_right = dr;
  history_.push_back(e);
  // Measurements that were waiting for this reading: inserted like any late one.
  while (!pending_.empty() && pending_.front().stamp <= t) {
    const Pending p = pending_.front();
    pending_.erase(pending_.begin());
    const UpdateResult u = update(p.stamp, Pose2(p.z.x(), p.z.y(), p.z.z()), p.R);
    if (pending_results) pending_results->push_back(u);
  }
  trim();
  return std::nullopt;
}

}  // namespace lampnav::fusion
