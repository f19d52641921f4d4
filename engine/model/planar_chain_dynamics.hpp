#pragma once
// Dynamics and tip kinematics of a planar chain of N revolute joints (N a compile-time constant), in
// one pass over fixed-size arrays: the inner loop of a trajectory run (methods/chain/planar_run.hpp).
// Vectors in the base frame; composite inertias about the base origin for M and g (as in
// model/chain_dynamics.cpp's planar algebra), and c and the tip's J̇ u̇ from the bodies' accelerations
// at zero joint accelerations, one outward and one inward pass; the chain's constants read once per run into PlanarChainConstants and the frames carried as the cosine and sine of each
// joint frame's absolute angle (PlanarChainTrig) instead of rotation matrices.
//
// Joint coordinates: everything here is written in u_i = sigma_i q_i, with sigma_i = +1 or -1 the
// direction of joint i's axis along z, i.e. as if every axis were +z. With D = diag(sigma) (D = D^-1),
// the chain's own quantities are q = D u, tau = D tau_u, M = D M_u D, J = J_u D: the run maps its
// inputs and outputs exactly (a multiplication by +-1), and every redundancy resolution of
// methods/chain/resolution.hpp gives the same joint motion in either coordinates.
#include <cmath>

#include "model/chain.hpp"
#include "model/sincos.hpp"

namespace ks {

/// True when the fixed-size planar kernel applies to `chain`: chain.planar() and every joint
/// revolute. (Planar chains with prismatic joints take the general algorithms.) The kernel takes each
/// axis as exactly +z or -z (Chain::planar allows 1e-12 off).
inline bool planar_revolute(const Chain& chain) {
  if (!chain.planar()) return false;
  for (const ChainJoint& j : chain.joints)
    if (j.type != JointType::revolute) return false;
  return true;
}

/// The constants of a planar revolute chain of N joints, in joint frames (see model/chain.hpp).
/// Joint i's frame has the absolute angle phi_i = sum_{j <= i} (beta_j + u_j) about z, u_j = sigma_j q_j.
template <int N>
struct PlanarChainConstants {
  double ox[N], oy[N];    ///< joint i's origin in joint i-1's frame (the base for i = 0) [m]
  double beta[N];         ///< the angle of joint i's origin rotation about z [rad]
  double sigma[N];        ///< direction of joint i's axis: +1 (+z) or -1 (-z), the sign of axis.z() [-]
  double m[N];            ///< body mass [kg]
  double cx[N], cy[N];    ///< body centre of mass in joint i's frame [m]
  double Izz[N];          ///< body inertia about z at its centre of mass [kg m^2]
  double tx, ty;          ///< the tip origin in the last joint's frame [m]
  double tip_angle;       ///< the tip frame's angle in the last joint's frame [rad]
  double lx, ly;          ///< -gravity in the base frame [m/s^2]

  /// Reads `chain` (planar_revolute(chain) and chain.dof() == N; not checked).
  explicit PlanarChainConstants(const Chain& chain) {
    for (int i = 0; i < N; ++i) {
      const ChainJoint& j = chain.joints[static_cast<std::size_t>(i)];
      ox[i] = j.origin.p.x();
      oy[i] = j.origin.p.y();
      beta[i] = std::atan2(j.origin.R(1, 0), j.origin.R(0, 0));
      sigma[i] = j.axis.z() > 0.0 ? 1.0 : -1.0;
      m[i] = j.mass;
      cx[i] = j.com.x();
      cy[i] = j.com.y();
      Izz[i] = j.inertia(2, 2);
    }
    tx = chain.tip.p.x();
    ty = chain.tip.p.y();
    tip_angle = std::atan2(chain.tip.R(1, 0), chain.tip.R(0, 0));
    lx = -chain.gravity.x();
    ly = -chain.gravity.y();
  }

