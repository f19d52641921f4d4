// solve_start(): damped Newton / minimum-norm steps on the start's rows (see chain_start.hpp).
#include "methods/chain_start.hpp"

#include <Eigen/LU>

#include "methods/chain_resolution.hpp"
#include "model/chain_kinematics.hpp"

namespace ks {
namespace {

using RowVec = Eigen::Vector3d;
using RowMat = Eigen::Matrix3d;
using RowJac = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxJoints>;

/// The start's rows at q: residual e = target - current, and their Jacobian.
class StartRows {
 public:
  StartRows(const Chain& chain, const StartTarget& t) : chain_(chain), t_(t), angle_(chain) {}
  /// |e| at q; fills e and, when J is given, the Jacobian.
  double residual(const VecN& q, RowVec& e, RowJac* J) {
    forward_kinematics(chain_, data_, q);
    const int pos = t_.planar ? 2 : 3;
    for (int r = 0; r < pos; ++r) e[r] = t_.position[r] - data_.tip.p[r];
    if (t_.planar) e[2] = t_.angle - angle_(q);
    if (J) {
      tip_jacobian(chain_, data_, J6_);
      J->resize(3, q.size());
      J->topRows(pos) = J6_.topRows(pos);
      if (t_.planar) J->row(2) = J6_.row(5);
    }
    return e.norm();
  }

 private:
  const Chain& chain_;
  const StartTarget& t_;
  const PlanarAngle angle_;
  ChainData data_;
  Mat6N J6_;
};

}  // namespace

std::optional<VecN> solve_start(const Chain& chain, const StartTarget& target, const VecN& q0,
                                const StartSolveOptions& o) {
  StartRows rows(chain, target);
  VecN q = q0, trial;
  RowVec e, e_trial;
  RowJac J;
  double norm = rows.residual(q, e, &J);
  double lambda2 = 0.0;
  int polish = 0;  // steps taken after convergence
  for (int it = 0; it < o.max_iterations; ++it) {
    if (norm <= o.tolerance && polish == 2) break;
    RowMat A = J * J.transpose();
    A.diagonal().array() += lambda2;
    const RowVec y = A.partialPivLu().solve(e);
    trial = q + J.transpose() * y;
    const double trial_norm = rows.residual(trial, e_trial, nullptr);
    if (trial_norm < norm) {
      q = trial;
      norm = rows.residual(q, e, &J);
      lambda2 = lambda2 > 1e-12 ? lambda2 / 10.0 : 0.0;
      if (norm <= o.tolerance) ++polish;
    } else if (norm <= o.tolerance) {
      break;  // converged, and no step improves on it
    } else {
      lambda2 = lambda2 == 0.0 ? 1e-6 : 10.0 * lambda2;  // (1e-3)^2, then tenfold in lambda^2
      if (!(lambda2 < 1e12)) break;
    }
  }
  if (!(norm <= o.tolerance) || !q.allFinite()) return std::nullopt;
  return q;
}

VecN planar_start_guess(int n) {
  VecN q(n);
  for (int i = 0; i < n; ++i) q[i] = i == 0 ? 0.5 : (i % 2 == 1 ? 1.0 : -1.0);
  return q;
}

}  // namespace ks
