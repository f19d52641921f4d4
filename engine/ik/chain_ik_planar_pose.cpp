// solve_chain for the planar pose task (tip x, y and angle about z), N = 2 .. kMaxJoints joints.
#include "ik/chain_ik_instances.hpp"

KS_CHAIN_IK_INSTANTIATE(ks::ik::ChainTask::planar_pose)
