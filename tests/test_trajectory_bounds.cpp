// The per-sample accumulator's new measures and the rules built on them, for the three trajectory
// loops (closed-form 3R, the fixed-size planar chain, the general chain): tracking and orientation
// errors, joint-limit ratios and the torque/force split against the run's own history (an
// independent recomputation from the stored samples and the path), the bound rules (mark, stop,
// ignore), and closed-loop feedback (CLIK) pulling the tip onto the path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "methods/chain/trajectory.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "methods/base/trajectory.hpp"
#include "methods/closed_form/lanes.hpp"
#include "methods/metrics/sample_metrics.hpp"
#include "model/chain_dynamics.hpp"

using namespace ks;

namespace {

Chain planar5() { return planar_chain(planar_bars({1.0, 0.5, 0.5, 0.5, 0.5}, {5, 1, 1, 0.5, 0.5}, 0.1)); }

/// planar5() with its middle joint made prismatic along the link (a P joint in a planar chain): the
/// general chain loop.
Chain planar_rpr() {
  Chain c = planar_chain(planar_bars({1.0, 1.0, 1.0}, {5, 2, 1}, 0.1));
  c.joints[1].type = JointType::prismatic;
  c.joints[1].axis = Eigen::Vector3d::UnitX();
  c.prepare();
  return c;
}

TrajectoryOptions base_options() {
  TrajectoryOptions o;
  o.alpha1A = 0.2;
  o.vertex_alpha = {0.5, 0.3, 0.0, 0.2};
  o.on_violation = OnViolation::ignore;  // the open loop drifts past the default bound on this 5R
  return o;
}

/// max and mean of |x_c - path(t_c)| over a full history (stride 1): the oracle of the tracking metrics.
template <class History, class Path>
void history_tracking(const History& h, const Path& path, double& max_err, double& mean_err) {
  max_err = 0, mean_err = 0;
  for (Eigen::Index c = 0; c < h.size; ++c) {
    const auto p = path.sample(h.t[c]).p;
    double e2 = 0;
    for (int r = 0; r < h.x.rows(); ++r) e2 += (h.x(r, c) - p[r]) * (h.x(r, c) - p[r]);
    max_err = std::max(max_err, std::sqrt(e2));
    mean_err += std::sqrt(e2);
  }
  mean_err /= static_cast<double>(h.size);
}

}  // namespace

// The tracking metrics equal their recomputation from the history and the path (every loop).
TEST(TrajectoryBounds, TrackingMetricsMatchTheHistory) {
  const Path2 square = seed_square();
  for (const SeedCase& c : seed_cases()) {
    SCOPED_TRACE(c.name);
    TrajectoryOptions o = c.options();
    TrajectoryHistory h;
    const TrajectoryMetrics m = simulate(PlanarArm3::seed(), square, o, &h);
    double mx, mean;
    history_tracking(h, square, mx, mean);
    EXPECT_NEAR(m.max_tracking_error, mx, 1e-15);
    EXPECT_NEAR(m.mean_tracking_error, mean, 1e-12 * std::max(1.0, mean));
    EXPECT_LE(m.mean_tracking_error, m.max_tracking_error);
    if (c.method == TrajectoryMethod::vertex_alpha) {
      EXPECT_FALSE(std::isnan(m.max_orientation_error));
    } else {
      EXPECT_TRUE(std::isnan(m.max_orientation_error));
    }
  }
  const Chain chain = planar5();
  const Path3 path = lift_to_3d(square);
  for (TaskSpace space : {TaskSpace::planar_position, TaskSpace::planar_pose}) {
    TrajectoryOptions o = base_options();
    ChainHistory h;
    const TrajectoryMetrics m = simulate(chain, ChainTask(space, path, o.dt), planar_start_guess(5), o, &h);
    ASSERT_EQ(m.status, RunStatus::ok);
    double mx, mean;
    history_tracking(h, path, mx, mean);
    EXPECT_NEAR(m.max_tracking_error, mx, 1e-15);
    EXPECT_NEAR(m.mean_tracking_error, mean, 1e-12);
    if (space == TaskSpace::planar_pose) {
      // the orientation error: |alpha - the tip angle's quintic through alpha1A and vertex_alpha|
      std::vector<Eigen::Matrix<double, 1, 1>> a{Eigen::Matrix<double, 1, 1>(o.alpha1A)};
      for (double v : o.vertex_alpha) a.emplace_back(v);
      const Profile1 alpha(std::move(a), path.durations());
      double worst = 0;
      for (Eigen::Index c = 0; c < h.size; ++c) worst = std::max(worst, std::abs(h.alpha[c] - alpha.sample(h.t[c]).p[0]));
      EXPECT_NEAR(m.max_orientation_error, worst, 1e-12);
    } else {
      EXPECT_TRUE(std::isnan(m.max_orientation_error));
    }
  }
}

