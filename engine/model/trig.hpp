#pragma once
// Every trigonometric term the planar 3R model needs, from three sincos calls and angle sums.
// Templates over the lane type T (model/lanes.hpp: double, or N runs in SIMD lanes): one definition
// of the arithmetic for the single run and for the lanes.
#include <type_traits>

#include "model/sincos.hpp"

namespace ks {

/// Sines and cosines of the absolute link angles (1, 12, 123) and of the relative ones (2, 3, 23).
template <class T>
struct JointTrigOf {
  T s1, c1, s12, c12, s123, c123;  // absolute: theta1, theta1+theta2, theta1+theta2+theta3
  T s2, c2, s3, c3, s23, c23;      // relative: theta2, theta3, theta2+theta3
};
using JointTrig = JointTrigOf<double>;

/// The sums (12, 23, 123) from the sines and cosines of the three joint angles.
template <class T>
inline void complete_trig(JointTrigOf<T>& t) {
  t.s23 = t.s2 * t.c3 + t.c2 * t.s3;
  t.c23 = t.c2 * t.c3 - t.s2 * t.s3;
  t.s12 = t.s1 * t.c2 + t.c1 * t.s2;
  t.c12 = t.c1 * t.c2 - t.s1 * t.s2;
  t.s123 = t.s1 * t.c23 + t.c1 * t.s23;
  t.c123 = t.c1 * t.c23 - t.s1 * t.s23;
}

/// Input: joint angles [rad]. Output: all sines and cosines. Cost: three sincos and a few products,
/// so that the three calls can run in parallel (no dependency between them).
template <class Vec3>
inline JointTrig joint_trig(const Vec3& q) {
  JointTrig t;
  const double x[3] = {q[0], q[1], q[2]};
  double s[3], c[3];
  fast_sincos3(x, s, c);
  t.s1 = s[0], t.c1 = c[0], t.s2 = s[1], t.c2 = c[1], t.s3 = s[2], t.c3 = c[2];
  complete_trig(t);
  return t;
}
/// The same in lanes (fast_sincos per lane: the values of joint_trig for each lane's angles).
template <class T>
inline JointTrigOf<T> joint_trig(const LaneVec<T, 3>& q) {
  JointTrigOf<T> t;
  sincos_lanes(q[0], t.s1, t.c1);
  sincos_lanes(q[1], t.s2, t.c2);
  sincos_lanes(q[2], t.s3, t.c3);
  complete_trig(t);
  return t;
}

/// Joint trig carried along a time-stepping loop: after a step q += dq, the new sines and cosines
/// follow by rotating the old ones by dq (sin and cos of a small angle are short polynomials),
/// which takes the three sincos calls off the step's dependency chain. Every `resync` steps, or when
/// a step is not small (|dq_i| >= 0.01 rad, 10 rad/s at 1 ms), they are evaluated directly, so rounding cannot drift:
/// the values stay within ~1e-14 of joint_trig(q) (tested).
/// In lanes each lane keeps its own count and makes its own choice (rotated or direct values, selected
/// per lane), so that a lane's values are those of the same run tracked alone.
template <class T>
class TrigTrackerOf {
 public:
  static constexpr int resync = 64;
  template <class V>
  explicit TrigTrackerOf(const V& q) {
    reset(q);
  }
  template <class V>
  void reset(const V& q) {
    t_ = joint_trig(q);
    steps_ = 0;
  }
  /// After q has become q + dq.
  template <class V, class D>
  void advance(const V& q, const D& dq) {
    if constexpr (std::is_same_v<T, double>) {
      if (++steps_ >= resync || !(std::abs(dq[0]) < 0.01 && std::abs(dq[1]) < 0.01 && std::abs(dq[2]) < 0.01)) {
        reset(q);
        return;
      }
      rotate_all(dq);
    } else {
      steps_ += 1.0;
      const auto direct = (steps_ >= T(double(resync))) | !((vabs(dq[0]) < 0.01) & (vabs(dq[1]) < 0.01) & (vabs(dq[2]) < 0.01));
      if (!any(direct)) {
        rotate_all(dq);
        return;
      }
      const JointTrigOf<T> d = joint_trig(q);
      if (!all(direct)) {
        rotate_all(dq);
        blend(direct, d);
      } else {
        t_ = d;
      }
      steps_ = select(direct, T(0.0), steps_);
    }
  }
  const JointTrigOf<T>& trig() const { return t_; }

 private:
  template <class D>
  void rotate_all(const D& dq) {
    rotate(t_.s1, t_.c1, dq[0]);
    rotate(t_.s2, t_.c2, dq[1]);
    rotate(t_.s3, t_.c3, dq[2]);
    complete_trig(t_);
  }
  static void rotate(T& s, T& c, T d) {
    // Taylor series of sin to d^5 and cos to d^6: the next terms are below 2e-18 for |d| < 0.01.
    const T z = d * d, dz = d * z;
    const T sd = d + dz * (-1.0 / 6 + z * (1.0 / 120));
    const T cd = 1.0 + z * (-0.5 + z * (1.0 / 24 + z * (-1.0 / 720)));
    const T sn = s * cd + c * sd;
    c = c * cd - s * sd;
    s = sn;
  }
  void blend(MaskOf<T> m, const JointTrigOf<T>& d) {
    JointTrigOf<T>& t = t_;
    t.s1 = select(m, d.s1, t.s1), t.c1 = select(m, d.c1, t.c1), t.s12 = select(m, d.s12, t.s12);
    t.c12 = select(m, d.c12, t.c12), t.s123 = select(m, d.s123, t.s123), t.c123 = select(m, d.c123, t.c123);
    t.s2 = select(m, d.s2, t.s2), t.c2 = select(m, d.c2, t.c2), t.s3 = select(m, d.s3, t.s3);
    t.c3 = select(m, d.c3, t.c3), t.s23 = select(m, d.s23, t.s23), t.c23 = select(m, d.c23, t.c23);
  }
  JointTrigOf<T> t_;
  std::conditional_t<std::is_same_v<T, double>, int, T> steps_ = 0;  // lanes: a count per lane
};
using TrigTracker = TrigTrackerOf<double>;

}  // namespace ks
