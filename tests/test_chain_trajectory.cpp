// Redundancy resolution along a path for any serial chain: the seed arm as a generic chain against the
// closed form (every seed case, both integrators, with and without null-space damping), the
// resolution against a brute-force KKT solve and finite differences, tracking and convergence for
// planar 4R/5R and spatial chains, statuses.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <random>

#include "methods/chain/trajectory.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "model/chain_dynamics.hpp"

using namespace ks;

namespace {

Chain seed_chain() { return planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1), 9.81); }

/// |a - b| <= tol max(|a|, |b|), NaN equal to NaN.
::testing::AssertionResult close(double a, double b, double tol = 1e-9) {
  if (std::isnan(a) && std::isnan(b)) return ::testing::AssertionSuccess();
  if (std::abs(a - b) <= tol * std::max(std::abs(a), std::abs(b))) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " vs " << b << " (rel " << std::abs(a - b) / std::max(std::abs(a), std::abs(b)) << ")";
}

/// A 7-joint spatial arm (axes z y z y z y z, links along z), gravity along -z.
Chain spatial_arm7() {
  Chain c;
  c.name = "arm7";
  c.source = "test";
  c.gravity = {0, 0, -9.81};
  const double z[7] = {0.3, 0.0, 0.0, 0.4, 0.0, 0.35, 0.0};
  const double mass[7] = {4.0, 3.5, 3.0, 2.5, 2.0, 1.5, 0.8};
  for (int i = 0; i < 7; ++i) {
    ChainJoint j;
    j.name = "j" + std::to_string(i + 1);
    j.origin.p = {0, 0, z[i]};
    j.axis = i % 2 == 0 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    j.mass = mass[i];
    j.com = {0.01 * i, 0.005, 0.1};
    j.inertia = Eigen::Vector3d(0.02, 0.025, 0.01 + 0.002 * i).asDiagonal();
    j.inertia(0, 1) = j.inertia(1, 0) = 0.001;
    c.joints.push_back(j);
  }
  c.tip.p = {0, 0, 0.15};
  return c;
}

/// A 4-joint spatial arm (axes z y y y): redundant by one for spatial_position.
Chain spatial_arm4() {
  Chain c = spatial_arm7();
  c.joints.resize(4);
  c.joints[2].axis = Eigen::Vector3d::UnitY();
  c.joints[2].origin.p = {0, 0, 0.4};
  c.joints[3].origin.p = {0, 0, 0.35};
  return c;
}

/// A square of side 0.1 m in a tilted plane around (0.35, 0.1, 0.55), 0.5 s per side.
Path3 spatial_square() {
  const Eigen::Vector3d c(0.35, 0.1, 0.55), u(0.1, 0.0, 0.0), v(0.0, 0.08, 0.06);
  return Path3({c, c + u, c + u + v, c + v, c}, {0.5, 0.5, 0.5, 0.5});
}
VecN spatial_guess(int n) {
  VecN q(n);
  const double g[7] = {0.2, 0.6, 0.1, -1.2, 0.2, 0.8, 0.1};
  for (int i = 0; i < n; ++i) q[i] = g[i];
  return q;
}

TrajectoryOptions chain_options(const SeedCase& c, Integrator integ, double KN) {
  TrajectoryOptions o = c.options();
  o.integrator = integ;
  o.null_damping = KN;
  return o;
}
TaskSpace seed_task_space(const SeedCase& c) {
  return c.method == TrajectoryMethod::vertex_alpha ? TaskSpace::planar_pose : TaskSpace::planar_position;
}

}  // namespace

// The start solve from planar_start_guess(3) lands on the analytic IK's positive elbow.
TEST(ChainStart, SeedArmReachesTheAnalyticPositiveElbow) {
  const Chain chain = seed_chain();
  const PlanarArm3 arm = PlanarArm3::seed();
  for (double deg = -24.0; deg <= 30.0; deg += 0.5) {
    StartTarget t;
    t.position = {1.5, 1.5, 0.0};
    t.angle = deg * M_PI / 180;
    const std::optional<VecN> q = solve_start(chain, t, planar_start_guess(3));
    const std::optional<Vec3> ref = inverse_kinematics(arm, Vec2(1.5, 1.5), t.angle, Elbow::positive);
    ASSERT_TRUE(ref.has_value()) << deg;
    ASSERT_TRUE(q.has_value()) << deg;
    EXPECT_LT((*q - *ref).cwiseAbs().maxCoeff(), 4e-15) << deg;
  }
}

