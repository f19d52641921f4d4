// Point-to-point motions (engine/motion): the clamped joint spline against a dense solve of its
// interpolation system; the criteria against closed forms and fine-grid Simpson integrals; every
// gradient against central differences of the whole evaluation (Puma 560 arm and planar 2R, with and
// without an obstacle); seed 002 §7.2's weighted torque/power motions (Puma 560, planar 2R) beside the
// seed's figures; and the least duration under effort limits against a bisection on feasibility.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "model/chain_dynamics.hpp"
#include "motion/joint_spline.hpp"
#include "motion/motion_problem.hpp"
#include "motion/solve_motion.hpp"
#include "study/study.hpp"

using namespace ks;
using namespace ks::motion;

namespace {

const std::string kRobots = KS_SOURCE_DIR "/studies/robots/";
const std::string kIk = "[[block]]\nname = \"b\"\nkind = \"ik\"\nproblem = \"position\"\n";

/// The chain the study parser builds from `[robot] dh = "<robots>/<name>.toml"`.
Chain dh_chain(const std::string& name) {
  const Study s = parse_study("[robot]\ndh = \"" + kRobots + name + ".toml\"\n" + kIk, "dh.toml");
  EXPECT_TRUE(s.base_chain);
  return *s.base_chain;
}

/// s, s', s'', s''' at u of the clamped spline through y (nodes u_j = j h), from the full
/// interpolation system (4 coefficients per segment, dense, FullPivLU): the oracle.
struct DenseSpline {
  int K;
  double h;
  Eigen::VectorXd coef;  // segment j: a + b d + c d² + e d³, d = u - u_j
  DenseSpline(const Eigen::VectorXd& y) : K(static_cast<int>(y.size()) - 2), h(1.0 / (K + 1)) {
    const int S = K + 1, n = 4 * S;
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(n);
    int row = 0;
    for (int j = 0; j < S; ++j) {
      A(row, 4 * j) = 1, r[row++] = y[j];
      for (int p = 0; p < 4; ++p) A(row, 4 * j + p) = std::pow(h, p);
      r[row++] = y[j + 1];
    }
    for (int j = 1; j < S; ++j) {
      for (int p = 1; p < 4; ++p) A(row, 4 * (j - 1) + p) = p * std::pow(h, p - 1);
      A(row++, 4 * j + 1) = -1;
      for (int p = 2; p < 4; ++p) A(row, 4 * (j - 1) + p) = p * (p - 1) * std::pow(h, p - 2);
      A(row++, 4 * j + 2) = -2;
    }
    A(row++, 1) = 1;
    for (int p = 1; p < 4; ++p) A(row, 4 * K + p) = p * std::pow(h, p - 1);
    ++row;
    coef = A.fullPivLu().solve(r);
  }
  double at(double u, int order) const {
    const int j = std::min(static_cast<int>(std::floor(u / h)), K);
    const double d = u - j * h;
    double v = 0;
    for (int p = order; p < 4; ++p) {
      double f = 1;
      for (int m = 0; m < order; ++m) f *= p - m;
      v += f * coef[4 * j + p] * std::pow(d, p - order);
    }
    return v;
  }
};

}  // namespace

