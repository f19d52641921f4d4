// solve_chain for the planar tasks (tip x, y; x, y and angle), N = 2 .. kMaxJoints joints.
#include "ik/chain_ik_instances.hpp"

KS_CHAIN_IK_INSTANTIATE(ks::ik::ChainTask::planar_position)
KS_CHAIN_IK_INSTANTIATE(ks::ik::ChainTask::planar_pose)
