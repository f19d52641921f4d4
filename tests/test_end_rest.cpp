// end = rest for the local methods on the seed arm (TrajectoryOptions::end): the terminal feedback
// over the last end_window brings the self-motion rate to zero while the tip keeps following the path,
// so the run ends at rest at the path's last vertex; before the window the run is bit for bit the free
// run; runs in SIMD lanes equal their single runs bit for bit; chains refuse the option.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

#include "methods/chain/trajectory.hpp"
#include "methods/metrics/sample_metrics.hpp"
#include "methods/base/trajectory.hpp"
#include "methods/closed_form/lanes.hpp"
#include "model/kinematics.hpp"

using namespace ks;

namespace {

constexpr int kQdMax = sample_metric_index("end_qd_max");
constexpr int kKinetic = sample_metric_index("end_kinetic_energy");
constexpr double kDeg = std::numbers::pi / 180.0;

bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TrajectoryOptions local_run(TrajectoryMethod method, double alpha1A_deg, double k, Elbow elbow) {
  TrajectoryOptions o;
  o.method = method;
  o.alpha1A = alpha1A_deg * kDeg;
  o.k = k;
  o.elbow = elbow;
  return o;
}

/// Local runs of both methods over both elbows, starts across the reachable range and k in [0, 0.5].
std::vector<TrajectoryOptions> sample_runs() {
  std::vector<TrajectoryOptions> runs;
  for (TrajectoryMethod m : {TrajectoryMethod::local_weighted, TrajectoryMethod::local_unweighted})
    for (Elbow e : {Elbow::positive, Elbow::negative})
      for (double a : {-22.0, 0.0, 30.0})
        for (double k : {0.0, 0.2}) runs.push_back(local_run(m, a, k, e));
  return runs;
}

}  // namespace

// At rest at the end: the free runs end moving (their self-motion, 0.07 to 4 rad/s here); the rest
// runs end with joint rates below 0.01 rad/s, a fifth of their free run's at most, and a kinetic
// energy below 1e-4 J, with the tip on the path's last vertex (within 1 mm) and within the tracking
// bound all along. What remains is the open loop's integration residual: semi-implicit Euler's
// tip drift per step, O(dt^2 |qd|^2) through the arm's curvature, which the tip feedback holds to
// about drift / (K_S dt) while the path still moves; it halves with dt (first order), which the next
// test checks.
TEST(EndRest, RestRunsEndAtRestOnTheLastVertex) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const Path2 square = seed_square();
  const Vec2 last_vertex = square.vertices().back();
  int ok = 0;
  for (TrajectoryOptions o : sample_runs()) {
    SCOPED_TRACE(std::string(to_string(o.method)) + " alpha1A " + std::to_string(o.alpha1A / kDeg) + " k " +
                 std::to_string(o.k) + " " + std::string(to_string(o.elbow)));
    const TrajectoryMetrics free_run = simulate(arm, square, o);
    o.end = EndState::rest;
    TrajectoryHistory h;
    h.stride = 2000;
    const TrajectoryMetrics rest = simulate(arm, square, o, &h);
    if (free_run.status != RunStatus::ok) continue;  // (a free run that leaves the path: not a reference)
    ASSERT_EQ(rest.status, RunStatus::ok);
    ++ok;
    EXPECT_EQ(rest.samples, free_run.samples);
    EXPECT_GT(free_run.sampled[kQdMax], 0.05);  // the free run ends moving
    EXPECT_LT(rest.sampled[kQdMax], 0.01);
    EXPECT_LT(rest.sampled[kQdMax], 0.2 * free_run.sampled[kQdMax]);
    EXPECT_LT(rest.sampled[kKinetic], 1e-4);
    EXPECT_LT(rest.max_tracking_error, o.tracking_bound);
    const Vec2 tip = h.x.col(h.size - 1);
    EXPECT_LT((tip - last_vertex).norm(), 1e-3);
    std::printf("%-16s %-10s alpha1A %6.1f k %.1f: E free %.4f rest %.4f Nm, end_qd_max free %.3g rest %.3g rad/s, "
                "tracking free %.2g rest %.2g m\n",
                std::string(to_string(o.method)).c_str(), std::string(to_string(o.elbow)).c_str(), o.alpha1A / kDeg,
                o.k, free_run.E, rest.E, free_run.sampled[kQdMax], rest.sampled[kQdMax], free_run.max_tracking_error,
                rest.max_tracking_error);
  }
  EXPECT_GE(ok, 12);
}

// The residual is the integration's: halving dt about halves the end rates of a rest run (between
// 0.3 and 0.7 of them), and RK4 leaves less than semi-implicit Euler at the same dt.
TEST(EndRest, TheResidualShrinksWithTheStep) {
  const PlanarArm3 arm = PlanarArm3::seed();
  TrajectoryOptions o = local_run(TrajectoryMethod::local_weighted, 0.0, 0.0, Elbow::positive);
  o.end = EndState::rest;
  const double coarse = simulate(arm, seed_square(), o).sampled[kQdMax];
  o.dt = 0.5e-3;
  const double fine = simulate(arm, seed_square(), o).sampled[kQdMax];
  o.dt = 1e-3;
  o.integrator = Integrator::rk4;
  const double rk4 = simulate(arm, seed_square(), o).sampled[kQdMax];
  std::printf("end_qd_max: dt 1 ms %.3g, 0.5 ms %.3g rad/s; RK4 at 1 ms %.3g rad/s\n", coarse, fine, rk4);
  EXPECT_GT(fine, 0.3 * coarse);
  EXPECT_LT(fine, 0.7 * coarse);
  EXPECT_LT(rk4, coarse);
}