TEST(MotionSpline, AgainstDenseInterpolationSystem) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-2, 2), unit(0, 1);
  double worst[4] = {0, 0, 0, 0};
  for (int K : {0, 1, 2, 3, 6, 12}) {
    SplineBasis basis(K);
    Eigen::VectorXd y(K + 2);
    for (auto& v : y) v = U(rng);
    const DenseSpline dense(y);
    NodeVec w;
    for (int t = 0; t < 200; ++t) {
      const double u = t == 0 ? 0.0 : t == 1 ? 1.0 : unit(rng);
      for (int order = 0; order < 4; ++order) {
        basis.weights(u, order, w);
        const double scale = std::pow(K + 1.0, order);  // derivatives grow as 1 / h^order
        worst[order] = std::max(worst[order], std::abs(w.dot(y) - dense.at(u, order)) / scale);
      }
    }
    for (int j = 0; j <= K + 1; ++j) {  // interpolates the nodes
      basis.weights(j * basis.spacing(), 0, w);
      EXPECT_NEAR(w.dot(y), y[j], 1e-13) << "K " << K << " node " << j;
    }
    basis.weights(0.0, 1, w);  // clamped: zero end slopes
    EXPECT_NEAR(w.dot(y), 0.0, 1e-12) << K;
    basis.weights(1.0, 1, w);
    EXPECT_NEAR(w.dot(y), 0.0, 1e-12) << K;
    for (int j = 1; j <= K; ++j)  // C²: s, s', s'' agree on both sides of each interior node
      for (int order = 0; order < 3; ++order) {
        const double u = j * basis.spacing(), e = 1e-9;
        NodeVec l, r;
        basis.weights(u - e, order, l);
        basis.weights(u + e, order, r);
        EXPECT_NEAR(l.dot(y), r.dot(y), 1e-6 * std::pow(K + 1.0, order + 1)) << K << " " << j << " " << order;
      }
  }
  std::printf("spline vs dense FullPivLU system (K = 0..12, 200 points each): worst |diff| h^order for s, s', s'', s''': "
              "%.2e %.2e %.2e %.2e\n", worst[0], worst[1], worst[2], worst[3]);
  for (double d : worst) EXPECT_LT(d, 1e-12);
}

TEST(MotionSpline, JointSplineMapsAndDuration) {
  VecN a = joint_vector({0.1, -0.4, 1.0}), b = joint_vector({1.2, 0.3, -0.5});
  JointSpline sp(a, b, 3, 2.5);
  // the cubic's controls reproduce the rest-to-rest cubic exactly
  VecN q, qd, qdd, j;
  for (double t : {0.0, 0.3, 1.1, 2.5}) {
    sp.evaluate(t, q, qd, qdd, j);
    const double u = t / 2.5;
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(q[i], a[i] + (b[i] - a[i]) * (3 * u * u - 2 * u * u * u), 1e-14);
      EXPECT_NEAR(qd[i], (b[i] - a[i]) * 6 * u * (1 - u) / 2.5, 1e-14);
    }
  }
  std::vector<double> c = {0.3, 0.5, 0.9, -0.2, 0.1, 0.2, 0.8, 0.1, -0.7};
  sp.set_controls(c);
  // linear map: q^(order)(t) = start/goal part + Σ_k w_k c_k
  VecN q2, qd2, qdd2, j2;
  for (double t : {0.2, 0.9, 1.7, 2.4}) {
    sp.evaluate(t, q, qd, qdd, j);
    for (int order = 0; order < 4; ++order) {
      NodeVec w;
      sp.control_weights(t, order, w);
      JointSpline bump = sp;
      std::vector<double> c2 = c;
      c2[4] += 1.0;  // joint 1, control 1: only joint 1 moves, by w[1]
      bump.set_controls(c2);
      bump.evaluate(t, q2, qd2, qdd2, j2);
      const VecN& x = order == 0 ? q : order == 1 ? qd : order == 2 ? qdd : j;
      const VecN& x2 = order == 0 ? q2 : order == 1 ? qd2 : order == 2 ? qdd2 : j2;
      EXPECT_NEAR(x2[1] - x[1], w[1], 1e-12) << t << " " << order;
      EXPECT_EQ(x2[0], x[0]);
      // duration derivative at fixed t against central differences
      VecN d;
      sp.duration_derivative(t, order, d);
      JointSpline up = sp, down = sp;
      const double h = 1e-5;
      up.set_duration(2.5 + h), down.set_duration(2.5 - h);
      up.evaluate(t, q2, qd2, qdd2, j2);
      const VecN xu = order == 0 ? q2 : order == 1 ? qd2 : order == 2 ? qdd2 : j2;
      down.evaluate(t, q2, qd2, qdd2, j2);
      const VecN xd = order == 0 ? q2 : order == 1 ? qd2 : order == 2 ? qdd2 : j2;
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(d[i], (xu[i] - xd[i]) / (2 * h), 1e-7 * std::max(1.0, std::abs(d[i])));
    }
  }
}

