// RNEA, CRBA, gravity and Coriolis torques and the one-pass evaluate_dynamics of a serial chain.
// Each algorithm is written once, templated on a vector algebra: 3-D spatial vectors for any chain
// (Spatial), or their 2-D reduction (Planar: scalar angular parts, xy linear parts) for chains with
// Chain::planar_fast_path. Both work in the base frame at the base origin, so composite inertias
// are plain sums and the joint twists are the columns of the base-origin Jacobian.
#include "model/chain_dynamics.hpp"

#include <type_traits>

#include "model/chain_spatial.hpp"

namespace ks {

namespace {

using detail::M3;
using detail::V3;

// 3-D spatial algebra. Motion (w; v): angular velocity and velocity of the body point at the base
// origin. Force (f; n): force and moment about the base origin. Inertia: mass m, first moment
// h = m c (c the centre of mass), rotational inertia J about the base origin.
struct Spatial {
  struct Motion {
    V3 w, v;
    Motion& operator+=(const Motion& b) {
      w += b.w;
      v += b.v;
      return *this;
    }
    Motion operator*(double k) const { return {w * k, v * k}; }
  };
  struct Force {
    V3 f, n;
    Force& operator+=(const Force& b) {
      f += b.f;
      n += b.n;
      return *this;
    }
  };
  struct Inertia {
    double m;
    V3 h;
    M3 J;
    Inertia& operator+=(const Inertia& b) {
      m += b.m;
      h += b.h;
      J += b.J;
      return *this;
    }
  };
  struct Bodies {
    Motion S[kMaxJoints];   // joint unit twists
    Inertia I[kMaxJoints];  // body inertias
  };

  static Motion zero_motion() { return {V3::Zero(), V3::Zero()}; }
  static Inertia zero_inertia() { return {0.0, V3::Zero(), M3::Zero()}; }
  /// Momentum (linear; angular about the origin) of inertia I moving with a.
  static Force mul(const Inertia& I, const Motion& a) { return {I.m * a.v + a.w.cross(I.h), I.J * a.w + I.h.cross(a.v)}; }
  static Motion crm(const Motion& a, const Motion& b) { return {a.w.cross(b.w), a.w.cross(b.v) + a.v.cross(b.w)}; }
  static Force crf(const Motion& a, const Force& b) { return {a.w.cross(b.f), a.w.cross(b.n) + a.v.cross(b.f)}; }
  static double dot(const Motion& a, const Force& b) { return a.w.dot(b.n) + a.v.dot(b.f); }
  /// The base acceleration -gravity that stands for gravity in the recursion.
  static Motion lift(const Chain& chain) { return {V3::Zero(), -chain.gravity}; }

  /// Forward kinematics into data (unless `kinematics` is false: data holds q's frames), the joint
  /// twists and (when `inertias`) the body inertias.
  static void bodies(const Chain& chain, ChainData& data, const VecN& q, Bodies& B, bool inertias, bool kinematics = true) {
    if (kinematics) forward_kinematics(chain, data, q);
    for (int i = 0; i < chain.dof(); ++i) {
      const ChainJoint& j = chain.joints[i];
      const Frame& F = data.joint[i];
      detail::joint_twist(j.type, data.axis[i], F.p, B.S[i].w, B.S[i].v);
      if (!inertias) continue;
      const V3 c = F.p + F.R * j.com;
      Inertia& I = B.I[i];
      I.m = j.mass;
      I.h = j.mass * c;
      I.J = F.R * j.inertia * F.R.transpose();
      I.J.diagonal().array() += j.mass * c.squaredNorm();
      I.J -= (j.mass * c) * c.transpose();
    }
  }

  /// Tip Jacobian (columns: the twists moved to the tip point), tip classical acceleration from the
  /// last body's velocity v and bias acceleration a, and the tip frame.
  static void tip_outputs(const Chain& chain, const ChainData& data, const Bodies& B, const Motion& v, const Motion& a,
                          Mat6N& J, Vec6& bias, Frame& tip) {
    const V3& p = data.tip.p;
    J.resize(6, chain.dof());
    for (int i = 0; i < chain.dof(); ++i) {
      J.col(i).head<3>() = B.S[i].v + B.S[i].w.cross(p);
      J.col(i).tail<3>() = B.S[i].w;
    }
    const V3 vp = v.v + v.w.cross(p);
    bias.head<3>() = a.v + a.w.cross(p) + v.w.cross(vp);
    bias.tail<3>() = a.w;
    tip = data.tip;
  }
};

// The planar reduction: every joint turns about z or slides in the xy plane, so angular parts are
// z components (scalars), linear parts xy vectors, and the inertia about z is all that acts.
struct Planar {
  struct Motion {
    double w, vx, vy;
    Motion& operator+=(const Motion& b) {
      w += b.w;
      vx += b.vx;
      vy += b.vy;
      return *this;
    }
    Motion operator*(double k) const { return {w * k, vx * k, vy * k}; }
  };
  struct Force {
    double fx, fy, n;
    Force& operator+=(const Force& b) {
      fx += b.fx;
      fy += b.fy;
      n += b.n;
      return *this;
    }
  };
  struct Inertia {
    double m, hx, hy, J;
    Inertia& operator+=(const Inertia& b) {
      m += b.m;
      hx += b.hx;
      hy += b.hy;
      J += b.J;
      return *this;
    }
  };
  struct Bodies {
    Motion S[kMaxJoints];
    Inertia I[kMaxJoints];
    detail::PlanarPose P;
  };