TEST(ChainStart, OutOfReachIsNoSolution) {
  StartTarget t;
  t.position = {3.5, 0.5, 0.0};
  EXPECT_FALSE(solve_start(seed_chain(), t, planar_start_guess(3)).has_value());
}

// Every seed case on the seed arm as a generic chain agrees with the closed form (physical M) to 1e-9
// in every metric and every history entry, with both integrators, with and without K_N.
TEST(ChainTrajectory, SeedArmMatchesTheClosedFormOnEverySeedCase) {
  const Chain chain = seed_chain();
  const PlanarArm3 arm = PlanarArm3::seed();
  const ChainTask position(TaskSpace::planar_position, seed_square(), 1e-3);
  const ChainTask pose(TaskSpace::planar_pose, seed_square(), 1e-3);
  const SampledPath path(seed_square(), 1e-3);
  TrajectoryHistory h;
  ChainHistory gh;
  for (const SeedCase& c : seed_cases())
    for (Integrator integ : {Integrator::semi_implicit_euler, Integrator::rk4})
      for (double KN : {0.0, 2.5}) {
        SCOPED_TRACE(std::string(c.name) + " " + std::string(to_string(integ)) + " K_N " + std::to_string(KN));
        const TrajectoryOptions o = chain_options(c, integ, KN);
        const TrajectoryMetrics ref = simulate(arm, path, o, &h);
        const ChainTask& task = seed_task_space(c) == TaskSpace::planar_pose ? pose : position;
        const TrajectoryMetrics got = simulate(chain, task, planar_start_guess(3), o, &gh);
        ASSERT_EQ(got.status, ref.status);
        ASSERT_EQ(got.samples, ref.samples);
        EXPECT_TRUE(close(got.E, ref.E));
        EXPECT_TRUE(close(got.E_M, ref.E_M));
        ASSERT_EQ(got.tau_inf.size(), 3);
        for (int i = 0; i < 3; ++i) EXPECT_TRUE(close(got.tau_inf[i], ref.tau_inf[i]));
        EXPECT_TRUE(close(got.min_manipulability, ref.min_manipulability));
        EXPECT_TRUE(close(got.torque_sq_integral, ref.torque_sq_integral));
        EXPECT_TRUE(close(got.power_sq_integral, ref.power_sq_integral));
        // an open-loop drift: a difference of nearly equal positions, compared in absolute terms [m]
        EXPECT_NEAR(got.max_tracking_error, ref.max_tracking_error, 1e-9);
        EXPECT_TRUE(close(got.final_alpha, ref.final_alpha));
        EXPECT_EQ(got.stop_time, ref.stop_time);
        ASSERT_EQ(gh.size, h.size);
        const auto rows_close = [&](const auto& a, const auto& b, const char* what) {
          const double scale = b.leftCols(h.size).cwiseAbs().maxCoeff();
          EXPECT_LE((a.leftCols(h.size) - b.leftCols(h.size)).cwiseAbs().maxCoeff(), 1e-9 * scale) << what;
        };
        EXPECT_EQ(gh.t.head(h.size), h.t.head(h.size));
        rows_close(gh.q, h.q, "q");
        rows_close(gh.qd, h.qd, "qd");
        rows_close(gh.qdd, h.qdd, "qdd");
        rows_close(gh.tau, h.tau, "tau");
        rows_close(gh.x, h.x, "x");
        EXPECT_LE((gh.alpha.head(h.size) - h.alpha.head(h.size)).cwiseAbs().maxCoeff(), 1e-9) << "alpha";
      }
}