namespace {

/// Composite Simpson's rule of f on [a, b] with m (even) intervals.
template <class F>
double simpson(F f, double a, double b, int m) {
  const double h = (b - a) / m;
  double s = f(a) + f(b);
  for (int i = 1; i < m; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
  return s * h / 3.0;
}

/// A single revolute joint about z with a point mass m at lc on its link, gravity g along -y:
/// τ = m lc² q̈ + m g lc cos q.
struct Pendulum {
  double m = 2.0, lc = 0.8, g = 9.81;
  Chain chain() const {
    PlanarLink l;
    l.l = lc, l.m = m, l.lc = lc, l.I = 0.0;
    return planar_chain({l}, g, "pendulum");
  }
  double tau(double q, double qdd) const { return m * lc * lc * qdd + m * g * lc * std::cos(q); }
};

}  // namespace

TEST(MotionCriteria, PendulumAgainstClosedFormSimpson) {
  const Pendulum p;
  MotionSpec spec;
  spec.chain = p.chain();
  spec.q_start = joint_vector({-0.4});
  spec.q_goal = joint_vector({1.3});
  spec.controls = 2;
  spec.duration = 1.7;
  spec.vary_duration = true;
  spec.weights.fill(1.0);
  at(spec.weights, Criterion::min_clearance) = 0.0;
  const std::vector<double> x = {0.2, 1.6, 1.7};  // controls, T
  double err201[2] = {0, 0};
  for (int samples : {201, 801}) {
    spec.samples = samples;
    const MotionProblem P(spec);
    MotionEvaluation e;
    P.evaluate(x, false, e);
    const JointSpline sp = P.spline_at(x);
    VecN q, qd, qdd, j;
    const auto at_t = [&](double t, int what) {
      sp.evaluate(t, q, qd, qdd, j);
      const double tau = p.tau(q[0], qdd[0]);
      return what == 0 ? tau * tau : what == 1 ? tau * tau * qd[0] * qd[0] : j[0] * j[0];
    };
    // Simpson per spline segment (q̈ has kinks at the nodes), 2000 intervals each
    double f5 = 0, f6 = 0, jerk = 0, peak = 0;
    const double T = 1.7, h = T / 3;
    for (int s = 0; s < 3; ++s) {
      const double a = s * h, b = (s + 1) * h;
      f5 += simpson([&](double t) { return at_t(t, 0); }, a, b, 2000);
      f6 += simpson([&](double t) { return at_t(t, 1); }, a, b, 2000);
      jerk += at_t(0.5 * (a + b), 2) * h;  // constant on the segment
    }
    for (int i = 0; i < P.samples(); ++i) peak = std::max(peak, std::sqrt(at_t(P.sample_time(i, T), 0)));
    const double r5 = std::abs(at(e.criteria, Criterion::torque_sq) / f5 - 1);
    const double r6 = std::abs(at(e.criteria, Criterion::power_sq) / f6 - 1);
    std::printf("pendulum, %d samples: f5 %.10g (Simpson %.10g, rel %.2e)  f6 %.10g (Simpson %.10g, rel %.2e)  "
                "jerk %.10g (%.10g)  peak %.6f (%.6f)\n",
                P.samples(), at(e.criteria, Criterion::torque_sq), f5, r5, at(e.criteria, Criterion::power_sq), f6, r6,
                at(e.criteria, Criterion::jerk_sq), jerk, at(e.criteria, Criterion::peak_torque), peak);
    EXPECT_LT(r5, 1e-4);
    EXPECT_LT(r6, 1e-4);
    EXPECT_NEAR(at(e.criteria, Criterion::jerk_sq), jerk, 1e-12 * jerk);
    EXPECT_NEAR(at(e.criteria, Criterion::peak_torque), peak, 1e-12 * peak);
    EXPECT_EQ(at(e.criteria, Criterion::duration), 1.7);
    if (samples == 201) err201[0] = r5, err201[1] = r6;
    else {  // the trapezoidal rule's second order: 4x the samples, about 16x less error
      EXPECT_LT(r5, err201[0] / 10);
      EXPECT_LT(r6, err201[1] / 10);
    }
  }
}

TEST(MotionCriteria, Planar2rManipulabilityAndSampleRule) {
  MotionSpec spec;
  spec.chain = dh_chain("planar2r");
  spec.q_start = joint_vector({0.0, 0.4});
  spec.q_goal = joint_vector({1.0, 2.0});
  spec.controls = 3;
  spec.duration = 2.0;
  spec.samples = 200;
  const MotionProblem P(spec);
  EXPECT_EQ(P.samples(), 201);  // the least N >= 200 with N - 1 a multiple of K + 1 = 4
  MotionEvaluation e;
  const std::vector<double> x = {0.2, 0.5, 0.8, 0.3, 0.1, 1.2};
  P.evaluate(x, false, e);
  const JointSpline sp = P.spline_at(x);
  double w = 1e300;
  VecN q, qd, qdd, j;
  for (int s = 0; s < P.samples(); ++s) {
    sp.evaluate(P.sample_time(s, 2.0), q, qd, qdd, j);
    w = std::min(w, 1.2 * 1.2 * std::abs(std::sin(q[1])));  // a1 a2 |sin q2|
  }
  EXPECT_NEAR(at(e.criteria, Criterion::min_manipulability), w, 1e-12);
  EXPECT_EQ(at(e.criteria, Criterion::min_clearance), std::numeric_limits<double>::infinity());
  spec.controls = 6;
  EXPECT_EQ(MotionProblem(spec).samples(), 204);  // 7 x 29 + 1
}

namespace {

/// Every gradient of the evaluation (each criterion's, the objective's, each constraint's row)
/// against central differences of the whole evaluation. Returns the worst relative difference.
double check_gradients(const MotionProblem& P, const std::vector<double>& x, const char* label) {
  MotionEvaluation e, up, down;
  P.evaluate(x, true, e);
  const int nv = P.variables(), nc = P.constraints();
  double worst = 0;
  for (int v = 0; v < nv; ++v) {
    const double h = 1e-6 * std::max(1.0, std::abs(x[v]));
    std::vector<double> xu = x, xd = x;
    xu[v] += h, xd[v] -= h;
    P.evaluate(xu, false, up);
    P.evaluate(xd, false, down);
    const auto cmp = [&](double g, double fu, double fd, double f, const std::string& what) {
      if (!std::isfinite(f)) return;
      const double num = (fu - fd) / (2 * h);
      const double tol = 1e-6 * std::max(1.0, std::abs(f)) + 1e-5 * std::abs(num);
      worst = std::max(worst, std::abs(g - num) / (std::max(1.0, std::abs(f)) + std::abs(num)));
      EXPECT_NEAR(g, num, tol) << label << ": " << what << " / x" << v;
    };
    for (int c = 0; c < kCriteria; ++c)
      cmp(e.criterion_gradients[c][v], up.criteria[c], down.criteria[c], e.criteria[c],
          std::string(to_string(static_cast<Criterion>(c))));
    cmp(e.objective_gradient[v], up.objective, down.objective, e.objective, "objective");
    for (int r = 0; r < nc; ++r)
      cmp(e.constraint_jacobian[static_cast<std::size_t>(r) * nv + v], up.constraints[r], down.constraints[r],
          e.constraints[r], "constraint " + std::to_string(r));
  }
  double clear_grad = 0;
  for (double g : e.criterion_gradients[static_cast<int>(Criterion::min_clearance)]) clear_grad = std::max(clear_grad, std::abs(g));
  std::printf("%s: %d variables, %d constraints, %d samples, min clearance %.4f m (|gradient| %.3f): worst |exact - "
              "central| / (max(1,|f|) + |fd|) = %.2e\n",
              label, nv, nc, P.samples(), at(e.criteria, Criterion::min_clearance), clear_grad, worst);
  return worst;
}

MotionSpec puma_spec() {
  MotionSpec spec;
  spec.chain = dh_chain("puma560_arm");
  spec.q_start = joint_vector({0.0, 0.0, 0.0});
  spec.q_goal = joint_vector({1.5708, 0.7854, -0.5236});
  spec.duration = 9.0;
  return spec;
}

MotionSpec planar2r_spec() {
  MotionSpec spec;
  spec.chain = dh_chain("planar2r");
  spec.q_start = joint_vector({-std::numbers::pi / 2, 0.0});  // hanging straight down
  spec.q_goal = joint_vector({0.0, 0.0});                      // stretched out horizontally
  spec.duration = 9.0;
  return spec;
}

/// Perturbed controls of the cubic and a duration: a generic point.
std::vector<double> generic_point(const MotionProblem& P, double T, unsigned seed) {
  std::vector<double> x = P.initial_point();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-0.15, 0.15);
  for (int v = 0; v + (P.spec().vary_duration ? 1 : 0) < P.variables(); ++v) x[v] += U(rng);
  if (P.spec().vary_duration) x.back() = T;
  return x;
}

}  // namespace

