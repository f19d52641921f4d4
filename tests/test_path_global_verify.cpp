// Verification between samples of path-global runs: the departure rule, and runs whose trajectory is
// cheap only at its samples, found by an evaluation between the samples written here without the
// evaluator (the path's exact position, the model's inverse kinematics, joint rates and accelerations by
// central differences in time, torques by inverse dynamics).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/solve_closed_form.hpp"
#include "methods/path_global/closed_form.hpp"
#include "methods/path_global/verify.hpp"
#include "methods/chain/start.hpp"
#include "methods/path_global/chain.hpp"
#include "methods/path_global/planar_chart.hpp"
#include "model/chain_dynamics.hpp"
#include "model/dynamics.hpp"

using namespace ks;

namespace {
TrajectoryMetrics metrics(double E, double tau, double manip) {
  TrajectoryMetrics m;
  m.E = E;
  m.tau_inf = VecN::Constant(3, tau);
  m.min_manipulability = manip;
  m.max_tracking_error = 1e-15;
  return m;
}
}  // namespace

TEST(DenseDeparture, ZeroForTheSameFiguresAndTheLargestRelativeChangeOtherwise) {
  const TrajectoryMetrics s = metrics(10.0, 50.0, 0.2);
  EXPECT_EQ(dense_departure(s, s, 1e-3), 0.0);
  EXPECT_NEAR(dense_departure(s, metrics(10.1, 50.0, 0.2), 1e-3), 0.01, 1e-12);   // E
  EXPECT_NEAR(dense_departure(s, metrics(10.0, 60.0, 0.2), 1e-3), 0.2, 1e-12);    // a higher peak
  EXPECT_EQ(dense_departure(s, metrics(10.0, 40.0, 0.2), 1e-3), 0.0);             // a lower peak cannot be
  EXPECT_NEAR(dense_departure(s, metrics(10.0, 50.0, 0.05), 1e-3), 0.75, 1e-12);  // nearer a singularity
  TrajectoryMetrics off = metrics(10.0, 50.0, 0.2);
  off.max_tracking_error = 5e-4;  // half the tracking bound between the samples
  EXPECT_NEAR(dense_departure(s, off, 1e-3), 0.5, 1e-5);
  TrajectoryMetrics stopped = s;
  stopped.status = RunStatus::infeasible;
  EXPECT_EQ(dense_departure(s, stopped, 1e-3), std::numeric_limits<double>::infinity());
}

TEST(DenseDeparture, VerifyEvaluatesTwoFinerGridsAndKeepsTheFinerFigures) {
  const TrajectoryMetrics s = metrics(10.0, 50.0, 0.2);
  std::vector<double> steps;
  const auto d = verify_between_samples(s, 1e-3, 4, 1e-3, [&](double h) {
    steps.push_back(h);
    return metrics(10.0, steps.size() == 1 ? 51.0 : 52.0, 0.2);
  });
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_DOUBLE_EQ(steps[0], 1e-3 / 4);
  EXPECT_DOUBLE_EQ(steps[1], 1e-3 / 16);
  EXPECT_DOUBLE_EQ(d.tau_inf, 52.0);
  EXPECT_NEAR(d.departure, 0.04, 1e-12);
  EXPECT_TRUE(std::isnan(verify_between_samples(s, 1e-3, 1, 1e-3, [](double) { return TrajectoryMetrics{}; }).departure));
}