// The local resolution on random states of planar 4R/5R and spatial chains, every task space:
// J qdd = b, and qdd is the KKT point of min |qdd + v|_W^2 subject to J qdd = b, solved densely.
TEST(ChainResolution, SatisfiesTheTaskAndMatchesTheKktSolve) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  struct Case {
    Chain chain;
    TaskSpace space;
  };
  const std::vector<Case> cases = {
      {planar_chain(planar_bars({1, 1, 1, 1}, {4, 3, 2, 1}, 0.1)), TaskSpace::planar_position},
      {planar_chain(planar_bars({1, 1, 1, 1}, {4, 3, 2, 1}, 0.1)), TaskSpace::planar_pose},
      {planar_chain(planar_bars({0.8, 0.8, 0.8, 0.8, 0.8}, {4, 3, 2, 1.5, 1}, 0.1)), TaskSpace::planar_position},
      {planar_chain(planar_bars({0.8, 0.8, 0.8, 0.8, 0.8}, {4, 3, 2, 1.5, 1}, 0.1)), TaskSpace::planar_pose},
      {spatial_arm4(), TaskSpace::spatial_position},
      {spatial_arm7(), TaskSpace::spatial_position},
      {spatial_arm7(), TaskSpace::spatial_pose},
  };
  auto check = [&]<TaskSpace S>(const Chain& chain) {
    constexpr int m = task_dimension(S);
    const int n = chain.dof();
    ChainData data;
    ChainState st;
    int checked = 0;
    for (int trial = 0; trial < 200; ++trial) {
      VecN q(n), qd(n);
      for (int i = 0; i < n; ++i) {
        q[i] = 3.0 * U(rng);
        qd[i] = 2.0 * U(rng);
      }
      evaluate_dynamics(chain, data, q, qd, st);
      TaskJacobian<m> J;
      select_task_rows<S>(st.J, J);
      if (std::sqrt(gram_determinant<m, m>(J)) < 1e-2) continue;
      TaskVec<m> b;
      for (int r = 0; r < m; ++r) b[r] = 3.0 * U(rng);
      const double k = trial % 3 == 0 ? 1.0 : 0.3, KN = trial % 2 ? 1.5 : 0.0;
      InertiaFactor llt;
      llt.compute(st.M, n);
      const VecN u = st.c + k * st.g;
      const Eigen::MatrixXd M = st.M;
      const Eigen::PartialPivLU<Eigen::MatrixXd> Mlu(M);
      const Eigen::VectorXd v = Mlu.solve(Eigen::VectorXd(u)) + KN * Eigen::VectorXd(qd);
      for (Weighting w : {Weighting::inertia, Weighting::inertia_squared}) {
        const VecN qdd = local_acceleration<m>(w, llt, J, b, u, KN, qd);
        EXPECT_LT((J * qdd - b).norm(), 1e-10 * (1 + b.norm() + (J * qdd).norm()));
        const Eigen::MatrixXd W = w == Weighting::inertia ? M : Eigen::MatrixXd(M * M);
        Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m, n + m);
        K.topLeftCorner(n, n) = W;
        K.topRightCorner(n, m) = Eigen::MatrixXd(J).transpose();
        K.bottomLeftCorner(m, n) = J;
        Eigen::VectorXd rhs(n + m);
        rhs << -(W * v), Eigen::VectorXd(b);
        const Eigen::VectorXd sol = Eigen::PartialPivLU<Eigen::MatrixXd>(K).solve(rhs);
        EXPECT_LT((Eigen::VectorXd(qdd) - sol.head(n)).norm(), 1e-9 * (1 + sol.head(n).norm()));
      }
      ++checked;
    }
    EXPECT_GT(checked, 50);
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.chain.dof());
    SCOPED_TRACE(std::string(to_string(c.space)));
    switch (c.space) {
      case TaskSpace::planar_position: check.operator()<TaskSpace::planar_position>(c.chain); break;
      case TaskSpace::planar_pose: check.operator()<TaskSpace::planar_pose>(c.chain); break;
      case TaskSpace::spatial_position: check.operator()<TaskSpace::spatial_position>(c.chain); break;
      case TaskSpace::spatial_pose: check.operator()<TaskSpace::spatial_pose>(c.chain); break;
    }
  }
}