// Closed-loop feedback pulls the tip onto the path: with K_P = 400/s^2, K_D = 40/s the drift of every
// loop falls below 1 mm where the open loop drifts centimetres; the run still starts on the path.
TEST(TrajectoryBounds, ClosedLoopFeedbackTracksThePath) {
  const Path2 square = seed_square();
  {
    TrajectoryOptions o = seed_cases()[0].options();
    const TrajectoryMetrics open = simulate(PlanarArm3::seed(), square, o);
    o.clik_kp = 400, o.clik_kd = 40;
    const TrajectoryMetrics closed = simulate(PlanarArm3::seed(), square, o);
    ASSERT_EQ(closed.status, RunStatus::ok);
    EXPECT_LT(closed.max_tracking_error, 1e-3);
    EXPECT_LT(closed.max_tracking_error, open.max_tracking_error);
  }
  const Chain chain = planar5();
  const Path3 path = lift_to_3d(square);
  for (TaskSpace space : {TaskSpace::planar_position, TaskSpace::planar_pose})
    for (Integrator integ : {Integrator::semi_implicit_euler, Integrator::rk4}) {
      TrajectoryOptions o = base_options();
      o.integrator = integ;
      o.k = 0.5;
      const TrajectoryMetrics open = simulate(chain, ChainTask(space, path, o.dt), planar_start_guess(5), o);
      o.clik_kp = 400, o.clik_kd = 40;
      const TrajectoryMetrics closed = simulate(chain, ChainTask(space, path, o.dt), planar_start_guess(5), o);
      SCOPED_TRACE(std::string(to_string(space)) + " " + std::string(to_string(integ)));
      ASSERT_EQ(closed.status, RunStatus::ok);
      // RK4: within 1 mm; semi-implicit Euler's first-order step error is only divided by the gains
      // (measured 16-29 mm here, against the open loop's drift)
      if (integ == Integrator::rk4) {
        EXPECT_LT(closed.max_tracking_error, 1e-3);
      }
      EXPECT_LE(closed.max_tracking_error, open.max_tracking_error);
      if (space == TaskSpace::planar_pose && integ == Integrator::rk4) {
        EXPECT_LT(closed.max_orientation_error, 1e-3);
      }
    }
}

// The bound rules: a tracking bound below the drift marks the run off_path with every metric kept
// (mark), ends it at the first sample beyond the bound with NaN metrics (stop), or changes nothing
// (ignore); the first sample beyond the bound is the history's.
TEST(TrajectoryBounds, TrackingBoundMarksStopsOrIgnores) {
  const Path2 square = seed_square();
  TrajectoryOptions o = seed_cases()[0].options();
  TrajectoryHistory h;
  const TrajectoryMetrics free = simulate(PlanarArm3::seed(), square, o, &h);
  ASSERT_EQ(free.status, RunStatus::ok);
  o.tracking_bound = 0.5 * free.max_tracking_error;
  // the first sample whose error exceeds the bound, from the history
  Eigen::Index first = -1;
  for (Eigen::Index c = 0; c < h.size && first < 0; ++c)
    if ((h.x.col(c) - square.sample(h.t[c]).p).norm() > o.tracking_bound) first = c;
  ASSERT_GT(first, 0);

  const TrajectoryMetrics mark = simulate(PlanarArm3::seed(), square, o);
  EXPECT_EQ(mark.status, RunStatus::off_path);
  EXPECT_EQ(mark.E, free.E);
  EXPECT_EQ(mark.samples, free.samples);

  o.on_violation = OnViolation::stop;
  const TrajectoryMetrics stop = simulate(PlanarArm3::seed(), square, o);
  EXPECT_EQ(stop.status, RunStatus::off_path);
  EXPECT_EQ(stop.samples, static_cast<std::size_t>(first + 1));
  EXPECT_DOUBLE_EQ(stop.stop_time, h.t[first]);
  EXPECT_TRUE(std::isnan(stop.E));
  EXPECT_TRUE(std::isnan(stop.max_tracking_error));

  o.on_violation = OnViolation::ignore;
  const TrajectoryMetrics ignore = simulate(PlanarArm3::seed(), square, o);
  EXPECT_EQ(ignore.status, RunStatus::ok);
  EXPECT_EQ(ignore.E, free.E);
}

