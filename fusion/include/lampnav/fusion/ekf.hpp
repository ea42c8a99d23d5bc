#pragma once
// The pose filter the robot drives on (paper 2, section 4): an extended Kalman filter on
// (x, y, yaw) predicted from wheel increments at odometry rate and corrected by pose measurements
// that arrive late. A late measurement is applied at its capture time: the filter keeps a
// time-stamped history of its inputs, states and covariances, goes back to the capture time,
// applies the measurement and re-applies every input (and every measurement) after it
// (paper 2, 4.2). Nothing outside is trusted: bad inputs are refused with a counted reason and
// leave the filter as it was.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "lampnav/core/pose2.hpp"
#include "lampnav/core/time.hpp"

namespace lampnav::fusion {

using StateVector = Eigen::Vector3d;  // x (m), y (m), yaw (rad)
using StateCovariance = Eigen::Matrix3d;

struct EkfOptions {
  double semi_axis = 0.20;             // m, half the wheel track (robot.json)
  double wheel_variance_per_m = 1e-4;  // m^2 per m of a wheel's travel: C = diag(k|dSl|, k|dSr|)
  double gate_probability = 0.99;      // chi-square gate on the 3-dof innovation
  Duration history = std::chrono::seconds(2);  // how late a measurement may be
  double max_wheel_speed = 3.0;                // m/s; a larger increment is an encoder glitch
  double wheel_jump_slack = 0.02;              // m added to max_wheel_speed * dt before refusing
  std::size_t max_pending = 64;                // measurements captured after the latest odometry
  void validate() const;                       // throws InputError naming the field
};

// Why an input was not used. Each is counted; none changes the filter.
enum class Refusal : int {
  not_initialized,  // no pose yet: initialize() first
  non_finite,       // NaN or infinity in a reading, a measurement or its covariance
  time_backwards,   // odometry stamped before (or, with motion, at) the previous reading
  wheel_jump,       // a wheel moved further than the robot can in that time
  bad_covariance,   // a measurement covariance that is not symmetric positive-definite
  gated,            // Mahalanobis distance beyond the chi-square gate
  too_old,          // captured before the history's horizon
  too_new,          // captured more than the horizon after the latest odometry, or too many pending
  duplicate,        // a measurement with this capture stamp was already given
};
inline constexpr int kRefusalCount = 9;
const char* to_string(Refusal refusal);

struct UpdateResult {
  enum class Status { applied, pending, refused } status = Status::refused;
  std::optional<Refusal> refusal;
  Stamp stamp;              // capture time of the measurement
  double mahalanobis2 = 0;  // squared distance of the innovation (when computed)
  int reapplied_steps = 0;  // history entries re-run after it
  bool applied() const { return status == Status::applied; }
};

// The filter at one instant.
struct FilterState {
  Stamp stamp;
  StateVector x = StateVector::Zero();
  StateCovariance P = StateCovariance::Identity();
  Pose2 pose() const { return Pose2(x.x(), x.y(), x.z()); }
};

// Motion model (conventions.md, paper 2 Eqs. 1-3): mid-point unicycle from the wheel increments.
StateVector predict_motion(const StateVector& x, double d_left, double d_right, double semi_axis);
// Its Jacobians: wrt the state, and wrt the wheel increments (d_left, d_right).
void motion_jacobians(const StateVector& x, double d_left, double d_right, double semi_axis,
                      Eigen::Matrix3d* jx, Eigen::Matrix<double, 3, 2>* ju);
// The process noise Q(U) = Ju C Ju^T with C = diag(k |dSl|, k |dSr|) (paper 2, Eqs. 4-5).
Eigen::Matrix3d process_noise(const StateVector& x, double d_left, double d_right,
                              const EkfOptions& options);
// A scalar summary of P for plots over time (paper 2, Fig. 7): its Frobenius norm.
double covariance_norm(const StateCovariance& P);
// True when P is finite, symmetric (relative 1e-9) and positive-definite.
bool is_covariance(const Eigen::Matrix3d& P);

class PoseEkf {
 public:
  explicit PoseEkf(const EkfOptions& options = {});

