#pragma once
// Joint accelerations of the redundancy resolutions for a serial chain (model/chain.hpp) at one
// instant: the seed's local methods (methods/base/resolution.hpp) for any number of joints n and any task
// dimension m < n, and the non-redundant solve for m = n. Free functions on fixed-maximum-size types
// (no allocation), templated on the task dimension m so the task-space matrices have fixed size.
// Every inverse is a solve: an LDL^T factor of M (n x n) and one of A = J W^-1 J^T (m x m).
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <limits>
#include <string_view>

#include "methods/base/resolution.hpp"
#include "model/chain.hpp"

namespace ks {

/// What the tip must do along the path: which rows of its motion the task prescribes.
enum class TaskSpace {
  planar_position,   ///< planar chains: tip x, y (m = 2)
  planar_pose,       ///< planar chains: tip x, y and its angle alpha about z (m = 3)
  spatial_position,  ///< tip x, y, z (m = 3)
  spatial_pose,      ///< tip x, y, z and its orientation, held at the start's (m = 6)
};

std::string_view to_string(TaskSpace s);
/// Parse a name; false when unknown.
bool parse(std::string_view name, TaskSpace& out);

/// Task dimension m: the number of prescribed rows.
constexpr int task_dimension(TaskSpace s) {
  switch (s) {
    case TaskSpace::planar_position: return 2;
    case TaskSpace::planar_pose: return 3;
    case TaskSpace::spatial_position: return 3;
    case TaskSpace::spatial_pose: return 6;
  }
  return 0;
}
/// True for the tasks of planar chains (tip in the xy plane, orientation one angle about z).
constexpr bool is_planar(TaskSpace s) { return s == TaskSpace::planar_position || s == TaskSpace::planar_pose; }
/// Number of position rows of the task (2 planar, 3 spatial): the tracked tip position's dimension.
constexpr int position_rows(TaskSpace s) { return is_planar(s) ? 2 : 3; }

/// Rows of the 6-row tip Jacobian (linear x, y, z, then angular x, y, z; base frame) that the task
/// prescribes, in task order. The position rows come first.
template <TaskSpace S>
constexpr std::array<int, task_dimension(S)> task_rows() {
  if constexpr (S == TaskSpace::planar_position) return {0, 1};
  else if constexpr (S == TaskSpace::planar_pose) return {0, 1, 5};
  else if constexpr (S == TaskSpace::spatial_position) return {0, 1, 2};
  else return {0, 1, 2, 3, 4, 5};
}

template <int m>
using TaskVec = Eigen::Matrix<double, m, 1>;
template <int m>
using TaskMat = Eigen::Matrix<double, m, m>;
/// A task Jacobian: m task rows x n joints.
template <int m>
using TaskJacobian = Eigen::Matrix<double, m, Eigen::Dynamic, 0, m, kMaxJoints>;
/// n joints x m task columns (W^-1 J^T).
template <int m>
using JointTaskMat = Eigen::Matrix<double, Eigen::Dynamic, m, 0, kMaxJoints, m>;

/// The task rows of the 6 x n tip Jacobian. \param[in] J (6 x n). \param[out] Jt (m x n).
template <TaskSpace S>
void select_task_rows(const Mat6N& J, TaskJacobian<task_dimension(S)>& Jt) {
  constexpr auto rows = task_rows<S>();
  Jt.resize(task_dimension(S), J.cols());
  for (int r = 0; r < task_dimension(S); ++r) Jt.row(r) = J.row(rows[r]);
}

/// The task rows of a 6-vector (the tip bias acceleration J̇ q̇, say).
template <TaskSpace S>
TaskVec<task_dimension(S)> select_task_rows(const Vec6& v) {
  constexpr auto rows = task_rows<S>();
  TaskVec<task_dimension(S)> out;
  for (int r = 0; r < task_dimension(S); ++r) out[r] = v[rows[r]];
  return out;
}

/// det(J J^T) of the first k rows of J (k <= m), the squared manipulability of those rows
/// [(m or rad)^(2k) per joint unit^2]; clamped at 0 from below (rounding at a singular configuration).
template <int k, int m>
double gram_determinant(const TaskJacobian<m>& J) {
  static_assert(k <= m);
  double d;
  if constexpr (k == 2) {
    double a = 0, b = 0, c = 0;
    for (Eigen::Index j = 0; j < J.cols(); ++j) {
      a += J(0, j) * J(0, j);
      b += J(0, j) * J(1, j);
      c += J(1, j) * J(1, j);
    }
    d = a * c - b * b;
  } else {
    const TaskMat<k> G = J.template topRows<k>() * J.template topRows<k>().transpose();
    d = G.determinant();
  }
  return d > 0.0 ? d : 0.0;
}

/// LDL^T factor of a small symmetric positive-definite matrix, A = L D L^T with L unit lower
/// triangular (n <= Max), in plain loops over fixed-size storage: at n <= 8 Eigen's dynamic-size LLT
/// and triangular solves cost several times more than the arithmetic, and LDL^T keeps the square
/// roots of a Cholesky factor off the step's dependency chain. Keeps 1 / D_i, so the solves multiply.
/// A pivot that is not positive (or not finite) becomes NaN, which every solve carries to its output.
template <int Max>
struct SmallLdlt {
  int n = 0;
  double L[Max][Max];  ///< strictly lower triangle, row-major; L[i][j] for j < i (unit diagonal)
  double d[Max];       ///< D_i
  double inv_d[Max];   ///< 1 / D_i

