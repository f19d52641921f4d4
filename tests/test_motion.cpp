// Point-to-point motions (engine/motion): the clamped joint spline against a dense solve of its
// interpolation system, its linear map from the control values and its derivatives in the duration.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <random>

#include "motion/joint_spline.hpp"

using namespace ks;
using namespace ks::motion;

namespace {

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
