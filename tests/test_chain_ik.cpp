// IK of a general serial chain (ik/chain_problems.hpp, ik/chain_ik.hpp): analytic derivatives
// against finite differences, convergence of every method to FK-generated targets, statuses, joint
// limits, agreement with ik::PlanarPose on the seed arm, Newton's quadratic rate, clustering.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "ik/chain_ik.hpp"
#include "ik/solve_impl.hpp"  // ChainProblem is solved directly below as well
#include "ik_chains.hpp"
#include "robot/urdf.hpp"

using namespace ks;
using namespace ks::ik;
using test::prismatic_planar_chain;
using test::prismatic_spatial_chain;
using test::srs7_chain;

namespace {
constexpr double kPi = std::numbers::pi;

Chain arm7() {
  return load_urdf(KS_SOURCE_DIR "/studies/robots/arm7.urdf", "base_link", "tool", Eigen::Vector3d(0, 0, -9.81));
}
Chain planar4r() { return planar_chain(planar_bars({0.5, 0.4, 0.3, 0.2}, {1, 1, 1, 1}, 0.05), 9.81, "planar4r"); }

std::mt19937_64& rng() {
  static std::mt19937_64 r(20240611);
  return r;
}
VecN random_q(const Chain& c, double spread = kPi) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecN q(c.dof());
  for (int i = 0; i < c.dof(); ++i) {
    const ChainJoint& j = c.joints[static_cast<std::size_t>(i)];
    const double lo = std::max(j.lower, j.type == JointType::revolute ? -spread : -0.3);
    const double hi = std::min(j.upper, j.type == JointType::revolute ? spread : 0.3);
    q[i] = 0.5 * (lo + hi) + 0.5 * (hi - lo) * u(rng()) * 0.95;
  }
  return q;
}

// The task whose target is the tip at q (reachable by construction).
ChainIkTask task_at(const Chain& c, ChainTask kind, const VecN& q) {
  ChainData d;
  forward_kinematics(c, d, q);
  ChainIkTask t;
  t.kind = kind;
  t.position = d.tip.p;
  t.rotation = d.tip.R;
  t.alpha = std::atan2(d.tip.R(1, 0), d.tip.R(0, 0));
  return t;
}

// Task error of q, from forward kinematics alone: position [m] and rotation angle [rad] as relevant.
double task_error(const Chain& c, const ChainIkTask& t, const VecN& q) {
  ChainData d;
  forward_kinematics(c, d, q);
  const Eigen::Vector3d dp = d.tip.p - t.position;
  switch (t.kind) {
    case ChainTask::planar_position: return dp.head<2>().norm();
    case ChainTask::planar_pose:
      return std::hypot(dp.head<2>().norm(), wrap_angle(std::atan2(d.tip.R(1, 0), d.tip.R(0, 0)) - t.alpha));
    case ChainTask::spatial_position: return dp.norm();
    case ChainTask::spatial_pose:
      return std::hypot(dp.norm(), Eigen::AngleAxisd(d.tip.R * t.rotation.transpose()).angle());
  }
  return NAN;
}

// --- derivatives ---------------------------------------------------------------------------------

