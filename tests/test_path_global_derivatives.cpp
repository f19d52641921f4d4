// The exact derivatives of the 3R path-global evaluator: derivative numbers against central
// differences, the closed-form extended solve against Eigen's LU, the value part of a derivative
// evaluation against the plain one bit for bit, the objective's gradient against central differences
// of the objective in every extension and objective.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <random>

#include "methods/closed_form/lanes.hpp"
#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/closed_form.hpp"
#include "methods/path_global/sample_3r.hpp"
#include "model/dual.hpp"
#include "path_global_fixtures.hpp"
#include "task/task_path.hpp"

namespace ks {
namespace {

using D = Dual<2>;

// f(x, y) = sqrt(x^2 y + 3) sin(x) / (y - 5) + cos(x y): every operation Dual defines
template <class T>
T composite(const T& x, const T& y) {
  T s, c, sxy, cxy;
  sincos_of(x, s, c);
  sincos_of(x * y, sxy, cxy);
  return sqrt_of(x * x * y + 3.0) * s / (y - 5.0) + cxy - (-x) / 2.0;
}

TEST(Dual, PartialsMatchCentralDifferencesAndValuesMatchDoubles) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0), w(0.1, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double x = u(rng), y = w(rng);
    const D f = composite(D::input(x, 0), D::input(y, 1));
    EXPECT_EQ(f.v, composite(x, y));  // the same operations, the same rounding
    const double h = 1e-6;
    const double fx = (composite(x + h, y) - composite(x - h, y)) / (2 * h);
    const double fy = (composite(x, y + h) - composite(x, y - h)) / (2 * h);
    EXPECT_NEAR(f.d[0], fx, 1e-8 * std::max(1.0, std::abs(fx)));
    EXPECT_NEAR(f.d[1], fy, 1e-8 * std::max(1.0, std::abs(fy)));
  }
}

// Widths that are a multiple of four take their derivatives four at a time (model/dual.hpp); any
// other width one at a time. The same seeds give the same bits either way.
TEST(Dual, FourWideDerivativesEqualTheOneAtATimeLoopBitForBit) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-2.0, 2.0), w(0.1, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double x = u(rng), y = w(rng);
    const Dual<8> f8 = composite(Dual<8>::input(x, 1), Dual<8>::input(y, 6));
    const Dual<7> f7 = composite(Dual<7>::input(x, 1), Dual<7>::input(y, 6));
    EXPECT_EQ(f8.v, f7.v);
    for (int k = 0; k < 7; ++k) EXPECT_EQ(f8.d[k], f7.d[k]) << "slot " << k;
    EXPECT_EQ(f8.d[7], 0.0);
    EXPECT_NE(f8.d[1], 0.0);
    EXPECT_NE(f8.d[6], 0.0);
  }
}

TEST(PathGlobalDerivatives, ClosedFormExtendedSolveEqualsLU) {
  const PlanarArm3 arm = PlanarArm3::seed();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3 q(u(rng), u(rng), u(rng));
    const JointTrig t = joint_trig(q);
    const Vec3 b(u(rng), u(rng), u(rng));
    Mat3 J3;
    J3.topRows<2>() = jacobian(arm, t);
    J3.row(2).setOnes();
    const Eigen::PartialPivLU<Mat3> lu(J3);
    const double det = arm.l[0] * arm.l[1] * t.s2;
    EXPECT_NEAR(det, lu.determinant(), 1e-13);
    if (std::abs(det) < 1e-3) continue;  // conditioning, not the formula, decides the agreement there
    const Vec3 x = solve_extended_3r(arm, t, 1.0 / det, b[0], b[1], b[2]), ref = lu.solve(b);
    EXPECT_LT((x - ref).norm(), 1e-11 * std::max(1.0, ref.norm())) << q.transpose();
  }
}