  static Motion zero_motion() { return {0.0, 0.0, 0.0}; }
  static Inertia zero_inertia() { return {0.0, 0.0, 0.0, 0.0}; }
  static Force mul(const Inertia& I, const Motion& a) {
    return {I.m * a.vx - a.w * I.hy, I.m * a.vy + a.w * I.hx, I.J * a.w + (I.hx * a.vy - I.hy * a.vx)};
  }
  static Motion crm(const Motion& a, const Motion& b) {
    return {0.0, b.w * a.vy - a.w * b.vy, a.w * b.vx - b.w * a.vx};
  }
  static Force crf(const Motion& a, const Force& b) { return {-a.w * b.fy, a.w * b.fx, a.vx * b.fy - a.vy * b.fx}; }
  static double dot(const Motion& a, const Force& b) { return a.w * b.n + a.vx * b.fx + a.vy * b.fy; }
  static Motion lift(const Chain& chain) { return {0.0, -chain.gravity.x(), -chain.gravity.y()}; }

  /// As Spatial::bodies, but data's frames are written only when `store_frames`.
  static void bodies(const Chain& chain, ChainData& data, const VecN& q, Bodies& B, bool inertias, bool store_frames = true) {
    detail::PlanarPose& P = B.P;
    detail::planar_pose(chain, q, P);
    if (store_frames) detail::store_planar_pose(chain, P, data);
    for (int i = 0; i < chain.dof(); ++i) {
      const ChainJoint& j = chain.joints[i];
      const double c = P.c[i], s = P.s[i], x = P.x[i], y = P.y[i];
      if (j.type == JointType::revolute) {
        const double sigma = j.axis.z();
        B.S[i] = {sigma, sigma * y, -sigma * x};
      } else {
        B.S[i] = {0.0, c * j.axis.x() - s * j.axis.y(), s * j.axis.x() + c * j.axis.y()};
      }
      if (!inertias) continue;
      const double cx = x + c * j.com.x() - s * j.com.y(), cy = y + s * j.com.x() + c * j.com.y();
      B.I[i] = {j.mass, j.mass * cx, j.mass * cy, j.inertia(2, 2) + j.mass * (cx * cx + cy * cy)};
    }
  }