template <int N, ChainTask T>
void check_derivatives(const Chain& c, int samples) {
  constexpr int M = chain_task_residuals(T);
  ChainData data;
  for (int s = 0; s < samples; ++s) {
    const VecN qs = random_q(c), qt = random_q(c);
    const ChainIkTask task = task_at(c, T, qt);
    ChainProblem<N, T> pb;
    pb.bind(c, data);
    pb.position = task.position, pb.alpha = task.alpha, pb.rotation = task.rotation;
    const Vec<N> q = qs;
    Vec<M> F;
    Mat<M, N> J;
    pb.evaluate(q, F, J);
    if (T == ChainTask::spatial_pose && Eigen::AngleAxisd(pb.rotation.transpose() * data.tip.R).angle() > 2.5) continue;
    // the geometric Jacobian of the chain's own kinematics, for the position rows
    Mat6N Jg;
    forward_kinematics(c, data, qs);
    tip_jacobian(c, data, Jg);
    const int P = T == ChainTask::planar_position || T == ChainTask::planar_pose ? 2 : 3;
    for (int r = 0; r < P; ++r)
      for (int k = 0; k < N; ++k) EXPECT_NEAR(J(r, k), Jg(r, k), 1e-12) << "row " << r << " col " << k;

    const SecondDerivatives<M, N> D = pb.second_derivatives(q);
    const double h = 1e-6;
    for (int k = 0; k < N; ++k) {
      Vec<N> qp = q, qm = q;
      qp[k] += h, qm[k] -= h;
      Vec<M> Fp, Fm;
      Mat<M, N> Jp, Jm;
      pb.evaluate(qp, Fp, Jp);
      pb.evaluate(qm, Fm, Jm);
      const Vec<M> dF = (Fp - Fm) / (2 * h);
      const Mat<M, N> dJ = (Jp - Jm) / (2 * h);
      for (int i = 0; i < M; ++i) {
        const double scale = 1.0 + std::abs(J(i, k));
        EXPECT_NEAR(J(i, k), dF[i], 1e-7 * scale) << c.name << " task " << int(T) << " dF" << i << "/dq" << k;
        for (int j = 0; j < N; ++j)
          EXPECT_NEAR(D[i](j, k), dJ(i, j), 1e-6 * (1.0 + std::abs(D[i](j, k))))
              << c.name << " task " << int(T) << " d2F" << i << "/dq" << j << "dq" << k;
      }
    }
    for (int i = 0; i < M; ++i) EXPECT_EQ(D[i], D[i].transpose()) << "symmetric";
  }
}

TEST(ChainIkDerivatives, Planar4R) {
  const Chain c = planar4r();
  check_derivatives<4, ChainTask::planar_position>(c, 5);
  check_derivatives<4, ChainTask::planar_pose>(c, 5);
  check_derivatives<4, ChainTask::spatial_position>(c, 5);
  check_derivatives<4, ChainTask::spatial_pose>(c, 5);
}

TEST(ChainIkDerivatives, SevenDof) {
  const Chain c = srs7_chain(false);
  check_derivatives<7, ChainTask::planar_position>(c, 5);
  check_derivatives<7, ChainTask::spatial_position>(c, 5);
  check_derivatives<7, ChainTask::spatial_pose>(c, 10);
}

TEST(ChainIkDerivatives, Arm7Urdf) {
  const Chain c = arm7();
  ASSERT_EQ(c.dof(), 7);
  check_derivatives<7, ChainTask::spatial_position>(c, 5);
  check_derivatives<7, ChainTask::spatial_pose>(c, 10);
}

TEST(ChainIkDerivatives, PrismaticJoints) {
  const Chain s = prismatic_spatial_chain();
  check_derivatives<5, ChainTask::planar_position>(s, 5);
  check_derivatives<5, ChainTask::spatial_position>(s, 5);
  check_derivatives<5, ChainTask::spatial_pose>(s, 10);
  const Chain p = prismatic_planar_chain();
  ASSERT_TRUE(p.planar());
  check_derivatives<3, ChainTask::planar_position>(p, 5);
  check_derivatives<3, ChainTask::planar_pose>(p, 5);
  check_derivatives<3, ChainTask::spatial_pose>(p, 5);
}

