#pragma once
// Every trigonometric term the planar 3R model needs, from three sincos calls and angle sums.
#include "model/sincos.hpp"

namespace ks {

/// Sines and cosines of the absolute link angles (1, 12, 123) and of the relative ones (2, 3, 23).
struct JointTrig {
  double s1, c1, s12, c12, s123, c123;  // absolute: theta1, theta1+theta2, theta1+theta2+theta3
  double s2, c2, s3, c3, s23, c23;      // relative: theta2, theta3, theta2+theta3
};

/// Input: joint angles [rad]. Output: all sines and cosines. Cost: three sincos and a few products,
/// so that the three calls can run in parallel (no dependency between them).
template <class Vec3>
inline JointTrig joint_trig(const Vec3& q) {
  JointTrig t;
  const double x[3] = {q[0], q[1], q[2]};
  double s[3], c[3];
  fast_sincos3(x, s, c);
  t.s1 = s[0], t.c1 = c[0], t.s2 = s[1], t.c2 = c[1], t.s3 = s[2], t.c3 = c[2];
  t.s23 = t.s2 * t.c3 + t.c2 * t.s3;
  t.c23 = t.c2 * t.c3 - t.s2 * t.s3;
  t.s12 = t.s1 * t.c2 + t.c1 * t.s2;
  t.c12 = t.c1 * t.c2 - t.s1 * t.s2;
  t.s123 = t.s1 * t.c23 + t.c1 * t.s23;
  t.c123 = t.c1 * t.c23 - t.s1 * t.s23;
  return t;
}

}  // namespace ks
