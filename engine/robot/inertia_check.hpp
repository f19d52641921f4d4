#pragma once
// The mass-property checks every robot reader applies (robot/urdf.hpp, the study's DH tables): a
// link's inertia tensor must be one a rigid body can have, and the chain's joint-space inertia
// matrix must be invertible.
#include <Eigen/Core>
#include <string>

#include "model/chain.hpp"

namespace ks {

/// "" when the inertia `Ic` (about the centre of mass) is finite, its principal moments are >= 0 and
/// each is at most the sum of the other two (a rigid body's: I1 + I2 - I3 = 2 * integral of the
/// squared distance along the third principal axis >= 0), both within 1e-6 of the trace (rounded
/// printed digits); a zero inertia (a point mass) passes. Otherwise what is wrong, e.g. "the inertia's
/// principal moments (0.01, 0.01, 0.5 kg m^2) violate the triangle inequality (0.5 > 0.01 + 0.01);
/// expected each moment <= the sum of the other two (no rigid body has such an inertia)".
std::string inertia_problem(const Eigen::Matrix3d& Ic);

/// "" when the chain's joint-space inertia matrix M(q) is positive definite at q = 0 and at three fixed
/// configurations within the joint limits. Otherwise what is wrong, with `*joint` set to the joint
/// that moves neither mass nor inertia (-1 when the joints together move the same bodies the same way).
std::string inertia_matrix_problem(const Chain& chain, int* joint);

}  // namespace ks