// Each torque's partials with respect to the coordinate, its rate and its acceleration, at samples of
// the seed's square in both extensions: derivative numbers against central differences of the values.
TEST(PathGlobalDerivatives, SampleTorquePartialsMatchCentralDifferences) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const DynamicsCoefficients dyn(arm);
  const SampledPath path(seed_square(), 1e-3);
  using D3 = Dual<3>;
  for (std::size_t i : {std::size_t(0), std::size_t(333), std::size_t(1200), std::size_t(1999)}) {
    const Vec2 p = path.position(i), v = path.path().sample_on(path.segment(i), path.time(i)).v,
               acc = path.acceleration(i);
    const Sample3RPointOf<double> pt{p.x(), p.y(), v.x(), v.y(), acc.x(), acc.y()};
    for (const double a0 : {-0.3, 0.1, 0.4}) {
      const double x[3] = {a0, 0.7, -2.0};
      const auto eval = [&](const double* y) {
        Sample3ROf<double> s;
        sample_3r(arm, dyn, pt, y[0], y[1], y[2], true, 1, PathGlobalProblem::kReachClamp, 0.0, 0.0, s);
        return s;
      };
      Sample3ROf<D3> s;
      sample_3r(arm, dyn, pt, D3::input(x[0], 0), D3::input(x[1], 1), D3::input(x[2], 2), true, 1,
                PathGlobalProblem::kReachClamp, D3(0.0), D3(0.0), s);
      if (!s.reachable) continue;
      for (int k = 0; k < 3; ++k) {
        const double h = 1e-6;
        double up[3] = {x[0], x[1], x[2]}, down[3] = {x[0], x[1], x[2]};
        up[k] += h;
        down[k] -= h;
        const Sample3ROf<double> su = eval(up), sd = eval(down);
        for (int j = 0; j < 3; ++j) {
          const double fd = (su.tau[j] - sd.tau[j]) / (2 * h);
          EXPECT_NEAR(s.tau[j].d[k], fd, 1e-6 * std::max(1.0, std::abs(fd))) << i << " " << a0 << " " << k << " " << j;
        }
      }
    }
  }
}

// The objective's exact gradient against central differences of the objective over the coefficients,
// every extension and objective, at a spline fitted to the thesis' case 4 (within reach everywhere).
// (The 12-knot spline: rows of full width and the last rows' narrower ones.)
TEST(PathGlobalDerivatives, ObjectiveGradientMatchesCentralDifferences) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  for (Extension ext : {Extension::self_motion, Extension::alpha}) {
    const PathGlobalProblem problem(arm, path, Elbow::positive, 1e-9, ext);
    const AlphaBasis b = cubic_spline_basis(path, 12);
    const std::vector<double> c = case4_fit(problem, path, b);
    if (ext == Extension::alpha) {  // within reach (the self-motion chart reaches by construction)
      std::vector<double> reach(path.size());
      problem.reach(b, c.data(), reach.data(), nullptr);
      ASSERT_LT(*std::max_element(reach.begin(), reach.end()), 0.0);
    }
    for (GlobalObjective obj : {GlobalObjective::E, GlobalObjective::E_M, GlobalObjective::torque_sq_integral,
                                GlobalObjective::kinetic_energy}) {
      std::vector<double> g(b.coefficients);
      const double f = problem.objective(b, c.data(), obj, g.data());
      EXPECT_EQ(f, problem.objective(b, c.data(), obj, nullptr)) << "the value part is the plain evaluation";
      for (int k = 0; k < b.coefficients; ++k) {
        // central differences at h and h / 2, extrapolated (Richardson): truncation error O(h^4)
        const auto central = [&](double h) {
          std::vector<double> up = c, down = c;
          up[k] += h;
          down[k] -= h;
          return (problem.objective(b, up.data(), obj, nullptr) - problem.objective(b, down.data(), obj, nullptr)) /
                 (2 * h);
        };
        const double fd = (4.0 * central(5e-6) - central(1e-5)) / 3.0;
        EXPECT_NEAR(g[k], fd, 1e-7 * std::max(1.0, std::abs(fd))) << to_string(ext) << " " << to_string(obj) << " " << k;
      }
    }
  }
}

// The objective and its gradient evaluated in lanes (every width the processor has) equal the
// one-by-one evaluation bit for bit.
TEST(PathGlobalDerivatives, LaneWidthsGiveTheSameBits) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const SampledPath path(seed_square(), 1e-3);
  for (Extension ext : {Extension::self_motion, Extension::alpha}) {
    const PathGlobalProblem problem(arm, path, Elbow::positive, 1e-9, ext);
    const AlphaBasis b = cubic_spline_basis(path, 20);
    std::vector<double> c = case4_fit(problem, path, b);
    c[3] += 2.0;  // some samples out of reach (alpha: the boundary and the barrier in lanes)
    for (GlobalObjective obj : {GlobalObjective::E, GlobalObjective::E_M, GlobalObjective::torque_sq_integral,
                                GlobalObjective::kinetic_energy}) {
      limit_lanes(1);
      std::vector<double> g1(b.coefficients);
      const double f1 = problem.objective(b, c.data(), obj, g1.data());
      for (int lanes : {4, 8}) {
        if (lanes > supported_lanes()) continue;
        limit_lanes(lanes);
        std::vector<double> g(b.coefficients);
        EXPECT_EQ(problem.objective(b, c.data(), obj, g.data()), f1) << lanes << " " << to_string(obj);
        EXPECT_EQ(g, g1) << lanes << " " << to_string(ext) << " " << to_string(obj);
        EXPECT_EQ(problem.objective(b, c.data(), obj, nullptr), f1) << lanes;
      }
      limit_lanes(0);
    }
  }
}

}  // namespace
}  // namespace ks