TEST(MotionGradients, PumaAndPlanar2rAgainstCentralDifferences) {
  for (int robot = 0; robot < 2; ++robot)
    for (int obstacle : {0, 1, 2}) {  // none, a fixed sphere, a moving one (its share in T)
      MotionSpec spec = robot == 0 ? puma_spec() : planar2r_spec();
      if (robot == 1) spec.q_start[1] = 0.4, spec.q_goal[1] = 0.9;  // off the stretched (singular) arm: manipulability > 0
      spec.controls = 2;
      spec.vary_duration = true;
      spec.weights.fill(1.0);
      spec.normalise = true;
      // limits so that every kind of constraint exists: velocity and effort limits by hand
      for (ChainJoint& j : spec.chain.joints) {
        j.velocity = 0.5;
        j.effort = robot == 0 ? 80.0 : 300.0;
        if (!std::isfinite(j.lower)) j.lower = -3.0, j.upper = 3.0;
      }
      if (obstacle) {
        // a sphere beside the middle configuration's elbow
        const VecN mid = 0.5 * (spec.q_start + spec.q_goal);
        ChainData d;
        forward_kinematics(spec.chain, d, mid);
        const Eigen::Vector3d elbow = d.joint[std::min(2, spec.chain.dof() - 1)].p;
        spec.obstacles.emplace_back(geometry::Sphere{elbow + Eigen::Vector3d(0.25, 0.2, robot == 0 ? 0.1 : 0.0), 0.1});
        spec.radii.assign(spec.chain.dof(), 0.05);
        if (obstacle == 2) spec.obstacle_velocities = {Eigen::Vector3d(0.04, -0.06, robot == 0 ? 0.02 : 0.0)};
      } else {
        at(spec.weights, Criterion::min_clearance) = 0.0;
      }
      spec.windows = 4;
      const MotionProblem P(spec);
      const std::string label = std::string(robot == 0 ? "puma560_arm" : "planar2r") +
                                (obstacle == 2 ? " + moving sphere" : obstacle ? " + sphere" : "");
      EXPECT_EQ(P.constraints(), 4 * (3 * spec.chain.dof() + (obstacle ? 1 : 0))) << label;
      EXPECT_LT(check_gradients(P, generic_point(P, 3.0, 11 + robot), label.c_str()), 1e-6);
    }
}