// The orientation residual is 2 tan(theta / 2) u: zero only at theta = 0, growing to a pole at pi.
TEST(ChainIkDerivatives, OrientationResidualHasNoHalfTurnRoot) {
  const Chain c = srs7_chain(false);
  ChainData data;
  ChainProblem<7, ChainTask::spatial_pose> pb;
  pb.bind(c, data);
  const VecN q = random_q(c);
  forward_kinematics(c, data, q);
  pb.position = data.tip.p;
  const Eigen::Vector3d u = Eigen::Vector3d(1, 2, -0.5).normalized();
  for (const double theta : {0.0, 0.5, 2.0, 3.0, kPi - 1e-3}) {
    pb.rotation = Eigen::AngleAxisd(-theta, u).toRotationMatrix() * data.tip.R;  // R R*^T = Rot(theta, u)
    Vec<6> F;
    Mat<6, 7> J;
    pb.evaluate(Vec<7>(q), F, J);
    EXPECT_LT(F.head<3>().norm(), 1e-15);
    const double g = std::tan(theta / 2);  // rounding in 1 + tr E is amplified by (1 + g^2) near the pole
    EXPECT_NEAR((F.tail<3>() - 2.0 * g * u).norm(), 0.0, 1e-11 * (1 + g * g));
  }
}

// --- convergence ---------------------------------------------------------------------------------

struct Case {
  std::string what;
  Chain chain;
  ChainTask task;
};

std::vector<Case> convergence_cases() {
  return {{"planar4r position", planar4r(), ChainTask::planar_position},
          {"planar4r pose", planar4r(), ChainTask::planar_pose},
          {"rpr planar pose", prismatic_planar_chain(), ChainTask::planar_pose},
          {"srs7 position", srs7_chain(), ChainTask::spatial_position},
          {"srs7 pose", srs7_chain(), ChainTask::spatial_pose},
          {"arm7 pose", arm7(), ChainTask::spatial_pose},
          {"rprrr position", prismatic_spatial_chain(), ChainTask::spatial_position},
          {"rprrr pose", prismatic_spatial_chain(), ChainTask::spatial_pose}};
}

TEST(ChainIk, EveryMethodConvergesFromNearStarts) {
  ChainIkWorkspace ws;
  ChainIkResult r;
  std::normal_distribution<double> perturb(0.0, 0.05);
  for (const Case& c : convergence_cases()) {
    const int n = c.chain.dof();
    for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley, Method::halley_thesis}) {
      if (m == Method::halley_thesis && residual_count(c.task) != n) continue;
      for (int trial = 0; trial < 20; ++trial) {
        const VecN qs = random_q(c.chain, 2.5);
        const ChainIkTask task = task_at(c.chain, c.task, qs);
        VecN q0 = qs;
        for (int i = 0; i < n; ++i) q0[i] += perturb(rng());
        Options o;
        o.method = m;
        o.tolerance = 1e-10;
        // lm's fixed damping must be small against sigma_min(J)^2 for a useful linear rate, also
        // near the singular configurations some random targets come close to
        o.lambda = 1e-6;
        o.max_iter = 5000;
        solve_chain(c.chain, task, q0, o, r, ws);
        ASSERT_EQ(r.status, Status::converged) << c.what << " " << to_string(m) << " trial " << trial;
        EXPECT_LT(task_error(c.chain, task, r.q), 1e-9) << c.what << " " << to_string(m);
        EXPECT_EQ(r.history.size(), static_cast<std::size_t>(r.iterations) + 1);
        for (int j = 0; j < n; ++j)  // the history keeps the iterates; the result wraps unlimited angles
          EXPECT_EQ(c.chain.joints[j].type == JointType::revolute ? wrap_angle(r.history.q.back()[j])
                                                                 : r.history.q.back()[j],
                    r.q[j]);
      }
    }
  }
}

