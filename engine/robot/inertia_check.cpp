// Mass-property checks shared by the robot readers (see inertia_check.hpp).
#include "robot/inertia_check.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "model/chain_dynamics.hpp"

namespace ks {

namespace {

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

std::string inertia_problem(const Eigen::Matrix3d& Ic) {
  if (!Ic.allFinite()) return "the inertia (ixx..izz) is not finite; expected finite numbers [kg m^2]";
  const Eigen::Vector3d p = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Ic, Eigen::EigenvaluesOnly).eigenvalues();  // ascending
  const double tol = 1e-6 * std::max(std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]), 1e-300);
  const std::string moments = "(" + num(p[0]) + ", " + num(p[1]) + ", " + num(p[2]) + " kg m^2)";
  if (p[0] < -tol)
    return "the inertia's principal moments " + moments +
           " include a negative one; expected a positive semi-definite inertia (ixx..izz about the centre of mass)";
  if (p[2] > p[0] + p[1] + tol)
    return "the inertia's principal moments " + moments + " violate the triangle inequality (" + num(p[2]) + " > " +
           num(p[0]) + " + " + num(p[1]) + "); expected each moment <= the sum of the other two (no rigid body has such an inertia)";
  return {};
}

std::string inertia_matrix_problem(const Chain& chain, int* joint) {
  *joint = -1;
  const int n = chain.dof();
  ChainData data;
  MatN M;
  for (int k = 0; k < 4; ++k) {
    VecN q = VecN::Zero(n);
    for (int i = 0; k > 0 && i < n; ++i) {
      const double u = std::fmod(0.318309886 * (k * 7 + i * 3 + 1), 1.0);  // spread in (0, 1)
      const ChainJoint& j = chain.joints[i];
      q[i] = std::isfinite(j.lower) && std::isfinite(j.upper) ? j.lower + u * (j.upper - j.lower) : (2 * u - 1) * 3.0;
    }
    crba(chain, data, q, M);
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M, Eigen::EigenvaluesOnly).eigenvalues();
    if (ev[0] > 1e-12 * std::max(1e-300, ev[n - 1])) continue;
    int weakest = 0;
    for (int i = 1; i < n; ++i)
      if (M(i, i) < M(weakest, weakest)) weakest = i;
    if (M(weakest, weakest) <= 1e-12 * M.diagonal().maxCoeff()) {
      *joint = weakest;
      return "the inertia matrix is singular: joint '" + chain.joints[weakest].name +
             "' moves neither mass nor inertia (every link from it to the tip is massless or lies on its axis)";
    }
    std::ostringstream s;
    s << "the inertia matrix is singular at q = (" << q.transpose() << "): the joints move the same bodies the same way";
    return s.str();
  }
  return {};
}

}  // namespace ks
