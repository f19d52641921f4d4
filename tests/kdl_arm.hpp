#pragma once
// Orocos KDL model of the planar 3R arm: the independent oracle of the tests (never used by the engine).
#include <kdl/chain.hpp>

#include "model/arm.hpp"

namespace ks::test {

/// Chain of three RotZ joints with segments of length l_i along x. KDL expresses a segment's
/// inertia in its tip frame, so link i's centre of mass sits at (lc_i - l_i, 0, 0).
inline KDL::Chain kdl_chain(const PlanarArm3& a) {
  KDL::Chain chain;
  for (int i = 0; i < 3; ++i) {
    const KDL::RigidBodyInertia inertia(a.m[i], KDL::Vector(a.lc[i] - a.l[i], 0, 0),
                                        KDL::RotationalInertia(0, 0, a.I[i], 0, 0, 0));
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ), KDL::Frame(KDL::Vector(a.l[i], 0, 0)), inertia));
  }
  return chain;
}

}  // namespace ks::test
