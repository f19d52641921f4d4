// Property tests of the IK problems and solvers: derivatives against central finite
// differences, closed forms are roots, planar 3R solves checked by Orocos KDL's forward kinematics,
// minimum-norm steps, singular starts, no allocation in a solve.
#include <gtest/gtest.h>

#include <Eigen/Geometry>  // cross

#include <atomic>
#include <cstdlib>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <new>
#include <numbers>
#include <random>

#include "ik/solve.hpp"
#include "kdl_arm.hpp"

using namespace ks;
using namespace ks::ik;

// ------------------------------------------------------------ allocation counter (this binary only)
static std::atomic<long> g_allocations{0};
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {
constexpr double kPi = std::numbers::pi;

struct Rng {
  std::mt19937_64 rng{20261123};
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
  Vec<3> angles(double r = kPi) { return {uniform(-r, r), uniform(-r, r), uniform(-r, r)}; }
};

// Central differences of F (columns of J) and of J (the second-derivative tensor).
template <class P>
void expect_derivatives_match(const P& p, const Vec<P::unknowns>& q, double scale) {
  constexpr int N = P::unknowns, M = P::residuals;
  Vec<M> F, Fp, Fm;
  Mat<M, N> J, Jp, Jm;
  p.evaluate(q, F, J);
  const SecondDerivatives<M, N> D = p.second_derivatives(q);
  const double h = 1e-5;
  for (int k = 0; k < N; ++k) {
    Vec<N> dq = Vec<N>::Zero();
    dq[k] = h;
    p.evaluate(q + dq, Fp, Jp);
    p.evaluate(q - dq, Fm, Jm);
    const Vec<M> dF = (Fp - Fm) / (2 * h);
    const Mat<M, N> dJ = (Jp - Jm) / (2 * h);
    for (int i = 0; i < M; ++i) {
      EXPECT_NEAR(J(i, k), dF[i], 1e-6 * scale) << "dF" << i << "/dq" << k << " at " << q.transpose();
      for (int j = 0; j < N; ++j) {
        EXPECT_NEAR(D[i](j, k), dJ(i, j), 1e-6 * scale) << "d2F" << i << "/dq" << j << "dq" << k;
        EXPECT_EQ(D[i](j, k), D[i](k, j));
      }
    }
  }
}

// KDL forward kinematics: tip position [m] and yaw [rad].
struct KdlFk {
  KDL::Chain chain;
  KDL::ChainFkSolverPos_recursive fk;
  explicit KdlFk(const PlanarArm3& a) : chain(test::kdl_chain(a)), fk(chain) {}
  Vec<3> operator()(const Vec<3>& q) {
    KDL::JntArray kq(3);
    for (int i = 0; i < 3; ++i) kq(i) = q[i];
    KDL::Frame f;
    fk.JntToCart(kq, f);
    double r, p, y;
    f.M.GetRPY(r, p, y);
    return {f.p.x(), f.p.y(), y};
  }
};

const PlanarArm3 kArm = PlanarArm3::bars({1.0, 0.8, 0.5}, {1, 1, 1}, 0.1);  // unequal links
}  // namespace

// ------------------------------------------------------------------------------- derivatives

TEST(IkProblem, ScaraDerivativesMatchFiniteDifferences) {
  Rng r;
  for (const ScaraZ z : {ScaraZ::thesis, ScaraZ::physical}) {
    ScaraPosition p;
    p.z_mode = z;
    for (int n = 0; n < 200; ++n) expect_derivatives_match(p, Vec<3>(r.uniform(-7, 7), r.uniform(-7, 7), r.uniform(-100, 100)), 350.0);
  }
}

TEST(IkProblem, PlanarDerivativesMatchFiniteDifferences) {
  Rng r;
  for (int n = 0; n < 200; ++n) {
    const Vec<3> q = r.angles(7.0);
    PlanarPose pose;
    pose.arm = kArm;
    pose.target = Vec2(r.uniform(-2, 2), r.uniform(-2, 2));
    pose.alpha = q.sum() + r.uniform(-3.0, 3.0);  // away from the wrap at +-pi of the residual
    expect_derivatives_match(pose, q, 2.3);
    PlanarPosition pos;
    pos.arm = kArm;
    pos.target = pose.target;
    expect_derivatives_match(pos, q, 2.3);
    // The model's Jacobians are the ones used.
    Vec<3> F;
    Mat<3, 3> J;
    pose.evaluate(q, F, J);
    EXPECT_EQ(J, jacobian_with_alpha(kArm, joint_trig(q)));
  }
}

