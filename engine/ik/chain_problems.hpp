#pragma once
// IK problem descriptions (ik/problem.hpp) over a serial chain (model/chain.hpp), for a compile-time
// number of joints N (2 .. kMaxJoints) and one of four tasks:
//
//   planar_position   M = 2  F = (x, y) of the tip - target [m]
//   planar_pose       M = 3  F = (x, y) - target [m], wrap(phi(q) - alpha) [rad]; planar chains only
//   spatial_position  M = 3  F = tip position - target [m]
//   spatial_pose      M = 6  F = (tip position - target [m], r(R R*^T) [rad, see below])
//
// Orientation residual of spatial_pose: with E = R R*^T (R the tip rotation, R* the target's, both
// in the base frame), s = vee(E - E^T) / 2 = sin(theta) u and t = tr E = 1 + 2 cos(theta),
//
//   r = 4 s / (1 + t) = 2 tan(theta / 2) u     (the scaled Gibbs / Rodrigues vector, base frame).
//
// r is a rational function of the entries of R, smooth for theta < pi, equal to theta u to second
// order (so |r| is the rotation error in rad near a solution) and zero ONLY at theta = 0: unlike
// vee(skew E) = sin(theta) u, it has no spurious roots at theta = pi (there it has a pole, and
// |r| = 2 tan(theta / 2) increases monotonically with theta, so descent methods are not drawn
// towards a half-turn). A start exactly at a half-turn gives a non-finite F: Status::diverged.
// Derivatives (dE/dq_k = [a_k]x E, a_k the world axis of joint k, zero for a prismatic joint):
//   ds/dq_k = (t I - E) a_k / 2,  dt/dq_k = -2 s . a_k,
//   d2s/dq_j dq_k = (t_k I - E_k) a_j / 2,  d2t/dq_j dq_k = -2 a_j . s_k   (j <= k, E_k = [a_k]x E),
// and r's by the quotient rule. Tip position: dp/dq_k = a_k x (p - o_k) (revolute; a_k prismatic),
// d2p/dq_j dq_k = a_j x dp/dq_k for j <= k with joint j revolute, 0 when it is prismatic.
//
// The planar pose angle phi(q) = phi0 + sum over revolute joints of sigma_i q_i (sigma_i = +-1, the
// axis' z component; phi0 the tip angle at q = 0): exact for a planar chain (Chain::planar()), and
// linear, so the angle residual has a zero Hessian like ik::PlanarPose's.
//
// Joint limits: the chain's [lower, upper] (HasJointLimits: project clamps q, admit tests a solution,
// moving revolute joints by multiples of 2 pi into their limits when possible).
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "ik/problem.hpp"
#include "model/chain_kinematics.hpp"

namespace ks::ik {

/// What a chain IK problem asks of the tip (see the header comment).
enum class ChainTask { planar_position, planar_pose, spatial_position, spatial_pose };

/// Number of residuals of a task.
constexpr int chain_task_residuals(ChainTask t) {
  return t == ChainTask::planar_position ? 2 : t == ChainTask::spatial_pose ? 6 : 3;
}

/// Tip-position and axis data of one forward pass, fixed size: a_k (world axis, zero for a
/// prismatic joint in the angular part), the geometric Jacobian's columns.
template <int N>
struct ChainFrames {
  std::array<Eigen::Vector3d, N> axis;  ///< a_k, base frame (unit)
  Mat<3, N> Jp;                         ///< d tip position / dq [m/rad or 1]
  Mat<3, N> Jw;                         ///< angular Jacobian (a_k for revolute, 0 for prismatic)
  Eigen::Matrix3d R;                    ///< tip rotation, base frame
  Eigen::Vector3d p;                    ///< tip position, base frame [m]
};

/// A chain IK problem: N joints, task T. Points at a chain and a ChainData workspace owned by the
/// caller (both must outlive the problem); call bind() before solving.
template <int N, ChainTask T>
struct ChainProblem {
  static_assert(N >= 1 && N <= kMaxJoints, "chain IK: 1 .. kMaxJoints joints");
  static constexpr int unknowns = N;
  static constexpr int residuals = chain_task_residuals(T);
  static constexpr int M = residuals;

