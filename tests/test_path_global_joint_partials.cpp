// The exact partials of the joints extension (methods/path_global/joint_partials.hpp) against central
// differences: each sample's joint positions, rates and torques and its term of each objective, with
// respect to each coordinate's value, rate and acceleration, on the 7-DOF arm (spatial, 4 coordinates),
// the planar 4R (2 coordinates, the planar dynamics) and the SCARA (a prismatic joint among the solved
// ones); then the whole objective's gradient and the limit Jacobian against differences of the objective.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "methods/chain/start.hpp"
#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/joint_chart.hpp"
#include "robot/urdf.hpp"

using namespace ks;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Case {
  std::string name;
  Chain chain;
  TaskSpace space;
  std::vector<int> solved;
  VecN q0;  // on the path's first vertex
  std::vector<Eigen::Vector3d> vertices;  // 1 s between two [m]
  Path3 path() const { return Path3(vertices, std::vector<double>(vertices.size() - 1, 1.0)); }
};

Chain urdf(const std::string& file, const std::string& tip, Eigen::Vector3d g) {
  return load_urdf(std::string(KS_SOURCE_DIR) + "/studies/robots/" + file, "base_link", tip, g);
}

/// The vertices of a square of side `side` [m] through the tip of q0, in the plane of `u` and `v`.
std::vector<Eigen::Vector3d> square_at(const Chain& chain, const VecN& q0, const Eigen::Vector3d& u, const Eigen::Vector3d& v, double side) {
  ChainData data;
  forward_kinematics(chain, data, q0);
  const Eigen::Vector3d p = data.tip.p;
  return {p, p + side * u, p + side * (u + v), p + side * v, p};
}

/// The chains, their solved joints, start configurations and paths: the 7-DOF arm on the first side of
/// studies/arm7_square.toml's square from its best start posture; the planar 4R and the SCARA on small
/// squares through their tips at a configuration away from singularities.
std::vector<Case> cases() {
  std::vector<Case> out;
  {
    Case c{"arm7", urdf("arm7.urdf", "tool", {0, 0, -9.81}), TaskSpace::spatial_position, {0, 1, 3}, VecN::Constant(7, 0.3),
           {{0.5, -0.1, 0.4}, {0.5, 0.0, 0.4}}};
    c.q0[2] = 60 * kDeg, c.q0[3] = -90 * kDeg;
    StartTarget t;
    t.position = c.vertices.front();
    t.planar = false;
    c.q0 = *solve_start(c.chain, t, c.q0);
    out.push_back(c);
  }
  for (Case c : {Case{"planar4r", urdf("planar4r.urdf", "tool", {0, -9.81, 0}), TaskSpace::planar_position, {1, 2},
                      joint_vector({0.4, 0.7, -0.9, 0.5}), {}},
                 Case{"scara", urdf("scara.urdf", "tool", {0, 0, -9.81}), TaskSpace::spatial_position, {0, 1, 2},
                      joint_vector({0.3, 0.8, 0.05, 0.4}), {}}}) {
    const bool planar = c.space == TaskSpace::planar_position;
    c.vertices = square_at(c.chain, c.q0, planar ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY(),
                       planar ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ(), 0.05);
    out.push_back(c);
  }
  return out;
}

/// The spline coefficients of a smooth excursion of the coordinates around their start values.
std::vector<double> excursion(const JointExtensionProblem& p, const VecN& q, int K) {
  std::vector<double> c(static_cast<std::size_t>(K) * p.coordinates());
  double z[kMaxJoints];
  Elbow e;
  p.coordinates_of(0, q, z, e);
  for (int k = 0; k < p.coordinates(); ++k)
    for (int j = 0; j < K; ++j) c[k * K + j] = z[k] + (j == 0 ? 0.0 : 0.05 * std::sin(1.0 + j + 2.0 * k));
  return c;
}

/// Richardson-extrapolated central difference of g at x: (4 D(h/2) - D(h)) / 3.
template <class G>
double richardson(G g, double h) {
  const double d1 = (g(h) - g(-h)) / (2 * h), d2 = (g(h / 2) - g(-h / 2)) / h;
  return (4 * d2 - d1) / 3;
}

}  // namespace