  /// The absolute joint frame angles phi (N) at u (N) [rad].
  void frame_angles(const double* u, double* phi) const {
    double acc = 0.0;
    for (int i = 0; i < N; ++i) {
      acc += beta[i] + u[i];
      phi[i] = acc;
    }
  }
};

/// The cosines and sines of the joint frames' absolute angles, carried along a time-stepping loop:
/// after a step u += du, each frame turns by delta_i = sum_{j <= i} du_j, and its sine and
/// cosine follow by a rotation through the Taylor series of sin and cos of delta_i (the next terms
/// are below 2e-18 for |delta_i| < 0.01), which keeps the N sincos calls off the step's dependency
/// chain. Every `resync` steps, or when a step is not small (some |delta_i| >= 0.01 rad), the values
/// are evaluated directly. The schedule depends only on the step count and the values.
template <int N>
class PlanarChainTrig {
 public:
  static constexpr int resync = 64;
  double s[N], c[N];  ///< sin and cos of phi_i

  /// Direct evaluation at u (N) [rad].
  void reset(const PlanarChainConstants<N>& k, const double* u) {
    double phi[N];
    k.frame_angles(u, phi);
    for (int i = 0; i < N; ++i) fast_sincos(phi[i], s[i], c[i]);
    steps_ = 0;
  }
  /// After u (N) has become u + du.
  void advance(const PlanarChainConstants<N>& k, const double* u, const double* du) {
    double d[N], acc = 0.0;
    bool small = true;
    for (int i = 0; i < N; ++i) {
      acc += du[i];
      d[i] = acc;
      small = small && std::abs(acc) < 0.01;  // NaN is not small
    }
    if (++steps_ >= resync || !small) {
      reset(k, u);
      return;
    }
    for (int i = 0; i < N; ++i) {
      const double z = d[i] * d[i], dz = d[i] * z;
      const double sd = d[i] + dz * (-1.0 / 6 + z * (1.0 / 120));
      const double cd = 1.0 + z * (-0.5 + z * (1.0 / 24 + z * (-1.0 / 720)));
      const double sn = s[i] * cd + c[i] * sd;
      c[i] = c[i] * cd - s[i] * sd;
      s[i] = sn;
    }
  }