namespace {

/// Seed 002's weighted objective p = k f5/f5⁰ + (1 - k) f6/f6⁰ (Eq. 7.1) over K controls per joint.
MotionSummary weighted_torque_power(MotionSpec spec, int K, double k, Criteria* reference) {
  spec.controls = K;
  at(spec.weights, Criterion::torque_sq) = k;
  at(spec.weights, Criterion::power_sq) = 1 - k;
  spec.normalise = true;
  const MotionProblem P(spec);
  *reference = P.reference();
  return solve_motion(P);
}

}  // namespace

// Seed 002 §7.2, Puma 560 (wrist locked at 0): θ from 0 to (1.5708, 0.7854, -0.5236) rad in 9 s,
// k = 0.4. The seed's reference and optimum: f5 23.03 -> 22.66 "kNm" (-1.6 %), f6 206.66 -> 137.97 "W"
// (-33.2 %), p = 0.4 (22.66 / 23.03) + 0.6 (137.97 / 206.66) = 0.7941. Our model (Armstrong et al.'s
// parameters through Corke's toolbox, studies/robots/puma560_arm.toml) gives other reference values;
// what is ours to assert: both criteria fall, f5 by at least the seed's 1.6 %, and with K = 3 the
// weighted objective p ends at or below the seed's.
TEST(MotionSeed002, PumaTorquePowerK04) {
  const double seed_p = 0.4 * 22.66 / 23.03 + 0.6 * 137.97 / 206.66;
  for (int K = 1; K <= 3; ++K) {
    Criteria ref;
    const MotionSummary S = weighted_torque_power(puma_spec(), K, 0.4, &ref);
    const double f50 = at(ref, Criterion::torque_sq), f60 = at(ref, Criterion::power_sq);
    const double f5 = at(S.final, Criterion::torque_sq), f6 = at(S.final, Criterion::power_sq);
    if (K == 1)
      std::printf("seed 002 7.2 Puma reference (rest-to-rest cubic, T = 9 s): f5 %.3f kN^2m^2s (seed 23.03 \"kNm\")  "
                  "f6 %.2f W^2s (seed 206.66 \"W\")\n", f50 / 1e3, f60);
    std::printf("seed 002 7.2 Puma k = 0.4, K = %d: f5 %.3f -> %.3f k (%+.1f %%; seed -1.6 %%)  f6 %.2f -> %.2f (%+.1f %%; "
                "seed -33.2 %%)  p %.4f (seed %.4f)  %s, %d evaluations\n",
                K, f50 / 1e3, f5 / 1e3, 100 * (f5 / f50 - 1), f60, f6, 100 * (f6 / f60 - 1), S.final_objective, seed_p,
                std::string(to_string(S.termination)).c_str(), S.evaluations);
    EXPECT_TRUE(S.feasible);  // the Puma's position limits hold at every sample
    EXPECT_NE(S.termination, MotionTermination::failure);
    EXPECT_LT(f5 / f50 - 1, -0.016);
    EXPECT_LT(f6 / f60 - 1, 0.0);
    if (K == 3) {
      EXPECT_LE(S.final_objective, seed_p);
    }
  }
  // how far f6 alone can fall on our model (k = 0): the seed's -33 % is compared with this
  for (int K : {3, 8}) {
    Criteria ref;
    const MotionSummary S = weighted_torque_power(puma_spec(), K, 0.0, &ref);
    std::printf("seed 002 7.2 Puma k = 0 (f6 alone), K = %d: f6 %.2f -> %.2f (%+.1f %%), f5 %+.1f %%\n", K,
                at(ref, Criterion::power_sq), at(S.final, Criterion::power_sq),
                100 * (at(S.final, Criterion::power_sq) / at(ref, Criterion::power_sq) - 1),
                100 * (at(S.final, Criterion::torque_sq) / at(ref, Criterion::torque_sq) - 1));
  }
}