namespace {
constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// The joint path q(t) of the self-motion chart for coefficients c, sampled at step h [s].
struct DenseJointPath {
  std::vector<VecN> q;  // one per sample of step h, angles continued across (-pi, pi]
  double h = 0;
};

DenseJointPath joint_path(const Chain& chain, const std::vector<double>& c, int knots, double h) {
  const ChainTask task(TaskSpace::planar_position, seed_square(), h);
  const PlanarChartProblem chart(chain, task, Extension::self_motion, Elbow::positive);
  const AlphaBasis basis = cubic_spline_basis(task.path.size(), h, task.path.path().duration(), knots, true);
  const int r = chart.coordinates(), K = basis.coefficients;
  DenseJointPath out;
  out.h = h;
  for (std::size_t i = 0; i < task.path.size(); ++i) {
    double z[kMaxJoints][3];
    for (int k = 0; k < r; ++k) basis.at(i, c.data() + k * K, z[k][0], z[k][1], z[k][2]);
    ChainGlobalSample s;
    chart.sample(i, z, s);
    VecN q = s.q;
    if (!out.q.empty())
      for (int j = 0; j < q.size(); ++j) q[j] = out.q.back()[j] + std::remainder(q[j] - out.q.back()[j], 2 * M_PI);
    out.q.push_back(q);
  }
  return out;
}

/// Peak |tau_j| over the interior samples of p, from central differences and the chain's RNEA.
double peak_torque(const Chain& chain, const DenseJointPath& p) {
  ChainData data;
  double peak = 0.0;
  for (std::size_t i = 1; i + 1 < p.q.size(); ++i) {
    const VecN qd = (p.q[i + 1] - p.q[i - 1]) / (2 * p.h);
    const VecN qdd = (p.q[i + 1] - 2 * p.q[i] + p.q[i - 1]) / (p.h * p.h);
    VecN tau(chain.dof());
    rnea(chain, data, p.q[i], qd, qdd, tau);
    peak = std::max(peak, tau.cwiseAbs().maxCoeff());
  }
  return peak;
}

Chain five_link_arm() {
  std::vector<PlanarLink> links = planar_bars({1.0, 0.5, 0.5, 0.5, 0.5}, {5.0, 1.0, 1.0, 0.5, 0.5}, 0.1);
  for (PlanarLink& l : links) l.lower = -170 * kDeg, l.upper = 170 * kDeg;
  return planar_chain(links);
}

TrajectoryOptions global_options(int knots, int refinements) {
  TrajectoryOptions o;
  o.method = TrajectoryMethod::global_spline;
  o.alpha1A = -1.5 * kDeg;
  o.global.knots = knots;
  o.global.extension = Extension::self_motion;
  o.global.refinements = refinements;
  return o;
}
}  // namespace

// The 5R arm of studies/path_global_5r.toml with 20 knots: SLSQP's optimum at dt = 1 ms passes the
// last three links' stretched configuration between two samples, a torque spike no sample sees. An
// evaluation between the samples written here (central differences of the joint path at 1/16 ms) finds
// the spike; the run is flagged, not ok.
TEST(VerifyBetweenSamples, AFiveLinkOptimumPassingAStretchedWristBetweenSamplesIsFlagged) {
  const Chain chain = five_link_arm();
  const ChainTask task(TaskSpace::planar_position, seed_square(), 1e-3);
  const VecN q0 = planar_start_guess(chain.dof());
  std::vector<double> c;
  const TrajectoryMetrics m = solve_global_spline_chain(chain, task, q0, global_options(20, 0), nullptr, &c);
  ASSERT_FALSE(c.empty());
  const double sampled_peak = m.tau_inf.maxCoeff();
  const double dense_peak = peak_torque(chain, joint_path(chain, c, 20, 1e-3 / 16));
  // the gap is real: between the samples the torque rises far above every sampled value
  EXPECT_GT(dense_peak, 2.0 * sampled_peak) << "sampled " << sampled_peak << " dense " << dense_peak;
  EXPECT_EQ(m.status, RunStatus::undersampled) << to_string(m.status);
  EXPECT_GT(m.dense.departure, 0.01);
  // the run's own dense peak (analytic rates at 1/16 ms) and the central differences' agree to their
  // truncation error at the spike's width
  EXPECT_NEAR(m.dense.tau_inf, dense_peak, 0.25 * dense_peak);
}

// The 10-knot run of the same study is verified: its peak torque between the samples, evaluated here,
// is within the tolerance of its sampled peak, and the run is ok.
TEST(VerifyBetweenSamples, AFiveLinkOptimumSmoothBetweenSamplesIsOk) {
  const Chain chain = five_link_arm();
  const ChainTask task(TaskSpace::planar_position, seed_square(), 1e-3);
  std::vector<double> c;
  const TrajectoryMetrics m =
      solve_global_spline_chain(chain, task, planar_start_guess(chain.dof()), global_options(10, 0), nullptr, &c);
  ASSERT_EQ(m.status, RunStatus::ok) << to_string(m.status);
  const double sampled_peak = m.tau_inf.maxCoeff();
  const double dense_peak = peak_torque(chain, joint_path(chain, c, 10, 1e-3 / 16));
  EXPECT_LE(dense_peak, (1.0 + 0.01) * sampled_peak + 1e-6) << "sampled " << sampled_peak << " dense " << dense_peak;
  EXPECT_LE(m.dense.departure, 0.01);
}