  static void tip_outputs(const Chain& chain, const ChainData&, const Bodies& B, const Motion& v, const Motion& a,
                          Mat6N& J, Vec6& bias, Frame& tip) {
    const double px = B.P.tx, py = B.P.ty;
    J.resize(6, chain.dof());
    for (int i = 0; i < chain.dof(); ++i) {
      const Motion& S = B.S[i];
      J.col(i) << S.vx - S.w * py, S.vy + S.w * px, 0.0, 0.0, 0.0, S.w;
    }
    const double vpx = v.vx - v.w * py, vpy = v.vy + v.w * px;
    bias << a.vx - a.w * py - v.w * vpy, a.vy + a.w * px + v.w * vpx, 0.0, 0.0, 0.0, a.w;
    detail::planar_frame(B.P.tc, B.P.ts, B.P.tx, B.P.ty, tip);
  }
};

// Inverse dynamics: velocities and accelerations outward from the base (accelerating at `a0`),
// body forces I a + v x* I v, then the forces summed inward and projected on the joint twists.
template <class A>
void rnea_impl(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd, const VecN* qdd,
               const typename A::Motion& a0, VecN& tau) {
  typename A::Bodies B;
  A::bodies(chain, data, q, B, true);
  const int n = chain.dof();
  typename A::Motion v = A::zero_motion(), a = a0;
  typename A::Force f[kMaxJoints];
  for (int i = 0; i < n; ++i) {
    const typename A::Motion vJ = B.S[i] * qd[i];
    a += A::crm(v, vJ);
    if (qdd) a += B.S[i] * (*qdd)[i];
    v += vJ;
    f[i] = A::mul(B.I[i], a);
    f[i] += A::crf(v, A::mul(B.I[i], v));
  }
  tau.resize(n);
  for (int i = n - 1; i >= 0; --i) {
    if (i + 1 < n) f[i] += f[i + 1];
    tau[i] = A::dot(B.S[i], f[i]);
  }
}

// Composite inertias Ic_j (bodies j..n-1, summed inward); M_ij = S_i . (Ic_j S_j) for i <= j.
template <class A>
void crba_impl(const Chain& chain, ChainData& data, const VecN& q, MatN& M) {
  typename A::Bodies B;
  A::bodies(chain, data, q, B, true);
  const int n = chain.dof();
  M.resize(n, n);
  typename A::Inertia Ic = A::zero_inertia();
  for (int j = n - 1; j >= 0; --j) {
    Ic += B.I[j];
    const typename A::Force F = A::mul(Ic, B.S[j]);
    for (int i = 0; i <= j; ++i) M(i, j) = M(j, i) = A::dot(B.S[i], F);
  }
}

// g_i = S_i . (Ic_i lift): the force that holds the composite of bodies i..n-1 against gravity.
template <class A>
void gravity_impl(const Chain& chain, ChainData& data, const VecN& q, VecN& g) {
  typename A::Bodies B;
  A::bodies(chain, data, q, B, true);
  const int n = chain.dof();
  const typename A::Motion lift = A::lift(chain);
  g.resize(n);
  typename A::Inertia Ic = A::zero_inertia();
  for (int i = n - 1; i >= 0; --i) {
    Ic += B.I[i];
    g[i] = A::dot(B.S[i], A::mul(Ic, lift));
  }
}

// One forward pass (velocities, bias accelerations, body forces), one inward pass (composite
// inertias for M and g, summed forces for c), then the tip quantities.
template <class A>
void evaluate_impl(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd, ChainState& st, bool frames_at_q) {
  typename A::Bodies B;
  if constexpr (std::is_same_v<A, Spatial>)
    A::bodies(chain, data, q, B, true, !frames_at_q);
  else
    A::bodies(chain, data, q, B, true, false);  // (the planar pose from q; data's frames left as they are)
  const int n = chain.dof();
  typename A::Motion v = A::zero_motion(), a = A::zero_motion();
  typename A::Force f[kMaxJoints];
  for (int i = 0; i < n; ++i) {
    const typename A::Motion vJ = B.S[i] * qd[i];
    a += A::crm(v, vJ);
    v += vJ;
    f[i] = A::mul(B.I[i], a);
    f[i] += A::crf(v, A::mul(B.I[i], v));
  }
  const typename A::Motion lift = A::lift(chain);
  st.M.resize(n, n);
  st.c.resize(n);
  st.g.resize(n);
  typename A::Inertia Ic = A::zero_inertia();
  for (int j = n - 1; j >= 0; --j) {
    if (j + 1 < n) f[j] += f[j + 1];
    Ic += B.I[j];
    st.c[j] = A::dot(B.S[j], f[j]);
    st.g[j] = A::dot(B.S[j], A::mul(Ic, lift));
    const typename A::Force F = A::mul(Ic, B.S[j]);
    for (int i = 0; i <= j; ++i) st.M(i, j) = st.M(j, i) = A::dot(B.S[i], F);
  }
  A::tip_outputs(chain, data, B, v, a, st.J, st.bias, st.tip);
}

}  // namespace

void rnea(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd, const VecN& qdd, VecN& tau) {
  if (chain.planar_fast_path)
    rnea_impl<Planar>(chain, data, q, qd, &qdd, Planar::lift(chain), tau);
  else
    rnea_impl<Spatial>(chain, data, q, qd, &qdd, Spatial::lift(chain), tau);
}

void crba(const Chain& chain, ChainData& data, const VecN& q, MatN& M) {
  if (chain.planar_fast_path)
    crba_impl<Planar>(chain, data, q, M);
  else
    crba_impl<Spatial>(chain, data, q, M);
}

void gravity_torques(const Chain& chain, ChainData& data, const VecN& q, VecN& g) {
  if (chain.planar_fast_path)
    gravity_impl<Planar>(chain, data, q, g);
  else
    gravity_impl<Spatial>(chain, data, q, g);
}

void coriolis_torques(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd, VecN& c) {
  if (chain.planar_fast_path)
    rnea_impl<Planar>(chain, data, q, qd, nullptr, Planar::zero_motion(), c);
  else
    rnea_impl<Spatial>(chain, data, q, qd, nullptr, Spatial::zero_motion(), c);
}

void evaluate_dynamics(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd, ChainState& state,
                       bool frames_at_q) {
  if (chain.planar_fast_path)
    evaluate_impl<Planar>(chain, data, q, qd, state, frames_at_q);
  else
    evaluate_impl<Spatial>(chain, data, q, qd, state, frames_at_q);
}

}  // namespace ks