// Joint limits: the ratios equal their recomputation from the history; limits below what the run
// reaches mark it out_of_limits (or stop it); limits above leave it ok. Continuous joints (no
// limits) give NaN ratios.
TEST(TrajectoryBounds, JointLimitRatiosAndStatus) {
  const Path3 path = lift_to_3d(seed_square());
  Chain chain = planar5();
  TrajectoryOptions o = base_options();
  {
    ChainHistory h;
    const TrajectoryMetrics m = simulate(chain, ChainTask(TaskSpace::planar_position, path, o.dt), planar_start_guess(5), o, &h);
    ASSERT_EQ(m.status, RunStatus::ok);
    EXPECT_TRUE(std::isnan(m.max_q_limit_ratio));
    EXPECT_TRUE(std::isnan(m.max_qd_limit_ratio));
    EXPECT_TRUE(std::isnan(m.max_tau_limit_ratio));
  }
  for (ChainJoint& j : chain.joints) {
    j.lower = -2.0, j.upper = 3.0;  // rad: centre 0.5, half range 2.5
    j.velocity = 2.0;               // rad/s
    j.effort = 40.0;                // Nm
  }
  chain.prepare();
  ChainHistory h;
  const TrajectoryMetrics m = simulate(chain, ChainTask(TaskSpace::planar_position, path, o.dt), planar_start_guess(5), o, &h);
  double rq = 0, rv = 0, rt = 0;
  for (Eigen::Index c = 0; c < h.size; ++c)
    for (int j = 0; j < 5; ++j) {
      rq = std::max(rq, std::abs(h.q(j, c) - 0.5) / 2.5);
      rv = std::max(rv, std::abs(h.qd(j, c)) / 2.0);
      rt = std::max(rt, std::abs(h.tau(j, c)) / 40.0);
    }
  EXPECT_NEAR(m.max_q_limit_ratio, rq, 1e-15);
  EXPECT_NEAR(m.max_qd_limit_ratio, rv, 1e-15);
  EXPECT_NEAR(m.max_tau_limit_ratio, rt, 1e-15);
  EXPECT_EQ(m.status, RunStatus::ok);  // on_violation = ignore: measured, not marked

  // an effort limit below the run's peak torque: out_of_limits, and stop ends the run where the
  // history first passes it
  const double peak = m.tau_inf.maxCoeff();
  o.on_violation = OnViolation::mark;
  o.tracking_bound = 10.0;  // m: only the limits decide here
  for (ChainJoint& j : chain.joints) j.lower = -1e3, j.upper = 1e3, j.velocity = 1e3, j.effort = 0.9 * peak;
  const TrajectoryMetrics mark = simulate(chain, ChainTask(TaskSpace::planar_position, path, o.dt), planar_start_guess(5), o);
  EXPECT_EQ(mark.status, RunStatus::out_of_limits);
  EXPECT_NEAR(mark.max_tau_limit_ratio, 1.0 / 0.9, 1e-12);
  EXPECT_EQ(mark.E, m.E);
  Eigen::Index first = -1;
  for (Eigen::Index c = 0; c < h.size && first < 0; ++c)
    if (h.tau.col(c).cwiseAbs().maxCoeff() > 0.9 * peak) first = c;
  o.on_violation = OnViolation::stop;
  const TrajectoryMetrics stop = simulate(chain, ChainTask(TaskSpace::planar_position, path, o.dt), planar_start_guess(5), o);
  EXPECT_EQ(stop.status, RunStatus::out_of_limits);
  EXPECT_EQ(stop.samples, static_cast<std::size_t>(first + 1));
  EXPECT_TRUE(std::isnan(stop.E));
  // both bounds crossed at once: the tracking bound wins
  o.tracking_bound = 1e-12;
  const TrajectoryMetrics both = simulate(chain, ChainTask(TaskSpace::planar_position, path, o.dt), planar_start_guess(5), o);
  EXPECT_EQ(both.status, RunStatus::off_path);
}