  /// Factor the n x n matrix A (read through A(i, j), lower triangle).
  template <class Matrix>
  void compute(const Matrix& A, int n_) {
    n = n_;
    double LD[Max];  // L[j][k] D_k of the current row j
    for (int j = 0; j < n; ++j) {
      double dj = A(j, j);
      for (int k = 0; k < j; ++k) {
        LD[k] = L[j][k] * d[k];
        dj -= L[j][k] * LD[k];
      }
      d[j] = dj;
      inv_d[j] = dj > 0.0 ? 1.0 / dj : std::numeric_limits<double>::quiet_NaN();
      for (int i = j + 1; i < n; ++i) {
        double s = A(i, j);
        for (int k = 0; k < j; ++k) s -= L[i][k] * LD[k];
        L[i][j] = s * inv_d[j];
      }
    }
  }
  /// x <- L^-1 x (x: n values).
  void forward(double* x) const {
    for (int i = 1; i < n; ++i) {
      double s = x[i];
      for (int k = 0; k < i; ++k) s -= L[i][k] * x[k];
      x[i] = s;
    }
  }
  /// x <- L^-T x.
  void backward(double* x) const {
    for (int i = n - 2; i >= 0; --i) {
      double s = x[i];
      for (int k = i + 1; k < n; ++k) s -= L[k][i] * x[k];
      x[i] = s;
    }
  }
  /// x <- A^-1 x.
  void solve(double* x) const {
    forward(x);
    for (int i = 0; i < n; ++i) x[i] *= inv_d[i];
    backward(x);
  }
  /// x^T A^-1 x; x is overwritten with L^-1 x.
  double inverse_quadratic_form(double* x) const {
    forward(x);
    double q = 0;
    for (int i = 0; i < n; ++i) q += x[i] * x[i] * inv_d[i];
    return q;
  }
};

/// The factor of a chain's inertia matrix M (n x n).
using InertiaFactor = SmallLdlt<kMaxJoints>;

/// Local (instantaneous) resolution at acceleration level for a chain (seed Eqs. 51, 56, generalised):
///   qdd = J_W+ b - (I - J_W+ J) v,  J_W+ = W^-1 J^T (J W^-1 J^T)^-1,  v = M^-1 (c + k g) + K_N qd + w,
/// computed as qdd = Y A^-1 (b + J v) - v with Y = W^-1 J^T (n x m, solves with the factor of M) and
/// A = J Y (m x m, an LDL^T factor of its own).
/// W = M (Weighting::inertia) minimises (qdd + v)^T M (qdd + v), i.e. with k = 1 and K_N = 0 the torque
/// norm tau^T M^-1 tau, among the qdd with J qdd = b; W = M^2 (inertia_squared) minimises
/// (qdd + v)^T M^2 (qdd + v), with k = 1 and K_N = 0 tau^T tau.
/// Inputs: Mf, the factor of M [kg m^2]; J (m x n), the task Jacobian [m or rad per joint unit];
/// b (m) = task acceleration - task rows of J̇ q̇ [m/s^2 or rad/s^2]; u = c + k g (n) [Nm]; K_N [1/s];
/// qd (n) [rad/s]; w (n, optional) [rad/s^2], a further null-space term (the limit spring
/// K_L (q - q_mid)). Output: qdd (n) [rad/s^2]. Non-finite input or a singular J gives non-finite output.
template <int m>
VecN local_acceleration(Weighting w, const InertiaFactor& Mf, const TaskJacobian<m>& J, const TaskVec<m>& b,
                        const VecN& u, double K_N, const VecN& qd, const double* extra = nullptr) {
  const int n = static_cast<int>(J.cols());
  double Y[m][kMaxJoints], v[kMaxJoints];
  for (int s = 0; s < m; ++s) {
    for (int j = 0; j < n; ++j) Y[s][j] = J(s, j);
    Mf.solve(Y[s]);
    if (w == Weighting::inertia_squared) Mf.solve(Y[s]);
  }
  for (int j = 0; j < n; ++j) v[j] = u[j];
  Mf.solve(v);
  if (K_N != 0.0)
    for (int j = 0; j < n; ++j) v[j] += K_N * qd[j];
  if (extra)
    for (int j = 0; j < n; ++j) v[j] += extra[j];
  TaskMat<m> A;
  double r[m];
  for (int s = 0; s < m; ++s) {
    for (int t = 0; t <= s; ++t) {
      double a = 0;
      for (int j = 0; j < n; ++j) a += J(s, j) * Y[t][j];
      A(s, t) = a;  // the factor reads the lower triangle
    }
    double jv = 0;
    for (int j = 0; j < n; ++j) jv += J(s, j) * v[j];
    r[s] = b[s] + jv;
  }
  SmallLdlt<m> Af;
  Af.compute(A, m);
  Af.solve(r);
  VecN qdd(n);
  for (int j = 0; j < n; ++j) {
    double x = -v[j];
    for (int s = 0; s < m; ++s) x += Y[s][j] * r[s];
    qdd[j] = x;
  }
  return qdd;
}

/// Non-redundant resolution (m = n; vertex_alpha): solve J qdd = b by LU with partial pivoting.
/// Inputs: J (m x m) [m or rad per joint unit], b [m/s^2 or rad/s^2]. Output: qdd [rad/s^2];
/// det_out receives det J, the singularity measure.
template <int m>
VecN nonredundant_acceleration(const TaskJacobian<m>& J, const TaskVec<m>& b, double& det_out) {
  const TaskMat<m> square = J;
  const Eigen::PartialPivLU<TaskMat<m>> lu(square);
  det_out = lu.determinant();
  return VecN(lu.solve(b));
}

/// The tip angle about z of a planar chain, unwrapped: alpha(q) = offset + sum_i s_i q_i, with s_i the
/// z component of revolute joint i's axis (+1 or -1 in a planar chain; 0 for prismatic joints) and
/// offset the angle of the tip frame at q = 0. Equals the angular-z row of the tip Jacobian times q
/// plus the offset; for the seed arm, theta1 + theta2 + theta3.
struct PlanarAngle {
  double offset = 0.0;  ///< [rad]
  VecN s;               ///< [-] (n)

  /// Reads the joint axes and the frames at q = 0 of a planar chain (see Chain::planar()).
  explicit PlanarAngle(const Chain& chain) : s(VecN::Zero(chain.dof())) {
    Frame f;
    for (int i = 0; i < chain.dof(); ++i) {
      const ChainJoint& j = chain.joints[static_cast<std::size_t>(i)];
      f = f * j.origin;
      if (j.type == JointType::revolute) s[i] = (f.R * j.axis).z();
    }
    f = f * chain.tip;
    offset = std::atan2(f.R(1, 0), f.R(0, 0));
  }
  /// alpha [rad] at q (n).
  double operator()(const VecN& q) const { return offset + s.dot(q); }
};

}  // namespace ks
