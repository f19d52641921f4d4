// solve_chain for the spatial pose task (tip position and rotation), N = 2 .. kMaxJoints joints.
#include "ik/chain_ik_instances.hpp"

KS_CHAIN_IK_INSTANTIATE(ks::ik::ChainTask::spatial_pose)