TEST(ChainIk, NewtonConvergesQuadratically) {
  const Chain c = srs7_chain();
  ChainIkWorkspace ws;
  ChainIkResult r;
  std::normal_distribution<double> perturb(0.0, 0.1);
  int well_conditioned = 0;
  for (const ChainTask kind : {ChainTask::spatial_pose, ChainTask::spatial_position}) {
    for (int trial = 0; trial < 10; ++trial) {
      const VecN qs = random_q(c, 2.0);
      VecN q0 = qs;
      for (int i = 0; i < 7; ++i) q0[i] += perturb(rng());
      Options o;
      o.tolerance = 1e-13;
      solve_chain(c, task_at(c, kind, qs), q0, o, r, ws);
      ASSERT_EQ(r.status, Status::converged);
      if (r.min_rcond < 1e-2) continue;  // near a singularity the quadratic regime starts late
      ++well_conditioned;
      // e_{k+1} <= C e_k^2 once e_k is small (and above roundoff).
      int checked = 0;
      for (std::size_t k = 0; k + 1 < r.history.size(); ++k) {
        const double e = r.history.error[k], en = r.history.error[k + 1];
        if (e > 1e-2 || e < 1e-9) continue;
        // a linear rate r would give en / e^2 = r / e > 1e4 at e < 1e-5
        EXPECT_LT(en, 1000.0 * e * e) << "k " << k << " e " << e << " next " << en;
        ++checked;
      }
      EXPECT_GE(checked, 1);
    }
  }
  EXPECT_GE(well_conditioned, 5);
}

// The chain's planar 3R pose problem is ik::PlanarPose on the seed arm: the same iterates.
TEST(ChainIk, Planar3RPoseMatchesPlanarPose) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const Chain c = planar_chain(planar_bars({arm.l[0], arm.l[1], arm.l[2]}, {5.0, 2.0, 1.0}, 0.1), 9.81, "seed");
  ChainIkWorkspace ws;
  ChainIkResult r;
  int compared = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const VecN qs = random_q(c, 3.0);
    const ArmPose f = forward_kinematics(arm, Vec3(qs));
    PlanarPose pp;
    pp.arm = arm;
    pp.target = f.tip;
    pp.alpha = f.alpha;
    ChainIkTask t;
    t.kind = ChainTask::planar_pose;
    t.position = {f.tip.x(), f.tip.y(), 0.0};
    t.alpha = f.alpha;
    const Vec<3> q0 = Vec<3>(qs) + Vec<3>(0.3, -0.2, 0.25);
    for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley, Method::halley_thesis}) {
      Options o;
      o.method = m;
      const Summary<3, 3> s = solve(pp, q0, o);
      solve_chain(c, t, VecN(q0), o, r, ws);
      std::size_t rows = s.history.size();
      const bool ill_conditioned = s.min_rcond < 0.05;
      if (m == Method::halley_thesis || (ill_conditioned && m != Method::lm_adaptive)) {
        // halley_thesis's step (I - L/2)^-1 is often ill-conditioned and it wanders for hundreds of
        // iterations, amplifying the rounding differences of the two kinematics ~10x per step (so
        // do the other methods' near-singular steps): compare the iteration map instead, one step
        // from each of the reference's first 50 iterates (lm_adaptive's map depends on its damping
        // state, so it is compared whole, with a tolerance scaled by the conditioning).
        Options one = o;
        one.max_iter = 1;
        for (std::size_t k = 0; k + 1 < std::min<std::size_t>(rows, 51); ++k) {
          solve_chain(c, t, VecN(s.history.q[k]), one, r, ws);
          if (r.iterations == 0) continue;  // stopped before the step (converged or singular)
          const double scale = 1.0 + s.history.q[k + 1].cwiseAbs().maxCoeff();
          EXPECT_LT((r.history.q[1] - VecN(s.history.q[k + 1])).cwiseAbs().maxCoeff(), 1e-12 * scale) << "k " << k;
          ++compared;
        }
        continue;
      } else {
        ASSERT_EQ(r.status, s.status) << to_string(m);
        ASSERT_EQ(r.iterations, s.iterations) << to_string(m);
        ASSERT_EQ(r.rejected, s.rejected) << to_string(m);
      }
      const double tol = 1e-12 * std::max(1.0, 0.05 / s.min_rcond);
      for (std::size_t k = 0; k < rows; ++k) {
        EXPECT_LT((r.history.q[k] - VecN(s.history.q[k])).cwiseAbs().maxCoeff(), tol) << to_string(m) << " k " << k;
        EXPECT_LT((r.history.F[k] - VecF(s.history.F[k])).cwiseAbs().maxCoeff(), tol) << to_string(m) << " k " << k;
        EXPECT_NEAR(r.history.lambda[k], s.history.lambda[k], 1e-12 * (1 + s.history.lambda[k]));
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 100);
}