  // Starts (or restarts, e.g. after relocalization) at `pose` with covariance `P`; forgets the
  // history. Throws InputError when the pose is not finite or P is not a covariance.
  void initialize(Stamp stamp, const Pose2& pose, const StateCovariance& P);
  bool initialized() const { return !history_.empty(); }

  // Wheel increments (m) since the previous reading, measured at `stamp`. Pending measurements
  // whose capture time this reading covers are applied on the way; their results are returned.
  std::optional<Refusal> predict(Stamp stamp, double d_left, double d_right,
                                 std::vector<UpdateResult>* pending_results = nullptr);

  // A pose measurement captured at `stamp` with covariance R (H = I). Applied at its capture
  // time; when that is after the latest odometry it waits for the reading that covers it.
  UpdateResult update(Stamp stamp, const Pose2& z, const StateCovariance& R);

  // Restarts from a pose known at `stamp` (a relocalization captured then) and re-applies the
  // odometry after it. Measurements in the history are dropped: they were labelled with the
  // estimate being replaced. Refused like a measurement when outside the history.
  std::optional<Refusal> restart_at(Stamp stamp, const Pose2& pose, const StateCovariance& P);

  // The estimate at the latest odometry.
  const FilterState& current() const { return history_.back().state; }
  Pose2 pose() const { return current().pose(); }
  const StateCovariance& covariance() const { return current().P; }
  Stamp stamp() const { return current().stamp; }
  // The estimate at an earlier instant inside the history (e.g. a frame's capture time, to label
  // its lamps), predicted from the entry before it with the covering input interpolated.
  // nullopt when `stamp` is before the history or after the latest odometry.
  std::optional<FilterState> state_at(Stamp stamp) const;
  Stamp oldest() const { return history_.front().state.stamp; }

  std::uint64_t refusals(Refusal r) const { return refused_[static_cast<int>(r)]; }
  std::uint64_t total_refusals() const;
  std::uint64_t updates_applied() const { return applied_; }
  std::uint64_t late_updates() const { return late_; }  // applied with at least one re-run step
  std::size_t history_size() const { return history_.size(); }
  std::size_t pending_size() const { return pending_.size(); }
  const EkfOptions& options() const { return o_; }

 private:
  struct Entry {
    FilterState state;               // after this entry
    double d_left = 0, d_right = 0;  // the input that led here from the previous entry
    bool measurement = false;        // an update entry (its input is zero)
    bool accepted = false;           // the measurement passed the gate when last run
    StateVector z = StateVector::Zero();
    StateCovariance R = StateCovariance::Zero();
  };
  struct Pending {
    Stamp stamp;
    StateVector z;
    StateCovariance R;
  };

  Refusal refuse(Refusal r);
  void step(const FilterState& from, double d_left, double d_right, Stamp to,
            FilterState* out) const;
  // Runs a gated update of `s` in place; returns the squared Mahalanobis distance and whether it
  // passed the gate.
  bool correct(FilterState* s, const StateVector& z, const StateCovariance& R, double* d2) const;
  // Makes the history have an entry ending exactly at t (splitting the input spanning it, whose
  // first part ends in `at_t`); returns its index.
  std::size_t split_at(Stamp t, const FilterState& at_t);
  // Recomputes the entries from `index` on from the one before it (re-gating measurements).
  void rerun_from(std::size_t index);
  void trim();
  bool known_measurement(Stamp stamp) const;
  // Index of the first history entry stamped after t (history_.size() when none is).
  std::size_t first_after(Stamp t) const;

  EkfOptions o_;
  double gate_;
  std::vector<Entry> history_;  // time-ordered; front is the oldest kept state
  std::vector<Pending> pending_;
  std::array<std::uint64_t, kRefusalCount> refused_{};
  std::uint64_t applied_ = 0, late_ = 0;
};

}  // namespace lampnav::fusion