// Seed 002 §7.2, planar 2R (a = 1.2 m, m = 10 kg per link, uniform rods), k = 0.2, 9 s. The seed gives
// no start or goal: ours are the Puma's first two joints' motion, θ from (0, 0) (stretched along +x)
// to (1.5708, 0.7854) rad. The seed's figures: f6 8.83 -> 7.39 "kW" (-16.3 %), f5 446.85 -> 370.51
// "kNm" (-17.1 %), p = 0.2 (370.51 / 446.85) + 0.8 (7.39 / 8.83) = 0.8354.
TEST(MotionSeed002, Planar2rTorquePowerK02) {
  const double seed_p = 0.2 * 370.51 / 446.85 + 0.8 * 7.39 / 8.83;
  MotionSpec spec = planar2r_spec();
  spec.q_start = joint_vector({0.0, 0.0});
  spec.q_goal = joint_vector({1.5708, 0.7854});
  for (int K = 1; K <= 3; ++K) {
    Criteria ref;
    const MotionSummary S = weighted_torque_power(spec, K, 0.2, &ref);
    const double f50 = at(ref, Criterion::torque_sq), f60 = at(ref, Criterion::power_sq);
    const double f5 = at(S.final, Criterion::torque_sq), f6 = at(S.final, Criterion::power_sq);
    std::printf("seed 002 7.2 planar 2R k = 0.2, K = %d: f6 %.2f -> %.2f k (%+.1f %%; seed 8.83 -> 7.39, -16.3 %%)  "
                "f5 %.2f -> %.2f k (%+.1f %%; seed 446.85 -> 370.51, -17.1 %%)  p %.4f (seed %.4f)  %s, %d evaluations\n",
                K, f60 / 1e3, f6 / 1e3, 100 * (f6 / f60 - 1), f50 / 1e3, f5 / 1e3, 100 * (f5 / f50 - 1), S.final_objective,
                seed_p, std::string(to_string(S.termination)).c_str(), S.evaluations);
    EXPECT_TRUE(S.feasible);
    EXPECT_LT(f5, f50);
    EXPECT_LT(f6, f60);
    EXPECT_LE(S.final_objective, seed_p);
  }
  // the multistart keeps the best of its starts; the first is the single start's run
  MotionSpec two = spec;
  two.controls = 2;
  at(two.weights, Criterion::torque_sq) = 0.2, at(two.weights, Criterion::power_sq) = 0.8, two.normalise = true;
  const MotionProblem P(two);
  MotionSolveOptions o;
  const double single = solve_motion(P, o).final_objective;
  o.starts = 4;
  const MotionSummary multi = solve_motion(P, o);
  std::printf("planar 2R k = 0.2, K = 2, 4 starts: p %.6f (one start %.6f), best start %d\n", multi.final_objective,
              single, multi.best_start);
  EXPECT_LE(multi.final_objective, single);
}

