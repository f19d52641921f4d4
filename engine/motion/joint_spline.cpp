// SplineBasis and JointSpline (motion/joint_spline.hpp).
#include "motion/joint_spline.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ks::motion {
namespace {

// The cubic Hermite functions H00, H10, H01, H11 on tau in [0, 1] and their derivatives in tau:
// out[0..3] for derivative `order` (0 .. 3).
void hermite(double tau, int order, double out[4]) {
  const double t2 = tau * tau, t3 = t2 * tau;
  switch (order) {
    case 0:
      out[0] = 2 * t3 - 3 * t2 + 1, out[1] = t3 - 2 * t2 + tau, out[2] = -2 * t3 + 3 * t2, out[3] = t3 - t2;
      return;
    case 1:
      out[0] = 6 * t2 - 6 * tau, out[1] = 3 * t2 - 4 * tau + 1, out[2] = -6 * t2 + 6 * tau, out[3] = 3 * t2 - 2 * tau;
      return;
    case 2:
      out[0] = 12 * tau - 6, out[1] = 6 * tau - 4, out[2] = -12 * tau + 6, out[3] = 6 * tau - 2;
      return;
    default:
      out[0] = 12, out[1] = 6, out[2] = -12, out[3] = 6;
      return;
  }
}

}  // namespace

SplineBasis::SplineBasis(int controls) : K_(controls), h_(1.0 / (controls + 1)) {
  if (controls < 0 || controls > kMaxControls)
    throw std::invalid_argument("SplineBasis: controls " + std::to_string(controls) + " not in 0 .. " +
                                std::to_string(kMaxControls));
  const int N = K_ + 2;
  S_.setZero(N, N);
  if (K_ == 0) return;
  // interior slopes: A m_int = B y, A tridiagonal (1, 4, 1), B y = 3 (y_{j+1} - y_{j-1}) / h
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(K_, K_), B = Eigen::MatrixXd::Zero(K_, N);
  for (int r = 0; r < K_; ++r) {
    A(r, r) = 4.0;
    if (r > 0) A(r, r - 1) = 1.0;
    if (r + 1 < K_) A(r, r + 1) = 1.0;
    B(r, r) = -3.0 / h_;      // node j - 1 = r
    B(r, r + 2) = 3.0 / h_;   // node j + 1 = r + 2
  }
  S_.block(1, 0, K_, N) = A.partialPivLu().solve(B);
}

int SplineBasis::segment(double u) const {
  const double v = std::clamp(u, 0.0, 1.0);
  return std::min(static_cast<int>(std::floor(v / h_)), K_);
}

void SplineBasis::weights(double u, int order, NodeVec& w) const {
  const int j = segment(u);
  const double tau = (std::clamp(u, 0.0, 1.0) - j * h_) / h_;
  double H[4];
  hermite(tau, order, H);
  const double scale = std::pow(h_, -order);  // d/du = (1/h) d/dtau
  w.setZero(K_ + 2);
  // s = H00 y_j + h H10 m_j + H01 y_{j+1} + h H11 m_{j+1}, m = S y
  w[j] += scale * H[0];
  w[j + 1] += scale * H[2];
  w += (scale * h_ * H[1]) * S_.row(j).transpose();
  w += (scale * h_ * H[3]) * S_.row(j + 1).transpose();
}

void SplineBasis::jerk_weights(int segment, NodeVec& w) const {
  weights((std::clamp(segment, 0, K_) + 0.5) * h_, 3, w);
}

JointSpline::JointSpline(const VecN& q_start, const VecN& q_goal, int controls, double duration)
    : basis_(controls), T_(1.0) {
  if (q_start.size() < 1 || q_start.size() > kMaxJoints || q_goal.size() != q_start.size())
    throw std::invalid_argument("JointSpline: q_start and q_goal must have the same size, 1 .. " +
                                std::to_string(kMaxJoints));
  set_duration(duration);
  nodes_.resize(q_start.size(), controls + 2);
  nodes_.col(0) = q_start;
  nodes_.col(controls + 1) = q_goal;
  set_controls(cubic_controls());
}

void JointSpline::set_controls(std::span<const double> c) {
  const int n = joints(), K = controls();
  if (static_cast<int>(c.size()) != n * K)
    throw std::invalid_argument("JointSpline: " + std::to_string(c.size()) + " control values for " +
                                std::to_string(n) + " joints x " + std::to_string(K) + " controls");
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < K; ++k) nodes_(i, k + 1) = c[static_cast<std::size_t>(i * K + k)];
}

void JointSpline::set_duration(double T) {
  if (!(T > 0.0) || !std::isfinite(T)) throw std::invalid_argument("JointSpline: duration must be finite and > 0");
  T_ = T;
}

std::vector<double> JointSpline::cubic_controls() const {
  const int n = joints(), K = controls();
  std::vector<double> c(static_cast<std::size_t>(n * K));
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < K; ++k) {
      const double u = (k + 1) * basis_.spacing();
      const double a = nodes_(i, 0), b = nodes_(i, K + 1);
      c[static_cast<std::size_t>(i * K + k)] = a + (b - a) * u * u * (3.0 - 2.0 * u);
    }
  return c;
}

void JointSpline::evaluate(double t, VecN& q, VecN& qd, VecN& qdd, VecN& jerk) const {
  const double u = std::clamp(t / T_, 0.0, 1.0);
  NodeVec w;
  basis_.weights(u, 0, w);
  q = nodes_ * w;
  basis_.weights(u, 1, w);
  qd = nodes_ * w / T_;
  basis_.weights(u, 2, w);
  qdd = nodes_ * w / (T_ * T_);
  basis_.weights(u, 3, w);
  jerk = nodes_ * w / (T_ * T_ * T_);
}

void JointSpline::control_weights(double t, int order, NodeVec& w) const {
  NodeVec all;
  basis_.weights(std::clamp(t / T_, 0.0, 1.0), order, all);
  w = all.segment(1, controls()) * std::pow(T_, -order);
}

void JointSpline::duration_derivative(double t, int order, VecN& d) const {
  const double u = std::clamp(t / T_, 0.0, 1.0);
  NodeVec w;
  basis_.weights(u, order, w);
  const VecN x = nodes_ * w * std::pow(T_, -order);  // q^(order)(t)
  VecN next = VecN::Zero(joints());                  // q^(order+1)(t) (the fourth derivative is 0)
  if (order < 3) {
    basis_.weights(u, order + 1, w);
    next = nodes_ * w * std::pow(T_, -(order + 1));
  }
  d = -(u * T_ * next + order * x) / T_;  // -(t q^(order+1) + order q^(order)) / T
}

}  // namespace ks::motion