  const Chain* chain = nullptr;
  ChainData* data = nullptr;            ///< forward-kinematics workspace (written by evaluate)
  std::array<bool, N> revolute{};       ///< per joint, from the chain
  Vec<N> lower = Vec<N>::Zero(), upper = Vec<N>::Zero();  ///< joint limits [rad or m]
  Eigen::Vector3d position = Eigen::Vector3d::Zero();     ///< target tip position [m] (planar: x, y)
  double alpha = 0.0;                                     ///< planar_pose: target tip angle [rad]
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity(); ///< spatial_pose: target tip rotation R*
  std::array<double, N> sigma{};        ///< planar_pose: d phi / dq_i
  double phi0 = 0.0;                    ///< planar_pose: tip angle at q = 0 [rad]

  /// Point at `c` (dof() == N) and `d`; copy the joint types and limits; planar_pose: phi0, sigma.
  void bind(const Chain& c, ChainData& d) {
    chain = &c;
    data = &d;
    for (int i = 0; i < N; ++i) {
      const ChainJoint& j = c.joints[static_cast<std::size_t>(i)];
      revolute[i] = j.type == JointType::revolute;
      lower[i] = j.lower;
      upper[i] = j.upper;
    }
    if constexpr (T == ChainTask::planar_pose) {
      forward_kinematics(c, d, VecN::Zero(N));
      phi0 = std::atan2(d.tip.R(1, 0), d.tip.R(0, 0));
      for (int i = 0; i < N; ++i) sigma[i] = revolute[i] ? (d.axis[i].z() >= 0.0 ? 1.0 : -1.0) : 0.0;
    }
  }

  /// Forward kinematics at q into `f` (base frame).
  void frames(const Vec<N>& q, ChainFrames<N>& f) const {
    forward_kinematics(*chain, *data, VecN(q));
    f.R = data->tip.R;
    f.p = data->tip.p;
    for (int k = 0; k < N; ++k) {
      f.axis[k] = data->axis[k];
      if (revolute[k]) {
        f.Jp.col(k) = f.axis[k].cross(f.p - data->joint[k].p);
        f.Jw.col(k) = f.axis[k];
      } else {
        f.Jp.col(k) = f.axis[k];
        f.Jw.col(k).setZero();
      }
    }
  }

  /// F(q) and J = dF/dq (see the header comment for each task).
  void evaluate(const Vec<N>& q, Vec<M>& F, Mat<M, N>& J) const {
    ChainFrames<N> f;
    frames(q, f);
    if constexpr (T == ChainTask::planar_position || T == ChainTask::planar_pose) {
      F[0] = f.p.x() - position.x();
      F[1] = f.p.y() - position.y();
      J.template topRows<2>() = f.Jp.template topRows<2>();
      if constexpr (T == ChainTask::planar_pose) {
        double phi = phi0;
        for (int i = 0; i < N; ++i)
          if (revolute[i]) phi += sigma[i] * q[i];
        F[2] = wrap_angle(phi - alpha);
        for (int i = 0; i < N; ++i) J(2, i) = sigma[i];
      }
    } else if constexpr (T == ChainTask::spatial_position) {
      F = f.p - position;
      J = f.Jp;
    } else {
      F.template head<3>() = f.p - position;
      J.template topRows<3>() = f.Jp;
      const Eigen::Matrix3d E = f.R * rotation.transpose();
      const Eigen::Vector3d s(0.5 * (E(2, 1) - E(1, 2)), 0.5 * (E(0, 2) - E(2, 0)), 0.5 * (E(1, 0) - E(0, 1)));
      const double t = E.trace(), d = 1.0 + t;
      F.template tail<3>() = (4.0 / d) * s;
      Eigen::Matrix3d G = (2.0 / d) * (t * Eigen::Matrix3d::Identity() - E);
      G.noalias() += (8.0 / (d * d)) * s * s.transpose();
      J.template bottomRows<3>().noalias() = G * f.Jw;
    }
  }