TEST(PathGlobalJointPartials, EachSamplesPartialsMatchCentralDifferences) {
  for (const Case& cs : cases()) {
    SCOPED_TRACE(cs.name);
    const double dt = 0.02;
    const ChainTask task(cs.space, cs.path(), dt);
    const JointExtensionProblem p(cs.chain, task, cs.solved, cs.q0);
    const int K = 6, r = p.coordinates(), n = cs.chain.dof();
    const AlphaBasis b = cubic_spline_basis(task.path.size(), dt, 4.0, K);
    const std::vector<double> c = excursion(p, cs.q0, K);
    double z[kMaxJoints][3];
    ChainGlobalSample s, up;
    p.begin_pass();
    int checked = 0;
    for (std::size_t i = 0; i < p.samples(); ++i) {
      for (int k = 0; k < r; ++k) b.at(i, c.data() + k * K, z[k][0], z[k][1], z[k][2]);
      p.sample(i, z, s);
      ASSERT_EQ(s.violation, 0.0) << i;
      if (i % 11 == 5) {
        ++checked;
        for (GlobalObjective objective : {GlobalObjective::torque_sq_integral, GlobalObjective::E, GlobalObjective::E_M,
                                          GlobalObjective::kinetic_energy}) {
          p.sample(i, z, s);  // the partials read the last sample computed
          ChainSamplePartials d;
          const double weight = 0.37;
          ASSERT_TRUE(p.partials(i, z, s, objective, weight, d));
          ASSERT_EQ(d.inputs, 3 * r);
          for (int input = 0; input < 3 * r; ++input) {
            const int k = input / 3, order = input % 3;
            // the sample at z + h e_input, continued from the last accepted sample as the objective's pass does
            auto at = [&](double h, auto get) {
              double zz[kMaxJoints][3];
              for (int a = 0; a < r; ++a)
                for (int e = 0; e < 3; ++e) zz[a][e] = z[a][e];
              zz[k][order] += h;
              p.sample(i, zz, up);
              return get(up);
            };
            const double h = 1e-4;
            const auto term = [&](const ChainGlobalSample& x) {
              switch (objective) {
                case GlobalObjective::E: return weight * x.tau.norm();
                case GlobalObjective::torque_sq_integral: return weight * x.tau.squaredNorm();
                default: break;
              }
              ChainState st;
              ChainData data;
              evaluate_dynamics(cs.chain, data, x.q, x.qd, st);
              if (objective == GlobalObjective::E_M) return weight * std::sqrt(x.tau.dot(st.M.ldlt().solve(x.tau)));
              return weight * 0.5 * x.qd.dot(st.M * x.qd);
            };
            const double fd = richardson([&](double hh) { return at(hh, term); }, h);
            EXPECT_NEAR(d.cost[input], fd, 1e-7 * std::max(1.0, std::abs(fd))) << "sample " << i << ", input " << input;
            if (objective != GlobalObjective::E) continue;
            for (int j = 0; j < n; ++j) {
              const double dq = richardson([&](double hh) { return at(hh, [&](const ChainGlobalSample& x) { return x.q[j]; }); }, h);
              const double dqd = richardson([&](double hh) { return at(hh, [&](const ChainGlobalSample& x) { return x.qd[j]; }); }, h);
              const double dtau = richardson([&](double hh) { return at(hh, [&](const ChainGlobalSample& x) { return x.tau[j]; }); }, h);
              EXPECT_NEAR(d.q[j][input], dq, 1e-8 * std::max(1.0, std::abs(dq))) << "q " << j << ", sample " << i << ", input " << input;
              EXPECT_NEAR(d.qd[j][input], dqd, 1e-7 * std::max(1.0, std::abs(dqd))) << "qd " << j << ", sample " << i << ", input " << input;
              EXPECT_NEAR(d.tau[j][input], dtau, 1e-7 * std::max(1.0, std::abs(dtau))) << "tau " << j << ", sample " << i << ", input " << input;
            }
          }
        }
      }
      p.sample(i, z, s);
      p.accept(i, z, s);
    }
    EXPECT_GE(checked, 5);
  }
}

// The objective's gradient (every objective) and the limit constraints' Jacobian, assembled from the
// samples' partials through the spline basis, against Richardson-extrapolated central differences of
// the objective in each coefficient.
TEST(PathGlobalJointPartials, ObjectiveGradientAndLimitJacobianMatchCentralDifferences) {
  for (const Case& cs : cases()) {
    SCOPED_TRACE(cs.name);
    const double dt = 0.02;
    const ChainTask task(cs.space, cs.path(), dt);
    const JointExtensionProblem p(cs.chain, task, cs.solved, cs.q0);
    const int K = 5, size = K * p.coordinates();
    const AlphaBasis b = cubic_spline_basis(task.path.size(), dt, 4.0, K);
    const std::vector<double> c = excursion(p, cs.q0, K);
    const LimitConstraints limits = LimitConstraints::of(cs.chain, p.samples(), K);
    for (GlobalObjective objective : {GlobalObjective::E, GlobalObjective::E_M, GlobalObjective::torque_sq_integral,
                                      GlobalObjective::kinetic_energy}) {
      std::vector<double> grad(size), con(limits.count()), jac(limits.count() * static_cast<std::size_t>(size));
      p.objective(b, c.data(), objective, grad.data(), &limits, con.data(), jac.data());
      for (int var = 0; var < size; ++var) {
        auto f = [&](double h) {
          std::vector<double> x = c;
          x[var] += h;
          return p.objective(b, x.data(), objective, nullptr);
        };
        const double fd = richardson(f, 1e-4);
        EXPECT_NEAR(grad[var], fd, 1e-7 * std::max(1.0, std::abs(fd))) << "variable " << var;
        for (std::size_t row = 0; row < con.size(); ++row) {
          auto g = [&](double h) {
            std::vector<double> x = c, cc(con.size());
            x[var] += h;
            p.objective(b, x.data(), objective, nullptr, &limits, cc.data());
            return cc[row];
          };
          if (objective != GlobalObjective::E) break;  // the constraints do not depend on the objective
          const double cd = richardson(g, 1e-5);
          EXPECT_NEAR(jac[row * size + var], cd, 1e-6 * std::max(1.0, std::abs(cd))) << "constraint " << row << ", variable " << var;
        }
      }
    }
  }
}
