// The pose EKF: motion model and Jacobians, gated Joseph-form update, late measurements applied at
// their capture time (equal to the on-time result), refusals of bad input, and a property battery
// on the covariance.

#include "lampnav/fusion/ekf.hpp"

#include <Eigen/Eigenvalues>
#include <random>

#include "lampnav/core/error.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fusion {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

Stamp ms(double v) { return stamp_from_seconds(v / 1000.0); }

Matrix3d diag(double a, double b, double c) { return Vector3d(a, b, c).asDiagonal(); }

TEST(Ekf, MotionJacobiansMatchNumericalDerivatives) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const double a = 0.2;
  for (int k = 0; k < 200; ++k) {
    const Vector3d x(5 * u(rng), 5 * u(rng), M_PI * u(rng));
    const Vector2d w(0.05 * u(rng), 0.05 * u(rng));
    Matrix3d jx;
    Eigen::Matrix<double, 3, 2> ju;
    motion_jacobians(x, w(0), w(1), a, &jx, &ju);
    const Matrix3d njx = test::numerical_jacobian<3, 3>(
        [&](const Vector3d& s) {
          Vector3d r = predict_motion(s, w(0), w(1), a);
          r.z() = s.z() + (w(1) - w(0)) / (2 * a);  // unwrapped, for differencing
          return r;
        },
        x);
    const auto nju = test::numerical_jacobian<3, 2>(
        [&](const Vector2d& v) {
          Vector3d r = predict_motion(x, v(0), v(1), a);
          r.z() = x.z() + (v(1) - v(0)) / (2 * a);
          return r;
        },
        w);
    EXPECT_LT((jx - njx).cwiseAbs().maxCoeff(), 1e-8) << k;
    EXPECT_LT((ju - nju).cwiseAbs().maxCoeff(), 1e-8) << k;
  }
}

TEST(Ekf, MotionFollowsConventions) {
  // A quarter circle of radius 1 m in 100 steps ends near (1, 1) facing +y.
  const double a = 0.2;
  Vector3d x = Vector3d::Zero();
  const double arc = M_PI / 2 / 100;
  for (int i = 0; i < 100; ++i) x = predict_motion(x, arc * (1 - a), arc * (1 + a), a);
  EXPECT_NEAR(x.x(), 1.0, 1e-4);
  EXPECT_NEAR(x.y(), 1.0, 1e-4);
  EXPECT_NEAR(x.z(), M_PI / 2, 1e-12);
}

TEST(Ekf, ProcessNoiseGrowsWithTravelAndVanishesAtRest) {
  const EkfOptions o;
  const Vector3d x(0, 0, 0.3);
  EXPECT_EQ(process_noise(x, 0, 0, o).norm(), 0.0);
  const Matrix3d q1 = process_noise(x, 0.01, 0.01, o), q2 = process_noise(x, 0.02, 0.02, o);
  EXPECT_GT(q2.trace(), 1.9 * q1.trace());
  // Straight ahead: the along-track variance is k|d|/2 (two independent wheels, mean of them).
  const Matrix3d q = process_noise(Vector3d::Zero(), 0.01, 0.01, o);
  EXPECT_NEAR(q(0, 0), o.wheel_variance_per_m * 0.01 / 2, 1e-15);
  EXPECT_NEAR(q(2, 2), 2 * o.wheel_variance_per_m * 0.01 / (4 * o.semi_axis * o.semi_axis), 1e-15);
}

TEST(Ekf, PredictionGrowsCovarianceAndUpdateShrinksIt) {
  PoseEkf f;
  f.initialize(ms(0), Pose2(1, 2, 0.5), diag(1e-4, 1e-4, 1e-4));
  for (int i = 1; i <= 100; ++i) ASSERT_FALSE(f.predict(ms(10 * i), 0.005, 0.006));
  const double grown = f.covariance().trace();
  EXPECT_GT(grown, 3e-4);
  const Pose2 before = f.pose();
  const UpdateResult r = f.update(ms(1000), before, diag(1e-6, 1e-6, 1e-6));
  ASSERT_TRUE(r.applied());
  EXPECT_LT(f.covariance().trace(), 3e-6);
  EXPECT_EQ(f.updates_applied(), 1u);
  EXPECT_EQ(f.late_updates(), 0u);
}

TEST(Ekf, AngleInnovationIsWrapped) {
  PoseEkf f;
  f.initialize(ms(0), Pose2(0, 0, M_PI - 0.02), diag(1e-2, 1e-2, 1e-2));
  const UpdateResult r = f.update(ms(0), Pose2(0, 0, -M_PI + 0.02), diag(1e-2, 1e-2, 1e-2));
  ASSERT_TRUE(r.applied());
  EXPECT_NEAR(std::fabs(f.pose().yaw()), M_PI, 1e-9);  // half way, across the cut
  EXPECT_LT(r.mahalanobis2, 0.1);
}