 private:
  int steps_ = 0;
};

/// What one step needs at (u, ud): M, c, g and the task rows of the tip Jacobian and of J̇ u̇, in the
/// coordinates u (see above). m = 2: tip x, y; m = 3: tip x, y and the angle about z.
template <int N, int m>
struct PlanarChainState {
  double M[N][N];  ///< inertia matrix, both triangles [kg m^2]
  double c[N];     ///< Coriolis and centrifugal torques [Nm]
  double g[N];     ///< gravity torques [Nm]
  double J[m][N];  ///< task rows of the tip Jacobian [m or rad per rad]
  double bias[m];  ///< task rows of J̇ q̇ [m/s^2 or rad/s^2] (the angle's is 0)
  double px, py;   ///< tip position [m]
};

/// Fill `st` from the frames' trig (s, c: N values each, see PlanarChainTrig) and ud (N) [rad/s].
/// Joint i's unit twist is S_i = (1; y_i, -x_i) with (x_i, y_i) its origin
/// (angular part; velocity of the body point at the base origin); force vectors (fx, fy; n) are
/// forces and moments about the base origin, so that a joint's torque is S_i . F.
template <int N, int m>
[[gnu::always_inline]] inline void planar_chain_state(const PlanarChainConstants<N>& __restrict k, const double* __restrict s,
                               const double* __restrict c, const double* __restrict ud,
                               PlanarChainState<N, m>& __restrict st) {
  static_assert(m == 2 || m == 3);
  // joint origins (x, y), centres of mass relative to them (dx, dy) and body inertias about the
  // base origin: mass, first moment h, rotational J
  double x[N], y[N], dx[N], dy[N], hx[N], hy[N], Jz[N];
  double xp = 0.0, yp = 0.0, cp = 1.0, sp = 0.0;
  for (int i = 0; i < N; ++i) {
    if (i == 0) {  // the base frame
      x[i] = k.ox[i];
      y[i] = k.oy[i];
    } else {
      x[i] = xp + (cp * k.ox[i] - sp * k.oy[i]);
      y[i] = yp + (sp * k.ox[i] + cp * k.oy[i]);
    }
    dx[i] = c[i] * k.cx[i] - s[i] * k.cy[i];
    dy[i] = s[i] * k.cx[i] + c[i] * k.cy[i];
    const double bx = x[i] + dx[i], by = y[i] + dy[i];
    hx[i] = k.m[i] * bx;
    hy[i] = k.m[i] * by;
    Jz[i] = k.Izz[i] + (hx[i] * bx + hy[i] * by);
    xp = x[i], yp = y[i], cp = c[i], sp = s[i];
  }
  const double px = xp + (cp * k.tx - sp * k.ty), py = yp + (sp * k.tx + cp * k.ty);
  st.px = px;
  st.py = py;

  // outward, with the accelerations zero: angular velocities w, joint origin accelerations ao (each
  // origin is a point of the previous body, which turns at a constant rate: ao_i = ao_{i-1} -
  // w_{i-1}^2 (o_i - o_{i-1})) and the centres of mass' (ab_i = ao_i - w_i^2 d_i); the bodies'
  // inertial forces m ab and their moments about the base origin b x m ab (no angular acceleration)
  double w = 0.0, w2 = 0.0, aox = 0.0, aoy = 0.0;
  double fx[N], fy[N], fn[N];
  for (int i = 0; i < N; ++i) {
    if (i > 0) {
      aox -= w2 * (x[i] - x[i - 1]);
      aoy -= w2 * (y[i] - y[i - 1]);
    }
    w += ud[i];
    w2 = w * w;
    fx[i] = k.m[i] * (aox - w2 * dx[i]);
    fy[i] = k.m[i] * (aoy - w2 * dy[i]);
    fn[i] = (x[i] + dx[i]) * fy[i] - (y[i] + dy[i]) * fx[i];
  }

  // inward: c_j = S_j . F_j = z . sum_{i >= j} (b_i - o_j) x m_i ab_i from the summed forces F and
  // moments; composite inertias Ic for g_j = S_j . (Ic_j (-gravity)) and M_ij = S_i . (Ic_j S_j)
  double Fx = 0.0, Fy = 0.0, Fn = 0.0, cm = 0.0, chx = 0.0, chy = 0.0, cJ = 0.0;
  for (int j = N - 1; j >= 0; --j) {
    Fx += fx[j];
    Fy += fy[j];
    Fn += fn[j];
    cm += k.m[j];
    chx += hx[j];
    chy += hy[j];
    cJ += Jz[j];
    st.c[j] = Fn + (y[j] * Fx - x[j] * Fy);
    st.g[j] = (chx * k.ly - chy * k.lx) + cm * (y[j] * k.lx - x[j] * k.ly);
    const double Gx = cm * y[j] - chy, Gy = chx - cm * x[j];  // Ic_j S_j
    const double Gn = cJ - (chx * x[j] + chy * y[j]);
    for (int i = 0; i <= j; ++i) {
      const double Mij = Gn + (y[i] * Gx - x[i] * Gy);
      st.M[i][j] = Mij;
      st.M[j][i] = Mij;
    }
  }

  // tip rows: the twists moved to the tip point, and the tip's acceleration at zero accelerations
  for (int i = 0; i < N; ++i) {
    st.J[0][i] = y[i] - py;
    st.J[1][i] = px - x[i];
    if constexpr (m == 3) st.J[2][i] = 1.0;
  }
  st.bias[0] = aox - w2 * (px - xp);
  st.bias[1] = aoy - w2 * (py - yp);
  if constexpr (m == 3) st.bias[2] = 0.0;
}

}  // namespace ks