  /// d2F_i/dq_j dq_k (symmetric N x N per residual), analytic (see the header comment).
  SecondDerivatives<M, N> second_derivatives(const Vec<N>& q) const {
    ChainFrames<N> f;
    frames(q, f);
    SecondDerivatives<M, N> D;
    for (auto& m : D) m.setZero();
    constexpr int P = T == ChainTask::planar_position || T == ChainTask::planar_pose ? 2 : 3;  // position rows
    for (int j = 0; j < N; ++j) {
      if (!revolute[j]) continue;  // a prismatic joint j turns nothing: its row (j <= k) is zero
      for (int k = j; k < N; ++k) {
        const Eigen::Vector3d h = f.axis[j].cross(f.Jp.col(k));
        for (int c = 0; c < P; ++c) D[c](j, k) = D[c](k, j) = h[c];
      }
    }
    if constexpr (T == ChainTask::spatial_pose) {
      const Eigen::Matrix3d E = f.R * rotation.transpose();
      const Eigen::Vector3d s(0.5 * (E(2, 1) - E(1, 2)), 0.5 * (E(0, 2) - E(2, 0)), 0.5 * (E(1, 0) - E(0, 1)));
      const double t = E.trace(), d = 1.0 + t;
      const double d1 = 1.0 / d, d2 = d1 * d1, d3 = d2 * d1;
      std::array<Eigen::Matrix3d, N> Ek;  // dE/dq_k = [a_k]x E (zero for prismatic joints)
      std::array<Eigen::Vector3d, N> sk;  // ds/dq_k
      std::array<double, N> tk;           // dt/dq_k
      for (int k = 0; k < N; ++k) {
        if (!revolute[k]) {
          Ek[k].setZero(), sk[k].setZero(), tk[k] = 0.0;
          continue;
        }
        const Eigen::Vector3d& a = f.axis[k];
        for (int c = 0; c < 3; ++c) Ek[k].col(c) = a.cross(E.col(c));
        sk[k] = 0.5 * (t * a - E * a);
        tk[k] = -2.0 * s.dot(a);
      }
      for (int j = 0; j < N; ++j) {
        if (!revolute[j]) continue;
        const Eigen::Vector3d& a = f.axis[j];
        for (int k = j; k < N; ++k) {
          if (!revolute[k]) continue;
          const Eigen::Vector3d sjk = 0.5 * (tk[k] * a - Ek[k] * a);
          const double tjk = -2.0 * a.dot(sk[k]);
          const Eigen::Vector3d h = 4.0 * d1 * sjk - 4.0 * d2 * (sk[k] * tk[j] + sk[j] * tk[k]) -
                                    4.0 * d2 * tjk * s + 8.0 * d3 * tk[j] * tk[k] * s;
          for (int c = 0; c < 3; ++c) D[3 + c](j, k) = D[3 + c](k, j) = h[c];
        }
      }
    }
    return D;
  }

  /// Clamp q onto [lower, upper] (infinite limits leave it free).
  void project(Vec<N>& q) const {
    for (int i = 0; i < N; ++i) q[i] = std::min(std::max(q[i], lower[i]), upper[i]);
  }

  /// True when q is within [lower, upper]; a revolute joint outside is first moved by the smallest
  /// multiple of 2 pi that brings it back across the limit it violates, when that also keeps it
  /// within the other one (q is changed only then).
  bool admit(Vec<N>& q) const {
    constexpr double kTwoPi = 6.28318530717958647692;
    bool ok = true;
    for (int i = 0; i < N; ++i) {
      if (q[i] >= lower[i] && q[i] <= upper[i]) continue;
      if (revolute[i] && std::isfinite(q[i])) {
        const double shifted = q[i] < lower[i] ? q[i] + kTwoPi * std::ceil((lower[i] - q[i]) / kTwoPi)
                                               : q[i] - kTwoPi * std::ceil((q[i] - upper[i]) / kTwoPi);
        if (shifted >= lower[i] && shifted <= upper[i]) {
          q[i] = shifted;
          continue;
        }
      }
      ok = false;
    }
    return ok;
  }
};

}  // namespace ks::ik
