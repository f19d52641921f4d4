#pragma once
// Joint coordinates as the extension of the path-global method (methods/path_global/chain.hpp), for
// any chain on a position path with m task rows (planar_position: x, y; spatial_position: x, y, z):
// the r = n - m redundant coordinates are the angles of r joints C, and the extended task [x; q_C] is
// square. At each sample the other m joints S solve x(q) = path(t) by Newton's method, started from
// the previous sample's solution (the branch of the start, followed along the path; exact: the
// residual is below 1e-13 m), and
//   J_S q̇_S = ẋ − J_C ż,        J_S q̈_S = ẍ − J_C z̈ − J̇ q̇,
// with J_S, J_C the columns of the tip's position Jacobian and J̇ q̇ its bias acceleration. The
// extension is singular where det J_S = 0 (reported as singular_extension); which joints are solved
// is the caller's choice (choose_solved picks the best conditioned along a run).
#include <vector>

#include "methods/path_global/chain.hpp"

namespace ks {

class JointExtensionProblem final : public ChainGlobalProblem {
 public:
  /// solved: the m joints solved on the task (0-based, distinct; m = the task's position rows),
  /// q_start: the configuration whose solved joints start the first sample's Newton iteration
  /// (std::invalid_argument for a wrong count or index, or a task that is not a position path).
  JointExtensionProblem(const Chain& chain, const ChainTask& task, std::vector<int> solved, const VecN& q_start);

  int coordinates() const override { return static_cast<int>(coordinate_joints_.size()); }
  /// s.det: det J_S [m^m for revolute joints]; s.violation: the Newton residual [m] when it did not
  /// converge (0 otherwise); s.alpha: the tip angle for planar tasks, NaN for spatial ones.
  void sample(std::size_t i, const double (*z)[3], ChainGlobalSample& s) const override;
  void coordinates_of(std::size_t i, const VecN& q, double* z, Elbow& elbow) const override;
  bool singular(const ChainGlobalSample& s, double tolerance) const override { return !(std::abs(s.det) >= tolerance); }
  bool wraps_angles() const override { return false; }
  void begin_pass() const override;
  void accept(std::size_t i, const double (*z)[3], const ChainGlobalSample& s) const override;
  /// Exact partials (methods/path_global/joint_partials.hpp). A sample whose Newton iteration did not
  /// converge costs a floor plus 1e6 |res|^2, res the residual where it stopped: its partials are those
  /// of the residual with the solved joints held, d|res|^2/dz = -2 res^T J_C.
  bool partials(std::size_t i, const double (*z)[3], const ChainGlobalSample& s, GlobalObjective objective,
                double weight, ChainSamplePartials& out) const override;

  const std::vector<int>& solved_joints() const { return solved_; }
  const std::vector<int>& coordinate_joints() const { return coordinate_joints_; }

  /// The m joints whose position-Jacobian columns are best conditioned along the configurations
  /// q.col(0 .. count) (every `stride`-th): of every set of m joints, the one with the largest
  /// smallest |det J_S|. \param[in] rows m (2 or 3).
  static std::vector<int> choose_solved(const Chain& chain, int rows, const Eigen::MatrixXd& q, Eigen::Index count,
                                        Eigen::Index stride = 10);

 private:
  using SquareM = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;
  using TaskV = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
  using CoordinateV = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJoints, 1>;  // the r coordinates' rates
  using JacobianC = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, kMaxJoints>;

  std::vector<int> solved_, coordinate_joints_;
  VecN q_start_;
  std::vector<Eigen::Vector3d> velocity_;  // the path's velocity at each sample [m/s]
  // the accepted sample: continuation's start, and what a perturbation of its rates reuses
  mutable std::size_t accepted_i_ = 0;
  mutable bool accepted_ = false;
  mutable VecN accepted_q_, accepted_qd_;
  mutable double accepted_z_[kMaxJoints][3] = {};
  mutable ChainState accepted_state_;
  mutable double accepted_det_ = 0, accepted_alpha_ = 0;
  mutable Eigen::PartialPivLU<SquareM> accepted_lu_, current_lu_;  // of J_S
  mutable JacobianC accepted_JC_, current_JC_;
  mutable TaskV current_res_;  // the Newton residual at the last sample computed [m]
};

}  // namespace ks
