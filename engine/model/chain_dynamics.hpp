#pragma once
// Rigid-body dynamics of a serial chain (model/chain.hpp): tau = M(q) q̈ + c(q, q̇) + g(q), by the
// recursive Newton-Euler algorithm (RNEA) and the composite-rigid-body algorithm (CRBA), on
// fixed-maximum-size types (no allocation). Units: rad or m, /s, /s^2; torques [Nm] or forces [N].
#include "model/chain_kinematics.hpp"

namespace ks {

/// Inverse dynamics with gravity (chain.gravity). \param[in] q, qd, qdd (dim chain.dof()).
/// \param[out] tau (dim chain.dof()).
void rnea(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd, const VecN& qdd, VecN& tau);

/// Joint-space inertia matrix. \param[in] q (dim n). \param[out] M (n x n), symmetric positive (semi)definite.
void crba(const Chain& chain, ChainData& data, const VecN& q, MatN& M);

/// Gravity torques g(q) (the RNEA at rest). \param[out] g (dim n).
void gravity_torques(const Chain& chain, ChainData& data, const VecN& q, VecN& g);

/// Centrifugal and Coriolis torques c(q, q̇) (the RNEA with q̈ = 0, without gravity). \param[out] c (dim n).
void coriolis_torques(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd, VecN& c);

/// Everything one step of a trajectory needs at (q, q̇), from one forward pass.
struct ChainState {
  MatN M;       ///< inertia matrix (n x n)
  VecN c, g;    ///< Coriolis/centrifugal and gravity torques (n)
  Mat6N J;      ///< tip geometric Jacobian, base frame (6 x n)
  Vec6 bias;    ///< J̇ q̇ (linear, angular)
  Frame tip;    ///< tip frame, base frame
};

/// Fill `state` at (q, q̇). Equal (to rounding) to crba, coriolis_torques, gravity_torques,
/// tip_jacobian and tip_bias_acceleration called one by one; faster. Chains with
/// Chain::planar_fast_path take the 2-D specialisation, which leaves data's frames as they were (the
/// other functions here write those of q): call forward_kinematics when they are needed.
/// frames_at_q: data already holds forward_kinematics(chain, data, q), which spatial chains then
/// do not compute again (the same frames, the same results).
void evaluate_dynamics(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd, ChainState& state,
                       bool frames_at_q = false);

}  // namespace ks