TEST(Ekf, GateRefusesOutliersAndCountsThem) {
  PoseEkf f;
  f.initialize(ms(0), Pose2(0, 0, 0), diag(1e-4, 1e-4, 1e-4));
  const FilterState before = f.current();
  const UpdateResult r = f.update(ms(0), Pose2(1, 0, 0), diag(1e-4, 1e-4, 1e-4));
  EXPECT_EQ(r.status, UpdateResult::Status::refused);
  EXPECT_EQ(r.refusal, Refusal::gated);
  EXPECT_NEAR(r.mahalanobis2, 1.0 / 2e-4, 1e-6);
  EXPECT_EQ(f.refusals(Refusal::gated), 1u);
  EXPECT_EQ(f.current().x, before.x);
  EXPECT_EQ(f.current().P, before.P);
  // Just inside the 0.99 gate (11.345 for 3 dof) passes.
  const double d = std::sqrt(11.3 * 2e-4);
  PoseEkf g;
  g.initialize(ms(0), Pose2(0, 0, 0), diag(1e-4, 1e-4, 1e-4));
  EXPECT_TRUE(g.update(ms(0), Pose2(d, 0, 0), diag(1e-4, 1e-4, 1e-4)).applied());
}

// Odometry at 100 Hz with a little of everything: turns, speed changes, a reading every 10 ms.
struct Drive {
  std::vector<Stamp> t;
  std::vector<Vector2d> inc;
};
Drive make_drive(std::uint32_t seed, int steps) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Drive d;
  for (int i = 1; i <= steps; ++i) {
    d.t.push_back(ms(10 * i));
    const double v = 0.004 + 0.004 * u(rng), w = 0.002 * (u(rng) - 0.5);
    d.inc.emplace_back(v - w, v + w);
  }
  return d;
}

struct Measurement {
  Stamp captured;
  Pose2 z;
  Matrix3d R;
};

// Feeds the drive; each measurement is given once the first reading at or after
// `captured + delay` has been given (or, with a negative delay, before the covering reading).
PoseEkf run(const Drive& d, std::vector<Measurement> ms_, const std::vector<Duration>& delays) {
  PoseEkf f;
  f.initialize(stamp_from_seconds(0), Pose2(0, 0, 0.1), diag(1e-3, 1e-3, 1e-3));
  std::vector<bool> given(ms_.size(), false);
  for (std::size_t i = 0; i < d.t.size(); ++i) {
    for (std::size_t k = 0; k < ms_.size(); ++k) {
      if (!given[k] && delays[k] < Duration::zero() && d.t[i] >= ms_[k].captured) {
        EXPECT_EQ(f.update(ms_[k].captured, ms_[k].z, ms_[k].R).status,
                  UpdateResult::Status::pending);
        given[k] = true;
      }
    }
    EXPECT_FALSE(f.predict(d.t[i], d.inc[i].x(), d.inc[i].y()));
    for (std::size_t k = 0; k < ms_.size(); ++k) {
      if (!given[k] && delays[k] >= Duration::zero() && d.t[i] >= ms_[k].captured + delays[k]) {
        EXPECT_TRUE(f.update(ms_[k].captured, ms_[k].z, ms_[k].R).applied());
        given[k] = true;
      }
    }
  }
  return f;
}

