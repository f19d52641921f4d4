#pragma once
// A rest-to-rest joint trajectory: each joint a C² cubic spline through its start, K control values
// at equally spaced times and its goal, clamped (zero velocity at both ends). The spline is written
// in normalised time u = t / T in [0, 1], q(t) = s(t / T), so the duration T scales its derivatives:
// q̇ = s'(u) / T, q̈ = s''(u) / T², jerk = s'''(u) / T³.
//
// The spline is linear in its node values (start, controls, goal): every derivative at any u is a
// weight row over the nodes, the same for every joint (SplineBasis). The derivatives of a motion with
// respect to its control values are these weights, exactly. Units: rad (revolute) or m (prismatic),
// seconds; no allocation after construction (fixed-maximum-size types).
#include <Eigen/Core>
#include <span>
#include <vector>

#include "model/chain.hpp"

namespace ks::motion {

/// The most control values per joint (nodes: controls + 2).
inline constexpr int kMaxControls = 30;
inline constexpr int kMaxNodes = kMaxControls + 2;

using NodeVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxNodes, 1>;  ///< one weight per node
using NodeMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJoints, kMaxNodes>;  ///< joints x nodes

/// The clamped cubic spline on [0, 1] with nodes u_j = j / (K + 1), j = 0 .. K + 1, as a linear map
/// from node values y to s(u) and its derivatives. Slopes at the nodes: m = S y with m_0 = m_{K+1} = 0
/// and, at the interior nodes, m_{j-1} + 4 m_j + m_{j+1} = 3 (y_{j+1} - y_{j-1}) / h (C² continuity,
/// h = 1 / (K + 1)); each segment is the cubic Hermite interpolant of its two nodes' values and slopes.
class SplineBasis {
 public:
  /// controls: K interior nodes, 0 .. kMaxControls (0: the rest-to-rest cubic 3u² - 2u³ between the
  /// ends). Throws std::invalid_argument outside that range.
  explicit SplineBasis(int controls);

  int controls() const { return K_; }
  int nodes() const { return K_ + 2; }
  int segments() const { return K_ + 1; }
  double spacing() const { return h_; }  ///< h = 1 / (K + 1), in u
  /// The segment holding u (clamped to [0, 1]): floor(u / h), the last one at u = 1.
  int segment(double u) const;

  /// The weights of d^order s / du^order (order 0 .. 3) at u in [0, 1] over the node values:
  /// s^(order)(u) = w · y. At a node the segment to its right is used (to its left at u = 1); only
  /// the third derivative differs between the two. \param[out] w (nodes()).
  void weights(double u, int order, NodeVec& w) const;
  /// The third derivative's weights on segment j (constant on it). \param[out] w (nodes()).
  void jerk_weights(int segment, NodeVec& w) const;

 private:
  int K_;
  double h_;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxNodes, kMaxNodes> S_;  // slopes = S_ y
};

/// n joints' splines over duration T, their node values in a joints x nodes matrix (column 0 the
/// start, K + 1 the goal, 1 .. K the control values).
class JointSpline {
 public:
  /// q_start, q_goal (dim n, 1 .. kMaxJoints) [rad or m]; controls K; duration T > 0 [s]. The
  /// control values start on the rest-to-rest cubic (cubic_controls()). Throws std::invalid_argument
  /// on a size mismatch, K out of range or T <= 0 (or not finite).
  JointSpline(const VecN& q_start, const VecN& q_goal, int controls, double duration);

  int joints() const { return static_cast<int>(nodes_.rows()); }
  int controls() const { return basis_.controls(); }
  double duration() const { return T_; }
  const SplineBasis& basis() const { return basis_; }
  const NodeMat& nodes() const { return nodes_; }
  /// The time of control k (0 .. K - 1): (k + 1) T / (K + 1) [s].
  double control_time(int k) const { return (k + 1) * basis_.spacing() * T_; }

  /// Control values, joint-major: c[i K + k] is joint i's k-th (n K values) [rad or m].
  /// Throws std::invalid_argument on a size mismatch.
  void set_controls(std::span<const double> c);
  void set_duration(double T);  ///< T > 0 [s]; throws std::invalid_argument otherwise
  /// The control values that put every joint on the rest-to-rest cubic q_start + (q_goal -
  /// q_start)(3u² - 2u³): the clamped spline through them is that cubic exactly (n K values).
  std::vector<double> cubic_controls() const;

  /// Position [rad], velocity [rad/s], acceleration [rad/s²] and jerk [rad/s³] at t in [0, T]
  /// (clamped; the jerk of the segment to the right of a node). \param[out] q, qd, qdd, jerk (dim n).
  void evaluate(double t, VecN& q, VecN& qd, VecN& qdd, VecN& jerk) const;
  /// d q_i^(order)(t) / d c_{i,k} for k = 0 .. K - 1 (the same for every joint i; other joints' controls
  /// do not move joint i): order 0 [1], 1 [1/s], 2 [1/s²], 3 [1/s³]. \param[out] w (K).
  void control_weights(double t, int order, NodeVec& w) const;
  /// d q^(order)(t) / dT at fixed t: -(t q^(order+1)(t) + order q^(order)(t)) / T (from
  /// q^(order)(t) = s^(order)(t / T) / T^order; the fourth derivative is 0 inside a segment). \param[out] d (dim n) [rad/s^(order+1)].
  void duration_derivative(double t, int order, VecN& d) const;

 private:
  SplineBasis basis_;
  NodeMat nodes_;
  double T_;
};

}  // namespace ks::motion