// local_weighted with k = 1 and K_N = 0 minimises tau^T M^-1 tau among the accelerations that satisfy
// the task: no null-space step lowers it (null space of J from a dense LU).
TEST(ChainResolution, WeightedMinimisesTauMInvTauInTheNullSpace) {
  const Chain chain = planar_chain(planar_bars({0.8, 0.8, 0.8, 0.8, 0.8}, {4, 3, 2, 1.5, 1}, 0.1));
  constexpr int m = 2;
  ChainData data;
  ChainState st;
  VecN q(5), qd(5);
  q << 0.3, 0.7, -0.4, 0.9, -0.2;
  qd << 0.5, -1.0, 0.8, 0.3, -0.6;
  evaluate_dynamics(chain, data, q, qd, st);
  TaskJacobian<m> J;
  select_task_rows<TaskSpace::planar_position>(st.J, J);
  const TaskVec<m> b(0.4, -0.7);
  InertiaFactor llt;
  llt.compute(st.M, 5);
  const VecN u = st.c + st.g;
  const VecN qdd = local_acceleration<m>(Weighting::inertia, llt, J, b, u, 0.0, qd);
  const Eigen::MatrixXd M = st.M;
  const auto cost = [&](const Eigen::VectorXd& a) {
    const Eigen::VectorXd tau = M * a + Eigen::VectorXd(st.c + st.g);
    return tau.dot(M.partialPivLu().solve(tau));
  };
  const Eigen::MatrixXd N = Eigen::FullPivLU<Eigen::MatrixXd>(Eigen::MatrixXd(J)).kernel();
  ASSERT_EQ(N.cols(), 3);
  const double best = cost(qdd);
  for (int j = 0; j < 3; ++j)
    for (double eps : {1e-3, -1e-3, 0.1, -0.1}) EXPECT_GT(cost(Eigen::VectorXd(qdd) + eps * N.col(j)), best);
}

namespace {
struct PropertyRun {
  const char* what;
  Chain chain;
  TaskSpace space;
  Path3 path;
  VecN q0;
  bool unweighted_tracks = true;  ///< false: local_unweighted's null-space motion grows without bound
};
std::vector<PropertyRun> property_runs() {
  const Path3 square = lift_to_3d(seed_square());
  return {
      {"planar 4R position", planar_chain(planar_bars({1, 1, 1, 1}, {4, 3, 2, 1}, 0.1)), TaskSpace::planar_position,
       square, planar_start_guess(4)},
      {"planar 5R position", planar_chain(planar_bars({0.8, 0.8, 0.8, 0.8, 0.8}, {4, 3, 2, 1.5, 1}, 0.1)),
       TaskSpace::planar_position, square, planar_start_guess(5), false},
      {"planar 5R pose", planar_chain(planar_bars({0.8, 0.8, 0.8, 0.8, 0.8}, {4, 3, 2, 1.5, 1}, 0.1)),
       TaskSpace::planar_pose, square, planar_start_guess(5), false},
      {"spatial 4 position", spatial_arm4(), TaskSpace::spatial_position, spatial_square(), spatial_guess(4)},
      {"spatial 7 position", spatial_arm7(), TaskSpace::spatial_position, spatial_square(), spatial_guess(7)},
      {"spatial 7 pose", spatial_arm7(), TaskSpace::spatial_pose, spatial_square(), spatial_guess(7)},
  };
}
TrajectoryOptions property_options(Integrator integ, double dt) {
  TrajectoryOptions o;
  o.integrator = integ;
  o.dt = dt;
  o.alpha1A = 0.2;
  o.vertex_alpha = {0.5, 0.3, 0.0, 0.2};  // planar_pose only
  o.null_damping = 1.0;
  return o;
}
}  // namespace

// The tip follows the path: RK4's open-loop drift is small and falls about 16-fold when dt halves,
// semi-implicit Euler's about 2-fold. The start sits on the first vertex. (local_unweighted on the 5R
// is the seed's case-2 instability: its torques grow to thousands of Nm, so it is left out here.)
TEST(ChainTrajectory, TipFollowsThePathAndDriftConvergesWithDt) {
  for (const PropertyRun& r : property_runs()) {
    SCOPED_TRACE(r.what);
    for (TrajectoryMethod method : {TrajectoryMethod::local_weighted, TrajectoryMethod::local_unweighted}) {
      if (method == TrajectoryMethod::local_unweighted && !r.unweighted_tracks) continue;
      double err[2][2];
      for (int integ = 0; integ < 2; ++integ)
        for (int h = 0; h < 2; ++h) {
          TrajectoryOptions o = property_options(integ ? Integrator::rk4 : Integrator::semi_implicit_euler, h ? 5e-4 : 1e-3);
          o.method = method;
          ChainHistory hist;
          const TrajectoryMetrics m = simulate(r.chain, ChainTask(r.space, r.path, o.dt), r.q0, o, &hist);
          ASSERT_EQ(m.status, RunStatus::ok) << to_string(method);
          ASSERT_EQ(m.tau_inf.size(), r.chain.dof());
          const int P = position_rows(r.space);
          EXPECT_LT((hist.x.col(0) - r.path.vertices().front().head(P)).norm(), 1e-12);
          if (is_planar(r.space))
            EXPECT_NEAR(hist.alpha[0], o.alpha1A, 1e-12);
          else
            EXPECT_TRUE(std::isnan(m.final_alpha));
          err[integ][h] = m.max_tracking_error;
        }
      EXPECT_LT(err[1][0], 1e-6);
      EXPECT_GT(err[0][0] / err[0][1], 1.6);
      EXPECT_LT(err[0][0] / err[0][1], 2.5);
      EXPECT_GT(err[1][0] / err[1][1], 10.0);
    }
  }
}

