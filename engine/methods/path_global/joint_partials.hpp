#pragma once
// Exact partial derivatives of one sample of the joints extension (methods/path_global/joint_chart.hpp)
// with respect to its coordinates: the value, rate and acceleration of each of the r coordinates.
// Forward-mode derivative numbers (model/dual.hpp) carry them through the chain's kinematics and
// dynamics from seeds that need no differencing:
// - the joint positions move along the tangent of the solved task, dq_S/dz = -J_S^-1 J_C (the
//   implicit-function derivative of the converged Newton solve), dq_C/dz = I;
// - every frame's derivative along such a motion is the sum of the joint twists before it, so the
//   joint axes, origins, centres of mass, rotated inertias and the tip point are seeded from the
//   frames forward_kinematics computed, with no trigonometry on derivative numbers;
// - the rates and accelerations of the solved joints solve the differentiated task, J_S x = b, whose
//   derivatives are J_S^-1 (db - dJ_S x) (solved with the sample's LU of J_S, never inverted);
// - the tip's bias acceleration comes from a forward pass of the body velocities, the torques from the
//   recursive Newton-Euler algorithm on derivative numbers (the values' and rates' partials); the
//   accelerations enter linearly: dqdd/dzdd = dq/dz and dtau/dzdd = M dq/dz, in closed form.
#include <Eigen/LU>

#include "methods/path_global/chain.hpp"

namespace ks {

/// What one sample's partials are computed from: the sample as JointExtensionProblem::sample left it.
struct JointSampleAt {
  const Chain* chain = nullptr;
  const ChainData* data = nullptr;  ///< the frames at q (forward_kinematics at the solved configuration)
  const int* solved = nullptr;      ///< the m solved joints
  const int* coordinate = nullptr;  ///< the r coordinate joints
  int m = 0, r = 0;
  const Eigen::PartialPivLU<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>>* lu = nullptr;  ///< of J_S
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, kMaxJoints>* JC = nullptr;  ///< J_C (m x r)
  const VecN* q = nullptr;    ///< [rad]
  const VecN* qd = nullptr;   ///< [rad/s]
  const VecN* qdd = nullptr;  ///< [rad/s^2]
  const VecN* tau = nullptr;  ///< [Nm]
  const MatN* M = nullptr;    ///< the inertia matrix at q
  const double (*z)[3] = nullptr;  ///< the coordinates: value, rate, acceleration
};

/// The partials of the sample `at` (a converged one: violation 0) into out, for the objective's term
/// weight * f(sample) with f: |tau| (E), sqrt(tau^T M^-1 tau) (E_M), tau^T tau (torque_sq_integral)
/// or qd^T M qd / 2 (kinetic_energy). \param[in] weight the term's factor (1 / samples, or the
/// trapezoid's step) [s or 1].
void joint_sample_partials(const JointSampleAt& at, GlobalObjective objective, double weight, ChainSamplePartials& out);

}  // namespace ks
