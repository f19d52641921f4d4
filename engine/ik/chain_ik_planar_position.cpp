// solve_chain for the planar position task (tip x, y), N = 2 .. kMaxJoints joints.
#include "ik/chain_ik_instances.hpp"

KS_CHAIN_IK_INSTANTIATE(ks::ik::ChainTask::planar_position)