// planar_pose: the tip angle passes through the vertex orientations (RK4, a redundant 5R).
TEST(ChainTrajectory, PlanarPoseFollowsTheVertexOrientations) {
  const PropertyRun r = property_runs()[2];
  TrajectoryOptions o = property_options(Integrator::rk4, 1e-3);
  ChainHistory h;
  const TrajectoryMetrics m = simulate(r.chain, ChainTask(r.space, r.path, o.dt), r.q0, o, &h);
  ASSERT_EQ(m.status, RunStatus::ok);
  EXPECT_NEAR(h.alpha[500], 0.5, 1e-7);
  EXPECT_NEAR(h.alpha[1000], 0.3, 1e-7);
  EXPECT_NEAR(h.alpha[1500], 0.0, 1e-7);
  EXPECT_NEAR(m.final_alpha, 0.2, 1e-7);
}

// Along a run: the history's torques are the inverse dynamics (RNEA) of the state beside them, and
// the tip acceleration J qdd + Jdot qd, with Jdot qd from central differences of J along qd, is the
// task's acceleration.
TEST(ChainTrajectory, HistoryObeysDynamicsAndTaskAcceleration) {
  for (const PropertyRun& r : property_runs()) {
    SCOPED_TRACE(r.what);
    const TrajectoryOptions o = property_options(Integrator::rk4, 1e-3);
    const ChainTask task(r.space, r.path, o.dt);
    ChainHistory h;
    h.stride = 50;
    const TrajectoryMetrics m = simulate(r.chain, task, r.q0, o, &h);
    ASSERT_EQ(m.status, RunStatus::ok);
    ASSERT_EQ(h.size, 41);
    ChainData data;
    Mat6N Jp, Jm, J;
    for (Eigen::Index c = 1; c < h.size; c += 3) {
      const VecN q = h.q.col(c), qd = h.qd.col(c), qdd = h.qdd.col(c);
      VecN tau;
      rnea(r.chain, data, q, qd, qdd, tau);
      EXPECT_LT((tau - VecN(h.tau.col(c))).norm(), 1e-9 * (1 + tau.norm()));
      const double eps = 1e-6;
      forward_kinematics(r.chain, data, q + eps * qd);
      tip_jacobian(r.chain, data, Jp);
      forward_kinematics(r.chain, data, q - eps * qd);
      tip_jacobian(r.chain, data, Jm);
      forward_kinematics(r.chain, data, q);
      tip_jacobian(r.chain, data, J);
      const Vec6 acc = J * qdd + (Jp - Jm) / (2 * eps) * qd;
      const std::size_t i = static_cast<std::size_t>(c * h.stride);
      const Eigen::Vector3d want = task.path.acceleration(i);
      const int P = position_rows(r.space);
      EXPECT_LT((acc.head(P) - want.head(P)).norm(), 1e-6 * (1 + want.norm())) << "sample " << i;
      if (r.space == TaskSpace::spatial_pose) {
        EXPECT_LT(acc.tail<3>().norm(), 1e-6);
      }
      if (r.space == TaskSpace::planar_pose) {
        Profile1 alpha({Eigen::Matrix<double, 1, 1>(o.alpha1A), Eigen::Matrix<double, 1, 1>(0.5),
                        Eigen::Matrix<double, 1, 1>(0.3), Eigen::Matrix<double, 1, 1>(0.0),
                        Eigen::Matrix<double, 1, 1>(0.2)},
                       r.path.durations());
        EXPECT_NEAR(acc[5], alpha.sample(task.path.time(i)).a[0], 1e-6 * (1 + std::abs(acc[5])));
      }
    }
  }
}