// Time optimality on a fixed path: the 2R's path shape fixed (K = 2 controls off the cubic), only T
// free, |τ_i| within effort limits at every sample; minimising T must end at the least feasible T,
// found here by a scan down from a feasible T and a bisection on feasibility.
TEST(MotionTime, LeastDurationUnderEffortLimits) {
  MotionSpec spec = planar2r_spec();
  spec.q_start = joint_vector({-1.2, 0.3});
  spec.q_goal = joint_vector({0.8, -0.4});
  spec.chain.joints[0].effort = 400.0;  // Nm; the static torques along the path stay below both
  spec.chain.joints[1].effort = 150.0;
  spec.controls = 2;
  spec.vary_controls = false;
  spec.fixed_controls = {-0.7, 0.3, 0.5, -0.2};
  spec.vary_duration = true;
  spec.duration = 5.0;
  spec.min_duration = 0.05;
  spec.max_duration = 20.0;
  at(spec.weights, Criterion::duration) = 1.0;
  const MotionProblem P(spec);
  ASSERT_EQ(P.variables(), 1);
  MotionEvaluation e;
  const auto feasible = [&](double T) {
    const std::vector<double> x = {T};
    P.evaluate(x, false, e);
    for (double c : e.constraints)
      if (c > 0) return false;
    return true;
  };
  ASSERT_TRUE(feasible(5.0));
  double hi = 5.0, lo = hi;
  while (feasible(lo)) hi = lo, lo *= 0.98;  // the first infeasible T going down
  for (int it = 0; it < 100 && hi - lo > 1e-12 * hi; ++it) (feasible(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
  MotionSolveOptions o;
  o.constraint_tolerance = 1e-10;
  const MotionSummary S = solve_motion(P, o);
  const double T = at(S.final, Criterion::duration);
  std::printf("least duration under effort limits (400, 150) Nm: SLSQP T = %.9f s (%s, %d evaluations), bisection "
              "T = %.9f s, relative difference %.2e; peak |tau| %.3f Nm\n",
              T, std::string(to_string(S.termination)).c_str(), S.evaluations, hi, T / hi - 1,
              at(S.final, Criterion::peak_torque));
  EXPECT_TRUE(S.feasible);
  EXPECT_NEAR(T, hi, 0.01 * hi);
}

TEST(MotionOptions, IsValidNamesTheRule) {
  std::string why;
  MotionSolveOptions o;
  EXPECT_TRUE(o.IsValid(&why));
  o.starts = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("starts"), std::string::npos);
  MotionSpec spec = planar2r_spec();
  spec.controls = 0;
  EXPECT_FALSE(spec.IsValid(&why));  // no variable
  spec.vary_duration = true;
  EXPECT_TRUE(spec.IsValid(&why)) << why;
  at(spec.weights, Criterion::min_clearance) = 1.0;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("obstacles"), std::string::npos);
  EXPECT_THROW(MotionProblem{spec}, std::invalid_argument);
}
