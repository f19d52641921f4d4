#pragma once
// Kinematics of a serial chain (model/chain.hpp): forward kinematics, the tip's geometric Jacobian
// and its bias acceleration J̇ q̇. Free functions over (chain constants, workspace); no allocation.
#include <array>

#include "model/chain.hpp"

namespace ks {

/// Per-call workspace of the chain algorithms (kinematics and dynamics): fixed size, reusable.
struct ChainData {
  std::array<Frame, kMaxJoints> joint;  ///< joint i's frame in the base frame (after q_i's motion)
  std::array<Eigen::Vector3d, kMaxJoints> axis;  ///< joint i's axis in the base frame
  Frame tip;                            ///< the tip frame in the base frame
};

/// Forward kinematics. \param[in] q joint positions (dim chain.dof()) [rad or m].
/// \param[out] data joint frames, axes and the tip frame, base frame.
void forward_kinematics(const Chain& chain, ChainData& data, const VecN& q);

/// The tip's geometric Jacobian in the base frame, at the tip frame's origin: rows 0-2 map q̇ to the
/// tip's linear velocity [m/s], rows 3-5 to its angular velocity [rad/s]. Reads the frames of the
/// last forward_kinematics(chain, data, q). \param[out] J (6 x chain.dof()).
void tip_jacobian(const Chain& chain, const ChainData& data, Mat6N& J);

/// The tip's acceleration when q̈ = 0, i.e. J̇(q, q̇) q̇: linear [m/s^2] (the tip origin's classical
/// acceleration), then angular [rad/s^2]. Runs forward_kinematics(chain, data, q) itself.
Vec6 tip_bias_acceleration(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd);

}  // namespace ks