// --- statuses and limits -------------------------------------------------------------------------

TEST(ChainIk, UnreachablePlanarTargetDoesNotConverge) {
  const Chain c = planar4r();  // reach 1.4 m
  ChainIkWorkspace ws;
  ChainIkResult r;
  ChainIkTask t;
  t.kind = ChainTask::planar_position;
  t.position = {1.2, 1.0, 0.0};
  for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley}) {
    Options o;
    o.method = m;
    o.max_iter = 200;
    VecN q0(4);
    q0 << 0.3, 0.2, -0.1, 0.4;
    solve_chain(c, t, q0, o, r, ws);
    EXPECT_NE(r.status, Status::converged) << to_string(m);
    if (m == Method::lm || m == Method::lm_adaptive) {
      EXPECT_TRUE(r.status == Status::stalled || r.status == Status::max_iter) << to_string(r.status);
    }
    EXPECT_GT(r.error, 1.56 - 1.4 - 1e-6);  // |target| - reach
  }
}

TEST(ChainIk, Unsupported) {
  ChainIkWorkspace ws;
  ChainIkResult r;
  const Chain c7 = srs7_chain();
  const ChainIkTask t = task_at(c7, ChainTask::spatial_pose, VecN::Zero(7));
  Options o;
  o.method = Method::analytic;
  solve_chain(c7, t, VecN::Constant(7, 0.1), o, r, ws);
  EXPECT_EQ(r.status, Status::unsupported);
  o.method = Method::halley_thesis;  // 6 residuals, 7 unknowns
  solve_chain(c7, t, VecN::Constant(7, 0.1), o, r, ws);
  EXPECT_EQ(r.status, Status::unsupported);
  o.method = Method::newton;
  solve_chain(c7, t, VecN::Constant(6, 0.1), o, r, ws);  // wrong size
  EXPECT_EQ(r.status, Status::unsupported);
  ChainIkTask planar = t;
  planar.kind = ChainTask::planar_pose;  // the 7-DOF arm is not planar
  solve_chain(c7, planar, VecN::Constant(7, 0.1), o, r, ws);
  EXPECT_EQ(r.status, Status::unsupported);
}

TEST(ChainIk, ClampKeepsIteratesWithinLimits) {
  Chain c = srs7_chain();
  for (auto& j : c.joints) j.lower = -1.0, j.upper = 1.0;
  ChainIkWorkspace ws;
  ChainIkResult r;
  int converged = 0;
  for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley}) {
    for (int trial = 0; trial < 20; ++trial) {
      const VecN qs = random_q(c);
      const ChainIkTask t = task_at(c, ChainTask::spatial_pose, qs);
      Options o;
      o.method = m;
      o.joint_limits = JointLimits::clamp;
      solve_chain(c, t, VecN::Constant(7, 0.2), o, r, ws);
      for (const VecN& q : r.history.q) EXPECT_LE(q.cwiseAbs().maxCoeff(), 1.0) << to_string(m);
      converged += r.converged();
    }
  }
  EXPECT_GT(converged, 0);
}

TEST(ChainIk, RejectFlagsSolutionsOutsideLimits) {
  Chain c = srs7_chain();
  ChainIkWorkspace ws;
  ChainIkResult r;
  VecN qs(7);
  qs << 0.4, 0.9, -0.3, 1.2, 0.2, -0.7, 0.5;
  const ChainIkTask t = task_at(c, ChainTask::spatial_pose, qs);
  VecN q0 = qs + VecN::Constant(7, 0.02);
  Options o;
  o.joint_limits = JointLimits::reject;
  solve_chain(c, t, q0, o, r, ws);
  EXPECT_EQ(r.status, Status::converged);  // within the arm's limits
  c.joints[3].upper = 1.0;                 // now the solution's elbow is outside
  solve_chain(c, t, q0, o, r, ws);
  EXPECT_EQ(r.status, Status::out_of_limits);
  EXPECT_LT(r.error, o.tolerance);
  o.joint_limits = JointLimits::none;
  solve_chain(c, t, q0, o, r, ws);
  EXPECT_EQ(r.status, Status::converged);
  // A revolute joint 2 pi away from its limits' range is moved into them, not rejected.
  c = srs7_chain();
  q0[0] += 2 * kPi;
  o.joint_limits = JointLimits::reject;
  solve_chain(c, t, q0, o, r, ws);
  EXPECT_EQ(r.status, Status::converged);
  EXPECT_LE(std::abs(r.q[0]), c.joints[0].upper);  // moved back by 2 pi (the arm is redundant:
  EXPECT_NEAR(r.q[0], qs[0], 0.1);                  // a nearby solution, not necessarily qs)
}

