// joint_sample_partials (methods/path_global/joint_partials.hpp): one sample of the joints extension
// on derivative numbers of 4, 8 or 12 slots: the r coordinates' values (slot k) and rates (slot r + k),
// padded. The accelerations enter linearly and take no slot: dqdd/dzdd = dq/dz, dtau/dzdd = M dq/dz.
#include "methods/path_global/joint_partials.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "model/dual.hpp"

namespace ks {
namespace {

using V3 = Eigen::Vector3d;

template <int N>
struct V3D {
  Dual<N> e[3];
  V3D() = default;
  explicit V3D(const V3& v) {
    for (int a = 0; a < 3; ++a) e[a] = Dual<N>(v[a]);
  }
  Dual<N>& operator[](int a) { return e[a]; }
  const Dual<N>& operator[](int a) const { return e[a]; }
};

template <int N>
[[gnu::always_inline]] inline V3D<N> operator+(const V3D<N>& a, const V3D<N>& b) {
  V3D<N> r;
  for (int i = 0; i < 3; ++i) r[i] = a[i] + b[i];
  return r;
}
template <int N>
[[gnu::always_inline]] inline V3D<N> operator-(const V3D<N>& a, const V3D<N>& b) {
  V3D<N> r;
  for (int i = 0; i < 3; ++i) r[i] = a[i] - b[i];
  return r;
}
template <int N>
[[gnu::always_inline]] inline V3D<N>& operator+=(V3D<N>& a, const V3D<N>& b) {
  for (int i = 0; i < 3; ++i) a[i] += b[i];
  return a;
}
template <int N>
[[gnu::always_inline]] inline V3D<N> operator*(const Dual<N>& k, const V3D<N>& a) {
  V3D<N> r;
  for (int i = 0; i < 3; ++i) r[i] = k * a[i];
  return r;
}
template <int N>
[[gnu::always_inline]] inline V3D<N> cross(const V3D<N>& a, const V3D<N>& b) {
  V3D<N> r;
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
  return r;
}
template <int N>
[[gnu::always_inline]] inline Dual<N> dot(const V3D<N>& a, const V3D<N>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// A quantity of a body moved by the joints before it: value v; its derivative along coordinate
/// k's tangent (slot k) is w_k x v (+ u_k for a point), (w_k; u_k) the body's twist along it.
template <int N>
V3D<N> seeded(const V3& v, const V3* w, const V3* u, int r) {
  V3D<N> x(v);
  for (int k = 0; k < r; ++k) {
    const V3 d = u ? V3(w[k].cross(v) + u[k]) : V3(w[k].cross(v));
    for (int a = 0; a < 3; ++a) x[a].d[k] = d[a];
  }
  return x;
}

template <int N>
struct MotionD {
  V3D<N> w, v;
};
template <int N>
struct InertiaD {
  double m;
  V3D<N> h;
  Dual<N> J[3][3];  // about the base origin
};

template <int N>
[[gnu::always_inline]] inline MotionD<N> crm(const MotionD<N>& a, const MotionD<N>& b) {
  return {cross(a.w, b.w), cross(a.w, b.v) + cross(a.v, b.w)};
}
/// Momentum of inertia I moving with a: (m a.v + a.w x h; J a.w + h x a.v).
template <int N>
[[gnu::always_inline]] inline MotionD<N> mul(const InertiaD<N>& I, const MotionD<N>& a) {
  MotionD<N> f;  // (force; moment) stored as (w; v) = (f; n)
  for (int i = 0; i < 3; ++i) f.w[i] = I.m * a.v[i];
  f.w += cross(a.w, I.h);
  for (int i = 0; i < 3; ++i) f.v[i] = I.J[i][0] * a.w[0] + I.J[i][1] * a.w[1] + I.J[i][2] * a.w[2];
  f.v += cross(I.h, a.v);
  return f;
}
/// a x* f for f = (force; moment).
template <int N>
[[gnu::always_inline]] inline MotionD<N> crf(const MotionD<N>& a, const MotionD<N>& f) {
  return {cross(a.w, f.w), cross(a.w, f.v) + cross(a.v, f.w)};
}
/// S . f for motion S and f = (force; moment).
template <int N>
[[gnu::always_inline]] inline Dual<N> power(const MotionD<N>& S, const MotionD<N>& f) {
  return dot(S.w, f.v) + dot(S.v, f.w);
}

template <int N>
void partials(const JointSampleAt& at, GlobalObjective objective, double weight, ChainSamplePartials& out) {
  const Chain& chain = *at.chain;
  const ChainData& data = *at.data;
  const int n = chain.dof(), m = at.m, r = at.r, inputs = 3 * r;
  const MatN& M = *at.M;
  // the joint positions' tangent along each coordinate: dq_C = e_k, dq_S = -J_S^-1 J_C e_k
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, kMaxJoints> dqS = -at.lu->solve(*at.JC);
  double dq[kMaxJoints][kMaxJoints] = {};  // [joint][coordinate]
  for (int k = 0; k < r; ++k) {
    dq[at.coordinate[k]][k] = 1.0;
    for (int b = 0; b < m; ++b) dq[at.solved[b]][k] = dqS(b, k);
  }
  // each body's twist along each coordinate (base origin), accumulated from the base, and the
  // bodies' joint twists, inertias and the tip point on derivative numbers
  V3 tw[kMaxJoints], tv[kMaxJoints];
  for (int k = 0; k < r; ++k) tw[k].setZero(), tv[k].setZero();
  MotionD<N> S[kMaxJoints];
  InertiaD<N> I[kMaxJoints];
  for (int i = 0; i < n; ++i) {
    const ChainJoint& j = chain.joints[i];
    const Frame& F = data.joint[i];
    const V3& axis = data.axis[i];
    const bool revolute = j.type == JointType::revolute;
    for (int k = 0; k < r; ++k) {
      if (revolute) {
        tw[k] += axis * dq[i][k];
        tv[k] += F.p.cross(axis) * dq[i][k];
      } else {
        tv[k] += axis * dq[i][k];
      }
    }
    const V3D<N> a = seeded<N>(axis, tw, nullptr, r);
    if (revolute) {
      S[i].w = a;
      S[i].v = cross(seeded<N>(F.p, tw, tv, r), a);
    } else {
      S[i].w = V3D<N>(V3::Zero());
      S[i].v = a;
    }
    // inertia about the base origin: R I R^T + m (|c|^2 1 - c c^T), c the centre of mass
    const V3D<N> c = seeded<N>(F.p + F.R * j.com, tw, tv, r);
    const Eigen::Matrix3d X = F.R * j.inertia * F.R.transpose();
    InertiaD<N>& B = I[i];
    B.m = j.mass;
    for (int a2 = 0; a2 < 3; ++a2) B.h[a2] = j.mass * c[a2];
    const Dual<N> cc = dot(c, c);
    // d X = W X - X W, W = [w_k]x: (W X) + (W X)^T, column b of W X the cross product w_k x X_b
    double WX[kMaxJoints][3][3];  // [coordinate][column][row]
    for (int k = 0; k < r; ++k)
      for (int b = 0; b < 3; ++b) {
        const V3 col = tw[k].cross(V3(X.col(b)));
        for (int a2 = 0; a2 < 3; ++a2) WX[k][b][a2] = col[a2];
      }
    Dual<N> dX[3][3];  // X on derivative numbers: all written before any is read as a whole
    for (int a2 = 0; a2 < 3; ++a2)
      for (int b = 0; b < 3; ++b) {
        dX[a2][b] = Dual<N>(X(a2, b));
        for (int k = 0; k < r; ++k) dX[a2][b].d[k] = WX[k][b][a2] + WX[k][a2][b];
      }
    for (int a2 = 0; a2 < 3; ++a2)
      for (int b = 0; b < 3; ++b) {
        const Dual<N> cab = c[a2] * c[b];
        const Dual<N> e = a2 == b ? cc - cab : Dual<N>(0.0) - cab;
        B.J[a2][b] = dX[a2][b] + j.mass * e;
      }
  }
  const V3D<N> tip = seeded<N>(data.tip.p, tw, tv, r);  // moved by every joint
  // the position rows of the tip Jacobian, J_i = S_i.v + S_i.w x p
  V3D<N> J[kMaxJoints];
  for (int i = 0; i < n; ++i) J[i] = S[i].v + cross(S[i].w, tip);
  // a linear solve J_S x = b on derivative numbers: x's value given, dx = J_S^-1 (db - dJ_S x)
  auto solve = [&](const V3D<N>& b, const double* x_value, Dual<N>* x) {
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, N> rhs(m, N);
    for (int a = 0; a < m; ++a)
      for (int k = 0; k < N; ++k) {
        double v = b[a].d[k];
        for (int c2 = 0; c2 < m; ++c2) v -= J[at.solved[c2]][a].d[k] * x_value[c2];
        rhs(a, k) = v;
      }
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, N> dx = at.lu->solve(rhs);
    for (int a = 0; a < m; ++a) {
      x[a].v = x_value[a];
      for (int k = 0; k < N; ++k) x[a].d[k] = dx(a, k);
    }
  };
  // rates: qd_C = zd, J_S qd_S = xd - J_C zd
  Dual<N> qd[kMaxJoints];
  {
    V3D<N> b(V3::Zero());  // the derivative of xd - J_C zd (xd's is 0)
    for (int k = 0; k < r; ++k) {
      qd[at.coordinate[k]] = Dual<N>::input(at.z[k][1], r + k);
      for (int a = 0; a < m; ++a) b[a] -= J[at.coordinate[k]][a] * qd[at.coordinate[k]];
    }
    double value[3];
    for (int a = 0; a < m; ++a) value[a] = (*at.qd)[at.solved[a]];
    Dual<N> x[3];
    solve(b, value, x);
    for (int a = 0; a < m; ++a) qd[at.solved[a]] = x[a];
  }
  // the body velocities and their accelerations at zero joint accelerations, the base at rest
  const MotionD<N> zero{V3D<N>(V3::Zero()), V3D<N>(V3::Zero())};
  MotionD<N> vb[kMaxJoints], ab[kMaxJoints];
  {
    MotionD<N> v = zero, a = zero;
    for (int i = 0; i < n; ++i) {
      const MotionD<N> vJ{qd[i] * S[i].w, qd[i] * S[i].v};
      const MotionD<N> x = crm(v, vJ);
      a.w += x.w, a.v += x.v;
      v.w += vJ.w, v.v += vJ.v;
      vb[i] = v, ab[i] = a;
    }
  }
  // the tip's bias acceleration (position rows): a.v + a.w x p + v.w x (v.v + v.w x p)
  const MotionD<N>& vt = vb[n - 1];
  const V3D<N> bias = ab[n - 1].v + cross(ab[n - 1].w, tip) + cross(vt.w, vt.v + cross(vt.w, tip));
  // accelerations: qdd_C = zdd, J_S qdd_S = xdd - J_C zdd - bias
  Dual<N> qdd[kMaxJoints];
  {
    V3D<N> b(V3::Zero());
    for (int k = 0; k < r; ++k) {
      qdd[at.coordinate[k]] = Dual<N>(at.z[k][2]);
      for (int a = 0; a < m; ++a) b[a] -= J[at.coordinate[k]][a] * qdd[at.coordinate[k]];
    }
    for (int a = 0; a < m; ++a) b[a] -= bias[a];
    double value[3];
    for (int a = 0; a < m; ++a) value[a] = (*at.qdd)[at.solved[a]];
    Dual<N> x[3];
    solve(b, value, x);
    for (int a = 0; a < m; ++a) qdd[at.solved[a]] = x[a];
  }
  // inverse dynamics: body i accelerates at -gravity + ab_i + sum_{j <= i} S_j qdd_j; its force
  // I a + v x* I v, summed inward and projected on the joint twists
  Dual<N> tau[kMaxJoints];
  {
    MotionD<N> lifted{V3D<N>(V3::Zero()), V3D<N>(V3(-chain.gravity))}, f[kMaxJoints];
    for (int i = 0; i < n; ++i) {
      lifted.w += qdd[i] * S[i].w, lifted.v += qdd[i] * S[i].v;
      const MotionD<N> a{lifted.w + ab[i].w, lifted.v + ab[i].v};
      f[i] = mul(I[i], a);
      const MotionD<N> g = crf(vb[i], mul(I[i], vb[i]));
      f[i].w += g.w, f[i].v += g.v;
    }
    for (int i = n - 1; i >= 0; --i) {
      if (i + 1 < n) f[i].w += f[i + 1].w, f[i].v += f[i + 1].v;
      tau[i] = power(S[i], f[i]);
      tau[i].v = (*at.tau)[i];  // the sample's own value (equal to rounding)
    }
  }
  // the torques' partials in the coordinates' accelerations: M dq/dz
  double tau_acc[kMaxJoints][kMaxJoints];  // [joint][coordinate]
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < r; ++k) {
      double t = 0.0;
      for (int j = 0; j < n; ++j) t += M(i, j) * dq[j][k];
      tau_acc[i][k] = t;
    }
  // the objective's term: slots (values, rates) and the accelerations' partials
  double dcost[N] = {}, dcost_acc[kMaxJoints] = {};
  switch (objective) {
    case GlobalObjective::E:
    case GlobalObjective::torque_sq_integral: {
      Dual<N> sq(0.0);
      for (int i = 0; i < n; ++i) sq += tau[i] * tau[i];
      const bool norm = objective == GlobalObjective::E;
      const Dual<N> term = norm ? sqrt_of(sq) : sq;
      for (int k = 0; k < N; ++k) dcost[k] = weight * term.d[k];
      // d|tau| = tau . dtau / |tau|, d(tau^T tau) = 2 tau . dtau
      const double scale = norm ? (sq.v > 0.0 ? weight / std::sqrt(sq.v) : 0.0) : 2.0 * weight;
      for (int k = 0; k < r; ++k) {
        double d = 0.0;
        for (int i = 0; i < n; ++i) d += tau[i].v * tau_acc[i][k];
        dcost_acc[k] = scale * d;
      }
      break;
    }
    case GlobalObjective::E_M: {  // d(tau^T M^-1 tau) = 2 y . dtau - y^T dM y, y = M^-1 tau
      const VecN y = M.ldlt().solve(*at.tau);
      const double qf = at.tau->dot(y);
      const double scale = qf > 0.0 ? weight * 0.5 / std::sqrt(qf) : 0.0;
      // y^T M y = sum_i V_i . I_i V_i, V_i = sum_{j <= i} S_j y_j: its derivatives hold y
      Dual<N> yMy(0.0);
      MotionD<N> V = zero;
      for (int i = 0; i < n; ++i) {
        V.w += Dual<N>(y[i]) * S[i].w, V.v += Dual<N>(y[i]) * S[i].v;
        yMy += power(V, mul(I[i], V));
      }
      for (int k = 0; k < N; ++k) {
        double d = -yMy.d[k];
        for (int i = 0; i < n; ++i) d += 2.0 * y[i] * tau[i].d[k];
        dcost[k] = scale * d;
      }
      for (int k = 0; k < r; ++k) {  // M^-1 tau . M dq/dz = tau . dq/dz
        double d = 0.0;
        for (int i = 0; i < n; ++i) d += 2.0 * (*at.tau)[i] * dq[i][k];
        dcost_acc[k] = scale * d;
      }
      break;
    }
    case GlobalObjective::kinetic_energy: {  // qd^T M qd = sum_i v_i . I_i v_i (no acceleration in it)
      Dual<N> ke(0.0);
      for (int i = 0; i < n; ++i) ke += power(vb[i], mul(I[i], vb[i]));
      for (int k = 0; k < N; ++k) dcost[k] = weight * 0.5 * ke.d[k];
      break;
    }
  }
  out.inputs = inputs;
  for (int k = 0; k < r; ++k) {
    out.cost[3 * k] = dcost[k];
    out.cost[3 * k + 1] = dcost[r + k];
    out.cost[3 * k + 2] = dcost_acc[k];
    for (int i = 0; i < n; ++i) {
      out.q[i][3 * k] = dq[i][k], out.q[i][3 * k + 1] = out.q[i][3 * k + 2] = 0.0;
      out.qd[i][3 * k] = qd[i].d[k], out.qd[i][3 * k + 1] = qd[i].d[r + k], out.qd[i][3 * k + 2] = 0.0;
      out.tau[i][3 * k] = tau[i].d[k], out.tau[i][3 * k + 1] = tau[i].d[r + k], out.tau[i][3 * k + 2] = tau_acc[i][k];
    }
  }
}

}  // namespace

void joint_sample_partials(const JointSampleAt& at, GlobalObjective objective, double weight, ChainSamplePartials& out) {
  const int slots = 2 * at.r;
  if (slots <= 4)
    partials<4>(at, objective, weight, out);
  else if (slots <= 8)
    partials<8>(at, objective, weight, out);
  else
    partials<12>(at, objective, weight, out);
}

}  // namespace ks