TEST(ChainTrajectory, UnreachableFirstVertexIsAStatus) {
  const PropertyRun r = property_runs()[1];
  const Path3 far({Eigen::Vector3d(5.0, 2.0, 0), Eigen::Vector3d(5.0, 2.5, 0)}, {0.5});
  ChainHistory h;
  const TrajectoryMetrics m = simulate(r.chain, ChainTask(r.space, far, 1e-3), r.q0, TrajectoryOptions{}, &h);
  EXPECT_EQ(m.status, RunStatus::unreachable_start);
  EXPECT_EQ(m.samples, 0u);
  EXPECT_TRUE(std::isnan(m.E));
  ASSERT_EQ(m.tau_inf.size(), 5);
  EXPECT_TRUE(std::isnan(m.tau_inf[4]));
  EXPECT_EQ(h.size, 0);
}

// Paths the arm cannot follow without a singular Jacobian: the seed arm's tip sent out of reach
// (local methods), and a vertex orientation whose path crosses sin(theta2) = 0 (vertex_alpha). With
// a tolerance large enough to be met at a sample, the run stops as singular at the closed form's
// sample.
TEST(ChainTrajectory, SingularPathStopsAsTheClosedFormDoes) {
  const Path2 out({Vec2(1.5, 1.5), Vec2(3.5, 0.5)}, {2.0});
  for (const char* name : {"1a", "2a", "5a"})
    for (Integrator integ : {Integrator::semi_implicit_euler, Integrator::rk4}) {
      SCOPED_TRACE(std::string(name) + " " + std::string(to_string(integ)));
      TrajectoryOptions o = find_seed_case(name)->options();
      o.integrator = integ;
      o.singular_tolerance = 0.2;
      o.torque_bound = 1e12;
      const bool pose = o.method == TrajectoryMethod::vertex_alpha;
      if (pose) o.vertex_alpha[0] = -60.0 * M_PI / 180;
      const Path2& path = pose ? seed_square() : out;
      const TrajectoryMetrics ref = simulate(PlanarArm3::seed(), path, o);
      const TrajectoryMetrics m = simulate(seed_chain(), ChainTask(pose ? TaskSpace::planar_pose : TaskSpace::planar_position, path, 1e-3),
                                           planar_start_guess(3), o);
      ASSERT_EQ(ref.status, RunStatus::singular);
      EXPECT_EQ(m.status, RunStatus::singular);
      EXPECT_EQ(m.samples, ref.samples);
    }
}

// A redundant 4R (reach 4 m) sent out to 4.5 m stops as singular on the way.
TEST(ChainTrajectory, PathOutOfReachStopsAsSingular) {
  const Chain chain = planar_chain(planar_bars({1, 1, 1, 1}, {4, 3, 2, 1}, 0.1));
  const Path3 out({Eigen::Vector3d(2.5, 0.5, 0), Eigen::Vector3d(4.5, 0.0, 0)}, {2.0});
  TrajectoryOptions o;
  o.singular_tolerance = 0.1;
  o.torque_bound = 1e12;
  const TrajectoryMetrics m = simulate(chain, ChainTask(TaskSpace::planar_position, out, 1e-3), planar_start_guess(4), o);
  EXPECT_EQ(m.status, RunStatus::singular);
  EXPECT_GT(m.samples, 100u);
  EXPECT_LT(m.samples, 2001u);
  EXPECT_GE(m.min_manipulability, 0.1);
}

TEST(ChainTrajectory, TorqueBoundStopsTheRunAsDiverged) {
  const PropertyRun r = property_runs()[0];
  TrajectoryOptions o = property_options(Integrator::semi_implicit_euler, 1e-3);
  const TrajectoryMetrics full = simulate(r.chain, ChainTask(r.space, r.path, o.dt), r.q0, o);
  ASSERT_EQ(full.status, RunStatus::ok);
  o.torque_bound = 0.5 * full.tau_inf.maxCoeff();
  const TrajectoryMetrics m = simulate(r.chain, ChainTask(r.space, r.path, o.dt), r.q0, o);
  EXPECT_EQ(m.status, RunStatus::diverged);
  EXPECT_GT(m.samples, 0u);
  EXPECT_LE(m.tau_inf.maxCoeff(), o.torque_bound);
}