TEST(IkProblem, OrientationResidualIsWrapped) {
  PlanarPose p;
  p.arm = kArm;
  p.alpha = 0.5;
  Vec<3> F;
  Mat<3, 3> J;
  p.evaluate(Vec<3>(0.5 + 2 * kPi, 0.0, 0.0), F, J);
  EXPECT_NEAR(F[2], 0.0, 1e-12);
  p.evaluate(Vec<3>(0.5 + 3.0, 0.0, 0.0), F, J);
  EXPECT_NEAR(F[2], 3.0, 1e-12);
  p.evaluate(Vec<3>(0.5 + 3.3, 0.0, 0.0), F, J);
  EXPECT_NEAR(F[2], 3.3 - 2 * kPi, 1e-12);
}

// ----------------------------------------------------------------------------- closed forms

TEST(IkProblem, KnownSolutionsAreRootsAndComplete) {
  Rng r;
  for (int n = 0; n < 300; ++n) {
    const Vec<3> q = r.angles();
    for (const ScaraZ z : {ScaraZ::thesis, ScaraZ::physical}) {
      ScaraPosition p;
      p.z_mode = z;
      const Vec<3> qs(q[0], q[1], r.uniform(-50, 150));
      p.target = p.forward(qs);
      const SolutionSet<3> set = p.known_solutions();
      ASSERT_EQ(set.count, 2);
      for (int i = 0; i < 2; ++i) EXPECT_LT((p.forward(set.q[i]) - p.target).norm(), 1e-9);
      EXPECT_GE(match_solution<3>(set, qs, ScaraPosition::revolute, 1e-7), 0) << qs.transpose();
      EXPECT_GT(set.q[0][1], -1e-12);  // index 0: sin(theta2) >= 0
    }
    PlanarPose pose;
    pose.arm = kArm;
    const ArmPose f = forward_kinematics(kArm, q);
    pose.target = f.tip;
    pose.alpha = f.alpha;
    const SolutionSet<3> set = pose.known_solutions();
    ASSERT_EQ(set.count, 2);
    for (int i = 0; i < 2; ++i) {
      Vec<3> F;
      Mat<3, 3> J;
      pose.evaluate(set.q[i], F, J);
      EXPECT_LT(F.norm(), 1e-12);
    }
    EXPECT_GE(match_solution<3>(set, q, PlanarPose::revolute, 1e-7), 0) << q.transpose();
  }
  ScaraPosition far;
  far.target = Vec<3>(400.0, 0.0, 0.0);  // beyond a1 + a2 = 350 mm
  EXPECT_EQ(far.known_solutions().count, 0);
}

// ------------------------------------------------------------------ planar 3R solves vs KDL

TEST(IkPlanar, PoseSolvesFromNearbyStartsMatchKdl) {
  Rng r;
  KdlFk kdl(kArm);
  Options o;
  o.tolerance = 1e-9;
  for (int n = 0; n < 300; ++n) {
    const Vec<3> qs = r.angles();
    PlanarPose p;
    p.arm = kArm;
    const ArmPose f = forward_kinematics(kArm, qs);
    p.target = f.tip;
    p.alpha = f.alpha;
    const SolutionSet<3> set = p.known_solutions();
    const int expected = match_solution<3>(set, qs, PlanarPose::revolute, 1e-7);
    if (std::abs(std::sin(qs[1])) < 0.2) continue;  // nearby starts may cross the singular fold
    const Vec<3> q0 = qs + Vec<3>(r.uniform(-0.2, 0.2), r.uniform(-0.2, 0.2), r.uniform(-0.2, 0.2));
    for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley, Method::halley_thesis}) {
      o.method = m;
      o.lambda = 1e-3;
      const auto s = solve(p, q0, o);
      ASSERT_EQ(s.status, Status::converged) << s.brief();
      const Vec<3> k = kdl(s.q);
      EXPECT_LT(std::hypot(k[0] - p.target.x(), k[1] - p.target.y()), 1e-9 + 1e-12);
      EXPECT_LT(std::abs(wrap_angle(k[2] - p.alpha)), 1e-9 + 1e-12);
      if (m != Method::halley_thesis) {
        EXPECT_EQ(s.solution, expected) << s.brief();  // the branch it started on
      }
      EXPECT_GE(s.solution, 0);
    }
  }
}