// A chain with a prismatic joint: E is the mean torque norm of the revolute joints [Nm], E_force the
// mean force norm of the prismatic one [N], each recomputed from the history.
TEST(TrajectoryBounds, PrismaticForcesAreMeasuredApartFromTorques) {
  const Chain chain = planar_rpr();
  ASSERT_TRUE(chain.planar());
  // a small square the arm reaches with the prismatic joint near its start
  const Path3 path({{1.2, 0.6, 0}, {1.4, 0.6, 0}, {1.4, 0.8, 0}, {1.2, 0.8, 0}, {1.2, 0.6, 0}}, {0.5, 0.5, 0.5, 0.5});
  TrajectoryOptions o;
  o.alpha1A = 0.3;
  ChainHistory h;
  const TrajectoryMetrics m = simulate(chain, ChainTask(TaskSpace::planar_position, path, o.dt), joint_vector({0.5, 0.2, -1.0}), o, &h);
  ASSERT_EQ(m.status, RunStatus::ok) << to_string(m.status);
  double e = 0, f = 0;
  for (Eigen::Index c = 0; c < h.size; ++c) {
    e += std::hypot(h.tau(0, c), h.tau(2, c));
    f += std::abs(h.tau(1, c));
  }
  EXPECT_NEAR(m.E, e / static_cast<double>(h.size), 1e-12 * m.E);
  EXPECT_NEAR(m.E_force, f / static_cast<double>(h.size), 1e-12 * std::max(1.0, m.E_force));
  EXPECT_TRUE(std::isnan(simulate(planar5(), ChainTask(TaskSpace::planar_position, lift_to_3d(seed_square()), o.dt),
                                  planar_start_guess(5), base_options())
                             .E_force));
}

// Lanes: runs with bounds, rules and feedback computed side by side equal the runs alone, bit for bit.
TEST(TrajectoryBounds, LanesEqualSingleRunsWithBoundsAndFeedback) {
  const int lanes = supported_lanes();
  if (lanes == 1) GTEST_SKIP() << "no SIMD lanes on this processor";
  const SampledPath sampled(seed_square(), 1e-3);
  for (OnViolation rule : {OnViolation::mark, OnViolation::stop})
    for (bool closed : {false, true})
      for (TrajectoryMethod method : {TrajectoryMethod::local_weighted, TrajectoryMethod::vertex_alpha}) {
        std::vector<TrajectoryOptions> opts(lanes);
        for (int i = 0; i < lanes; ++i) {
          TrajectoryOptions& o = opts[i];
          o.method = method;
          o.alpha1A = (-20.0 + 7.0 * i) * M_PI / 180;
          o.vertex_alpha = {0.1 * i, 0.2, -0.1, 0.05 * i};
          o.k = 0.1 * i;
          o.on_violation = rule;
          o.tracking_bound = 0.002 + 0.004 * i;
          o.orientation_bound = 0.01 + 0.01 * i;
          if (closed) o.clik_kp = 100.0 + 50 * i, o.clik_kd = 20.0 + i;
        }
        std::vector<TrajectoryMetrics> together(lanes);
        simulate_lanes(lanes, PlanarArm3::seed(), sampled, opts.data(), lanes, together.data());
        for (int i = 0; i < lanes; ++i) {
          const TrajectoryMetrics alone = simulate(PlanarArm3::seed(), sampled, opts[i]);
          SCOPED_TRACE(i);
          EXPECT_EQ(together[i].status, alone.status);
          EXPECT_EQ(together[i].samples, alone.samples);
          const double a[] = {alone.E, alone.max_tracking_error, alone.mean_tracking_error, alone.max_orientation_error};
          const double b[] = {together[i].E, together[i].max_tracking_error, together[i].mean_tracking_error,
                              together[i].max_orientation_error};
          for (int k = 0; k < 4; ++k) EXPECT_TRUE(std::memcmp(&a[k], &b[k], sizeof(double)) == 0) << k;
          // runs that stop at a crossing take the last sample's entries there
          for (int k = 0; k < kSampleMetricCount; ++k)
            EXPECT_TRUE(std::memcmp(&alone.sampled[k], &together[i].sampled[k], sizeof(double)) == 0)
                << k;
        }
      }
}