TEST(ChainTrajectory, ArgumentsThatDoNotFitThrow) {
  const Chain chain = seed_chain();
  const ChainTask task(TaskSpace::planar_position, seed_square(), 1e-3);
  TrajectoryOptions o;
  EXPECT_THROW(simulate(chain, task, planar_start_guess(4), o), std::invalid_argument);  // q0 size
  o.dt = 2e-3;
  EXPECT_THROW(simulate(chain, task, planar_start_guess(3), o), std::invalid_argument);  // dt
  o = find_seed_case("5a")->options();
  EXPECT_THROW(simulate(chain, task, planar_start_guess(3), o), std::invalid_argument);  // vertex_alpha, position task
  const ChainTask pose(TaskSpace::planar_pose, seed_square(), 1e-3);
  o = TrajectoryOptions{};
  EXPECT_THROW(simulate(chain, pose, planar_start_guess(3), o), std::invalid_argument);  // n = m, local method
  EXPECT_THROW(simulate(spatial_arm7(), task, spatial_guess(7), o), std::invalid_argument);  // planar task, spatial chain
}

// A spatial arm of three joints on a position path has no redundancy: J qdd = b. The tip follows the
// path, the local methods (and k) are the same run bit for bit, and the history's tip acceleration is
// the path's.
TEST(ChainTrajectory, NonRedundantSpatialArmSolvesTheTask) {
  Chain c;
  c.name = "elbow3";
  c.source = "test";
  c.gravity = {0, 0, -9.81};
  const double z[3] = {0.3, 0.0, 0.45};
  const Eigen::Vector3d axis[3] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitY()};
  for (int i = 0; i < 3; ++i) {
    ChainJoint j;
    j.name = "j" + std::to_string(i + 1);
    j.origin.p = {0, 0, z[i]};
    j.axis = axis[i];
    j.mass = 3.0 - i;
    j.com = {0, 0, 0.2};
    j.inertia = Eigen::Vector3d(0.02, 0.02, 0.005).asDiagonal();
    c.joints.push_back(j);
  }
  c.tip.p = {0, 0, 0.4};
  c.prepare();
  const Path3 path({Eigen::Vector3d(0.4, 0.1, 0.5), Eigen::Vector3d(0.45, -0.1, 0.4), Eigen::Vector3d(0.35, 0.0, 0.6)},
                   {1.0, 1.0});
  TrajectoryOptions o;
  o.integrator = Integrator::rk4;
  o.dt = 1e-3;
  const ChainTask task(TaskSpace::spatial_position, path, o.dt);
  const VecN q0 = (VecN(3) << 0.2, 0.6, 0.9).finished();
  ChainHistory h;
  h.stride = 100;
  const TrajectoryMetrics a = simulate(c, task, q0, o, &h);
  ASSERT_EQ(a.status, RunStatus::ok);
  EXPECT_LT(a.max_tracking_error, 1e-6);
  EXPECT_GT(a.min_manipulability, 0.0);
  for (TrajectoryMethod method : {TrajectoryMethod::local_unweighted, TrajectoryMethod::local_weighted}) {
    TrajectoryOptions p = o;
    p.method = method;
    p.k = 0.7;
    const TrajectoryMetrics b = simulate(c, task, q0, p);
    EXPECT_EQ(b.E, a.E);
    EXPECT_EQ(b.tau_inf, a.tau_inf);
    EXPECT_EQ(b.power_sq_integral, a.power_sq_integral);
  }
  ChainData data;
  Mat6N Jp, Jm, J;
  for (Eigen::Index col = 1; col < h.size; col += 4) {
    const VecN q = h.q.col(col), qd = h.qd.col(col), qdd = h.qdd.col(col);
    const double eps = 1e-6;
    forward_kinematics(c, data, q + eps * qd);
    tip_jacobian(c, data, Jp);
    forward_kinematics(c, data, q - eps * qd);
    tip_jacobian(c, data, Jm);
    forward_kinematics(c, data, q);
    tip_jacobian(c, data, J);
    const Vec6 acc = J * qdd + (Jp - Jm) / (2 * eps) * qd;
    const Eigen::Vector3d want = task.path.acceleration(static_cast<std::size_t>(col * h.stride));
    EXPECT_LT((acc.head<3>() - want).norm(), 1e-6 * (1 + want.norm())) << "row " << col;
  }
}

TEST(ChainTrajectory, TaskSpaceNamesRoundTrip) {
  for (auto s : {TaskSpace::planar_position, TaskSpace::planar_pose, TaskSpace::spatial_position, TaskSpace::spatial_pose}) {
    TaskSpace back;
    ASSERT_TRUE(parse(to_string(s), back));
    EXPECT_EQ(back, s);
  }
  TaskSpace x;
  EXPECT_FALSE(parse("planar", x));
}