TEST(Ekf, LateMeasurementEqualsOnTimeResult) {
  const Drive d = make_drive(3, 500);  // 5 s
  const PoseEkf none = run(d, {}, {});
  // Measurements a few centimetres off the dead-reckoned path, at and between odometry readings.
  std::vector<Measurement> m;
  const double at[] = {1.2345, 2.0, 2.5031};
  const Vector3d off[] = {{0.03, -0.02, 0.01}, {-0.02, 0.04, -0.02}, {0.01, 0.01, 0.015}};
  for (int k = 0; k < 3; ++k) {
    // Dead reckoning is still inside the history at 5 s only for t >= 3 s: recompute it.
    PoseEkf ref;
    ref.initialize(stamp_from_seconds(0), Pose2(0, 0, 0.1), diag(1e-3, 1e-3, 1e-3));
    for (std::size_t i = 0; i < d.t.size() && d.t[i] < stamp_from_seconds(at[k] + 0.02); ++i)
      ref.predict(d.t[i], d.inc[i].x(), d.inc[i].y());
    const Vector3d x = ref.state_at(stamp_from_seconds(at[k]))->x + off[k];
    m.push_back({stamp_from_seconds(at[k]), Pose2(x.x(), x.y(), x.z()), diag(4e-4, 4e-4, 1e-4)});
  }
  using std::chrono::milliseconds;
  const PoseEkf on_time = run(d, m, {milliseconds(0), milliseconds(0), milliseconds(0)});
  // The camera is 1 s late, and the measurements arrive out of order.
  const PoseEkf late = run(d, m, {milliseconds(1000), milliseconds(1400), milliseconds(700)});
  // Captured after the latest odometry: held until the reading that covers it.
  const PoseEkf early = run(d, m, {milliseconds(-1), milliseconds(-1), milliseconds(-1)});
  EXPECT_EQ(on_time.updates_applied(), 3u);
  EXPECT_EQ(late.updates_applied(), 3u);
  EXPECT_EQ(late.late_updates(), 3u);
  for (const PoseEkf* f : {&late, &early}) {
    EXPECT_LT((f->current().x - on_time.current().x).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((f->covariance() - on_time.covariance()).cwiseAbs().maxCoeff(), 1e-9);
    for (double s : {1.0, 1.2345, 2.2, 4.5}) {
      if (stamp_from_seconds(s) < f->oldest()) continue;
      const auto a = f->state_at(stamp_from_seconds(s)),
                 b = on_time.state_at(stamp_from_seconds(s));
      ASSERT_TRUE(a && b);
      EXPECT_LT((a->x - b->x).cwiseAbs().maxCoeff(), 1e-9) << s;
    }
  }
  // And the measurements did something: without them the estimate is elsewhere.
  EXPECT_GT((none.current().x - on_time.current().x).head<2>().norm(), 0.01);
}

TEST(Ekf, StateAtInterpolatesBetweenReadings) {
  PoseEkf f;
  f.initialize(ms(0), Pose2(0, 0, 0), diag(1e-4, 1e-4, 1e-4));
  ASSERT_FALSE(f.predict(ms(20), 0.02, 0.02));
  const auto half = f.state_at(ms(10));
  ASSERT_TRUE(half);
  EXPECT_NEAR(half->x.x(), 0.01, 1e-12);
  EXPECT_FALSE(f.state_at(ms(21)));
  EXPECT_FALSE(f.state_at(ms(-1)));
}

TEST(Ekf, RefusesMeasurementsOutsideTheHistoryAndDuplicates) {
  PoseEkf f;
  f.initialize(ms(0), Pose2(0, 0, 0), diag(1e-2, 1e-2, 1e-2));
  for (int i = 1; i <= 500; ++i) ASSERT_FALSE(f.predict(ms(10 * i), 0.005, 0.005));
  const Matrix3d R = diag(1e-3, 1e-3, 1e-3);
  const FilterState before = f.current();
  // History is 2 s: 5.0 - 2.0 = 3.0 s is the oldest accepted capture.
  EXPECT_EQ(f.update(ms(2999), Pose2(1.5, 0, 0), R).refusal, Refusal::too_old);
  EXPECT_EQ(f.update(ms(7001), Pose2(2.5, 0, 0), R).refusal, Refusal::too_new);
  EXPECT_EQ(f.current().x, before.x);
  ASSERT_TRUE(f.update(ms(3000), f.state_at(ms(3000))->pose(), R).applied());
  EXPECT_EQ(f.update(ms(3000), f.state_at(ms(3000))->pose(), R).refusal, Refusal::duplicate);
  EXPECT_EQ(f.refusals(Refusal::too_old), 1u);
  EXPECT_EQ(f.refusals(Refusal::too_new), 1u);
  EXPECT_EQ(f.refusals(Refusal::duplicate), 1u);
  // Long runs keep the history bounded.
  for (int i = 501; i <= 20000; ++i) ASSERT_FALSE(f.predict(ms(10 * i), 0.005, 0.005));
  EXPECT_LT(f.history_size(), 1100u);
}

TEST(Ekf, RefusesBadInputAndStaysHealthy) {
  PoseEkf f;
  EXPECT_EQ(f.predict(ms(10), 0.01, 0.01), Refusal::not_initialized);
  EXPECT_EQ(f.update(ms(10), Pose2(), diag(1, 1, 1)).refusal, Refusal::not_initialized);
  f.initialize(ms(0), Pose2(0, 0, 0), diag(1e-4, 1e-4, 1e-4));
  ASSERT_FALSE(f.predict(ms(10), 0.005, 0.005));
  const FilterState before = f.current();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(f.predict(ms(20), nan, 0.005), Refusal::non_finite);
  EXPECT_EQ(f.predict(ms(20), 0.005, inf), Refusal::non_finite);
  EXPECT_EQ(f.predict(ms(5), 0.005, 0.005), Refusal::time_backwards);
  EXPECT_EQ(f.predict(ms(10), 0.005, 0.005), Refusal::time_backwards);
  EXPECT_FALSE(f.predict(ms(10), 0, 0));  // a repeated reading with no motion is harmless
  EXPECT_EQ(f.predict(ms(20), 5.0, 5.0), Refusal::wheel_jump);
  EXPECT_EQ(f.predict(ms(20), -0.2, 0.005), Refusal::wheel_jump);
  EXPECT_EQ(f.update(ms(10), Pose2(nan, 0, 0), diag(1, 1, 1)).refusal, Refusal::non_finite);
  EXPECT_EQ(f.update(ms(10), Pose2(0, 0, 0), diag(1, nan, 1)).refusal, Refusal::non_finite);
  EXPECT_EQ(f.update(ms(10), Pose2(0, 0, 0), diag(1, 0, 1)).refusal, Refusal::bad_covariance);
  EXPECT_EQ(f.update(ms(10), Pose2(0, 0, 0), diag(1, -1, 1)).refusal, Refusal::bad_covariance);
  Matrix3d asym = diag(1, 1, 1);
  asym(0, 1) = 0.5;
  EXPECT_EQ(f.update(ms(10), Pose2(0, 0, 0), asym).refusal, Refusal::bad_covariance);
  EXPECT_EQ(f.refusals(Refusal::non_finite), 4u);
  EXPECT_EQ(f.refusals(Refusal::time_backwards), 2u);
  EXPECT_EQ(f.refusals(Refusal::wheel_jump), 2u);
  EXPECT_EQ(f.refusals(Refusal::bad_covariance), 3u);
  EXPECT_EQ(f.current().x, before.x);
  EXPECT_EQ(f.current().P, before.P);
  EXPECT_EQ(f.current().stamp, before.stamp);
  EXPECT_FALSE(f.predict(ms(20), 0.005, 0.005));
  EXPECT_TRUE(is_covariance(f.covariance()));
  EXPECT_THROW(f.initialize(ms(0), Pose2(0, 0, 0), diag(1, 0, 1)), InputError);
  EXPECT_THROW(f.initialize(ms(0), Pose2(nan, 0, 0), diag(1, 1, 1)), InputError);
  EkfOptions bad;
  bad.semi_axis = 0;
  EXPECT_THROW(PoseEkf{bad}, InputError);
}

// Thousands of random sequences of predictions, updates (on time, late, out of order, bad), tiny
// and huge covariances: P stays symmetric positive-definite after every step.
TEST(Ekf, CovarianceStaysSymmetricPositiveDefinite) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  auto logu = [&](double lo, double hi) {
    return std::exp(std::log(lo) + u(rng) * std::log(hi / lo));
  };
  int updates = 0, checks = 0;
  for (int seq = 0; seq < 3000; ++seq) {
    PoseEkf f;
    const double p0 = logu(1e-8, 1e2);
    f.initialize(ms(0), Pose2(10 * u(rng), 10 * u(rng), 6 * u(rng) - 3),
                 diag(p0, p0 * u(rng) + 1e-9, logu(1e-9, 1)));
    Stamp t = ms(0);
    for (int k = 0; k < 60; ++k) {
      const double r = u(rng);
      if (r < 0.6) {
        t += std::chrono::milliseconds(1 + static_cast<int>(30 * u(rng)));
        f.predict(t, 0.02 * (u(rng) - 0.3), 0.02 * (u(rng) - 0.3));
      } else {
        // A measurement near the estimate at a random earlier instant, any covariance shape.
        const Stamp c = t - std::chrono::milliseconds(static_cast<int>(1500 * u(rng)));
        Eigen::Matrix3d A = Eigen::Matrix3d::Random() * std::sqrt(logu(1e-9, 1e1));
        Matrix3d R = A * A.transpose() + logu(1e-12, 1e-3) * Matrix3d::Identity();
        const Pose2 z(f.pose().x() + 0.05 * (u(rng) - 0.5), f.pose().y() + 0.05 * (u(rng) - 0.5),
                      f.pose().yaw() + 0.1 * (u(rng) - 0.5));
        if (f.update(c, z, R).applied()) ++updates;
      }
      ++checks;
      const Matrix3d& P = f.covariance();
      ASSERT_TRUE(is_covariance(P)) << "sequence " << seq << " step " << k << "\n" << P;
      ASSERT_GT(Eigen::SelfAdjointEigenSolver<Matrix3d>(P).eigenvalues().minCoeff(), 0);
    }
  }
  EXPECT_GT(updates, 5000);
  EXPECT_EQ(checks, 3000 * 60);
}

TEST(Ekf, CovarianceNormIsFrobenius) {
  EXPECT_DOUBLE_EQ(covariance_norm(diag(3, 4, 0) + 1e-300 * Matrix3d::Identity()), 5.0);
}

}  // namespace
}  // namespace lampnav::fusion