TEST(IkPlanar, PositionSolvesMatchKdl) {
  Rng r;
  KdlFk kdl(kArm);
  Options o;
  o.tolerance = 1e-9;
  int converged = 0, total = 0;
  for (int n = 0; n < 300; ++n) {
    const Vec<3> qs = r.angles();
    PlanarPosition p;
    p.arm = kArm;
    p.target = forward_kinematics(kArm, qs).tip;
    ASSERT_TRUE(p.known_solutions().continuum);
    const Vec<3> q0 = qs + Vec<3>(r.uniform(-0.5, 0.5), r.uniform(-0.5, 0.5), r.uniform(-0.5, 0.5));
    for (const Method m : {Method::newton, Method::lm_adaptive, Method::halley}) {
      o.method = m;
      const auto s = solve(p, q0, o);
      ++total;
      if (s.status != Status::converged) continue;
      ++converged;
      const Vec<3> k = kdl(s.q);
      EXPECT_LT(std::hypot(k[0] - p.target.x(), k[1] - p.target.y()), 1e-9 + 1e-12);
      EXPECT_EQ(s.solution, -1);  // a continuum: no index
    }
  }
  EXPECT_GE(converged, total * 98 / 100) << converged << " / " << total;
}

TEST(IkPlanar, PositionNewtonStepIsMinimumNorm) {
  // Every minimum-norm step lies in the row space of J: orthogonal to J's null vector.
  Rng r;
  for (int n = 0; n < 100; ++n) {
    PlanarPosition p;
    p.arm = kArm;
    p.target = forward_kinematics(kArm, r.angles()).tip;
    const Vec<3> q0 = r.angles();
    Options o;
    o.method = Method::newton;
    o.max_iter = 1;
    const auto s = solve(p, q0, o);
    if (s.status == Status::singular) continue;
    Vec<2> F;
    Mat<2, 3> J;
    p.evaluate(q0, F, J);
    const Vec<3> step = s.history.q[1] - q0;
    const Vec<3> null = Vec<3>(J.row(0)).cross(Vec<3>(J.row(1))).normalized();
    EXPECT_NEAR(null.dot(step), 0.0, 1e-10 * (1.0 + step.norm()));
    EXPECT_LT((J * step + F).norm(), 1e-10 * (1.0 + F.norm()));  // and it solves the linearisation
  }
}

TEST(IkPlanar, StretchedArmIsSingularForNewtonNotForLm) {
  PlanarPosition p;
  p.arm = kArm;
  p.target = Vec2(1.0, 1.0);
  Options o;
  o.method = Method::newton;
  EXPECT_EQ(solve(p, Vec<3>::Zero(), o).status, Status::singular);  // rank 1 at q = 0
  o.method = Method::halley;
  EXPECT_EQ(solve(p, Vec<3>::Zero(), o).status, Status::singular);
  o.method = Method::lm_adaptive;
  EXPECT_EQ(solve(p, Vec<3>::Zero(), o).status, Status::converged);
  PlanarPose pose;
  pose.arm = kArm;
  pose.target = Vec2(1.0, 0.5);
  pose.alpha = 0.3;
  o.method = Method::newton;
  EXPECT_EQ(solve(pose, Vec<3>(0.2, 0.0, 0.1), o).status, Status::singular);  // det = l1 l2 sin(theta2)
  EXPECT_EQ(solve(pose, Vec<3>(0.2, -kPi, 0.1), o).status, Status::singular);
}

TEST(IkPlanar, LmAdaptiveFromRandomStarts) {
  // Fully random starts: lm_adaptive reaches a closed-form solution almost always.
  Rng r;
  Options o;
  o.method = Method::lm_adaptive;
  int ok = 0, n = 0;
  for (; n < 1000; ++n) {
    PlanarPose p;
    p.arm = kArm;
    const ArmPose f = forward_kinematics(kArm, r.angles());
    p.target = f.tip;
    p.alpha = f.alpha;
    const auto s = solve(p, r.angles(), o);
    if (s.converged()) {
      ++ok;
      EXPECT_GE(s.solution, 0) << s.brief();
    }
  }
  EXPECT_GE(ok, 950) << ok << " / " << n;
}

// ------------------------------------------------------------------------------- allocations

TEST(IkSolve, NoAllocationWithoutHistoryOrWithAReusedSummary) {
  PlanarPose p;
  p.arm = kArm;
  p.target = Vec2(1.2, 0.7);
  p.alpha = 0.4;
  Options o;
  Summary<3, 3> s;
  for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley, Method::halley_thesis}) {
    o.method = m;
    o.keep_history = false;
    long before = g_allocations.load();
    solve(p, Vec<3>(0.3, 0.9, -0.5), o, s);
    EXPECT_EQ(g_allocations.load() - before, 0) << to_string(m);
    EXPECT_EQ(s.status, Status::converged) << s.brief();
    o.keep_history = true;
    solve(p, Vec<3>(0.3, 0.9, -0.5), o, s);  // sizes the history once
    before = g_allocations.load();
    solve(p, Vec<3>(0.3, 0.9, -0.5), o, s);
    EXPECT_EQ(g_allocations.load() - before, 0) << to_string(m);
    EXPECT_GT(s.history.size(), 1u);
  }
}