TEST(ChainIk, WorkspaceReuseGivesIdenticalResults) {
  const Chain c = srs7_chain();
  ChainIkWorkspace ws, fresh;
  ChainIkResult a, b;
  const ChainIkTask t = task_at(c, ChainTask::spatial_pose, random_q(c));
  const VecN q0 = random_q(c);
  Options o;
  o.method = Method::lm_adaptive;
  solve_chain(c, task_at(c, ChainTask::spatial_position, random_q(c)), random_q(c), o, a, ws);
  solve_chain(c, t, q0, o, a, ws);
  solve_chain(c, t, q0, o, b, fresh);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.q, b.q);
}

TEST(ChainIk, Names) {
  EXPECT_EQ(to_string(Status::out_of_limits), "out_of_limits");
  Status s;
  EXPECT_TRUE(parse("out_of_limits", s));
  EXPECT_EQ(s, Status::out_of_limits);
  for (const JointLimits l : {JointLimits::none, JointLimits::clamp, JointLimits::reject}) {
    JointLimits back;
    EXPECT_TRUE(parse(to_string(l), back));
    EXPECT_EQ(back, l);
  }
  Options o;
  EXPECT_TRUE(o.IsValid());
  o.joint_limits = static_cast<JointLimits>(7);
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("joint_limits"), std::string::npos);
}

// --- clustering ----------------------------------------------------------------------------------

TEST(ClusterSolutions, GreedyInInputOrderModTwoPi) {
  auto v = [](double a, double b) {
    VecN q(2);
    q << a, b;
    return q;
  };
  const std::vector<bool> rev{true, false};
  const std::vector<VecN> q{v(0.1, 0.5),         v(0.1 + 2 * kPi, 0.5004),  // same (mod 2 pi)
                            v(0.1, 0.5 + 2 * kPi),                          // prismatic: no wrap
                            v(kPi - 1e-4, 0.0),  v(-kPi + 1e-4, 0.0),       // across the cut
                            v(NAN, 0.0),         v(0.1009, 0.5),            // within 1e-3 of the first
                            v(0.1011, 0.5)};                                // not (first member only)
  EXPECT_EQ(cluster_solutions(q, rev), (std::vector<int>{0, 0, 1, 2, 2, -1, 0, 3}));
  EXPECT_EQ(cluster_solutions(q, rev, 10.0), (std::vector<int>{0, 0, 0, 0, 0, -1, 0, 0}));
  EXPECT_TRUE(cluster_solutions({}, rev).empty());
}

}  // namespace

TEST(ChainIk, OptionsAreCheckedFirst) {
  const Chain c = planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1), 9.81);
  ChainIkTask t;
  t.kind = ChainTask::planar_position;
  t.position = {1.5, 1.0, 0.0};
  ChainIkResult r;
  ChainIkWorkspace ws;
  Options o;
  o.tolerance = -1.0;
  EXPECT_THROW(solve_chain(c, t, VecN::Constant(3, 0.3), o, r, ws), std::invalid_argument);
  o = Options{};
  solve_chain(c, t, VecN::Constant(3, 0.3), o, r, ws);
  EXPECT_EQ(r.status, Status::converged);
}