// Before the window the terminal feedback does not act: the history of a rest run equals the free run's
// bit for bit up to the window's first sample; RK4 too.
TEST(EndRest, BeforeTheWindowTheRunIsTheFreeRun) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  for (Integrator integrator : {Integrator::semi_implicit_euler, Integrator::rk4}) {
    TrajectoryOptions o = local_run(TrajectoryMethod::local_weighted, -20.0, 0.1, Elbow::positive);
    o.integrator = integrator;
    TrajectoryHistory hf, hr;
    const TrajectoryMetrics f = simulate(arm, path, o, &hf);
    o.end = EndState::rest;
    o.end_window = 0.3;
    const TrajectoryMetrics r = simulate(arm, path, o, &hr);
    ASSERT_EQ(f.status, RunStatus::ok);
    ASSERT_EQ(r.status, RunStatus::ok);
    // the first sample whose step uses the feedback: t >= 2 - 0.3 (RK4: its last stage, t + dt)
    Eigen::Index first = 0;
    while (hf.t[first] + (integrator == Integrator::rk4 ? 1e-3 : 0.0) < 2.0 - 0.3) ++first;
    ASSERT_GT(first, 1000);
    EXPECT_EQ(std::memcmp(hf.q.data(), hr.q.data(), sizeof(double) * 3 * (first + 1)), 0);
    EXPECT_EQ(std::memcmp(hf.qd.data(), hr.qd.data(), sizeof(double) * 3 * (first + 1)), 0);
    EXPECT_EQ(std::memcmp(hf.tau.data(), hr.tau.data(), sizeof(double) * 3 * first), 0);
    EXPECT_NE(std::memcmp(hf.qd.data(), hr.qd.data(), sizeof(double) * 3 * hf.size), 0);
    EXPECT_LT(r.sampled[kQdMax], 0.01);
  }
}

// The default is free, and free runs do not read the window or the gain: bit for bit the same.
TEST(EndRest, FreeRunsIgnoreTheWindowAndTheGain) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  TrajectoryOptions o = local_run(TrajectoryMethod::local_unweighted, 5.0, 0.0, Elbow::negative);
  EXPECT_EQ(o.end, EndState::free);
  const TrajectoryMetrics a = simulate(arm, path, o);
  o.end_window = 1.2;
  o.end_gain = 3.0;
  const TrajectoryMetrics b = simulate(arm, path, o);
  EXPECT_TRUE(same(a.E, b.E) && same(a.tau_inf[0], b.tau_inf[0]) && same(a.sampled[kQdMax], b.sampled[kQdMax]));
}

// Rest runs in SIMD lanes equal their single runs, every metric bit for bit (random starts, elbows,
// gains, windows shared by the batch).
TEST(EndRest, LanesEqualSingleRuns) {
  const int lanes = supported_lanes();
  if (lanes == 1) GTEST_SKIP() << "no SIMD lanes on this processor";
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (TrajectoryMethod m : {TrajectoryMethod::local_weighted, TrajectoryMethod::local_unweighted})
    for (Integrator integ : {Integrator::semi_implicit_euler, Integrator::rk4}) {
      std::vector<TrajectoryOptions> runs(lanes);
      for (TrajectoryOptions& o : runs) {
        o = local_run(m, -24.0 + 60.0 * u(rng), u(rng) < 0.5 ? 0.0 : u(rng), u(rng) < 0.5 ? Elbow::positive : Elbow::negative);
        o.integrator = integ;
        o.null_damping = u(rng) < 0.5 ? 0.0 : 3.0 * u(rng);
        o.end = EndState::rest;
        o.end_window = 0.4;
        o.end_gain = 30.0;
      }
      std::vector<TrajectoryMetrics> together(lanes);
      simulate_lanes(lanes, arm, path, runs.data(), lanes, together.data());
      for (int i = 0; i < lanes; ++i) {
        const TrajectoryMetrics alone = simulate(arm, path, runs[i]);
        EXPECT_EQ(alone.status, together[i].status);
        EXPECT_TRUE(same(alone.E, together[i].E) && same(alone.E_M, together[i].E_M) &&
                    same(alone.max_tracking_error, together[i].max_tracking_error) &&
                    same(alone.final_alpha, together[i].final_alpha))
            << i;
        for (int j = 0; j < 3; ++j) EXPECT_TRUE(same(alone.tau_inf[j], together[i].tau_inf[j])) << i;
        for (int k = 0; k < kSampleMetricCount; ++k) EXPECT_TRUE(same(alone.sampled[k], together[i].sampled[k])) << i;
      }
      // runs with another end condition cannot share the batch
      runs[1].end = EndState::free;
      EXPECT_FALSE(lane_compatible(runs[0], runs[1]));
    }
}

// The option's rules: window and gain positive; chains refuse end = rest.
TEST(EndRest, BadWindowOrGainAndChainsAreRefused) {
  TrajectoryOptions o;
  o.end = EndState::rest;
  std::string why;
  o.end_window = 0.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("end_window"), std::string::npos) << why;
  o.end_window = 0.5;
  o.end_gain = -1.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("end_gain"), std::string::npos) << why;
  o.end_gain = 40.0;
  const Chain r4 = planar_chain(planar_bars({1, 1, 0.5, 0.5}, {5, 2, 0.5, 0.5}, 0.1));
  EXPECT_THROW(simulate(r4, ChainTask(TaskSpace::planar_position, seed_square(), o.dt), planar_start_guess(4), o),
               std::invalid_argument);
}

