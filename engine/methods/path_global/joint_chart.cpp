// JointExtensionProblem (methods/path_global/joint_chart.hpp): Newton's method on the solved joints, their
// rates and accelerations, and the choice of the solved joints.
#include "methods/path_global/joint_chart.hpp"
#include "methods/path_global/joint_partials.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ks {
namespace {

constexpr int kMaxNewton = 15;
constexpr double kResidual = 1e-13;  // [m]: converged
constexpr double kRounding = 1e-15;  // [m]: no polishing step below this

/// The first m entries of v (an element loop: GCC's bounds analysis misreads head(m) of a fixed vector).
Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1> first(const Eigen::Vector3d& v, int m) {
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1> r(m);
  for (int a = 0; a < m; ++a) r[a] = v[a];
  return r;
}

}  // namespace

JointExtensionProblem::JointExtensionProblem(const Chain& chain, const ChainTask& task, std::vector<int> solved,
                                             const VecN& q_start)
    : ChainGlobalProblem(chain, task), solved_(std::move(solved)), q_start_(q_start) {
  std::sort(solved_.begin(), solved_.end());
  const bool distinct = std::adjacent_find(solved_.begin(), solved_.end()) == solved_.end();
  if (static_cast<int>(solved_.size()) != rows_ || !distinct || solved_.front() < 0 || solved_.back() >= n_ ||
      n_ <= rows_ || q_start.size() != n_)
    throw std::invalid_argument("global_spline, joints extension: " + std::to_string(rows_) +
                                " distinct solved joints of a chain of more joints (" + std::to_string(n_) +
                                "), and a start configuration of its size");
  for (int j = 0; j < n_; ++j)
    if (!std::binary_search(solved_.begin(), solved_.end(), j)) coordinate_joints_.push_back(j);
  const SampledPath3& path = task.path;
  velocity_.reserve(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) velocity_.push_back(path.path().sample_on(path.segment(i), path.time(i)).v);
  accepted_q_ = q_start_;
}

void JointExtensionProblem::begin_pass() const {
  accepted_ = false;
  accepted_q_ = q_start_;
}

void JointExtensionProblem::accept(std::size_t i, const double (*z)[3], const ChainGlobalSample& s) const {
  if (s.violation > 0.0) {  // keep the last solution as continuation's start; nothing to reuse
    accepted_ = false;
    return;
  }
  accepted_ = true;
  accepted_i_ = i;
  accepted_q_ = s.q;
  accepted_qd_ = s.qd;
  for (int k = 0; k < coordinates(); ++k)
    for (int d = 0; d < 3; ++d) accepted_z_[k][d] = z[k][d];
  accepted_state_ = state_;
  accepted_det_ = s.det;
  accepted_alpha_ = s.alpha;
  accepted_lu_ = current_lu_;
  accepted_JC_ = current_JC_;
}

void JointExtensionProblem::sample(std::size_t i, const double (*z)[3], ChainGlobalSample& s) const {
  const int m = rows_, r = coordinates();
  s.q.resize(n_), s.qd.resize(n_), s.qdd.resize(n_), s.tau.resize(n_);
  s.violation = 0.0;
  bool same_q = accepted_ && accepted_i_ == i, same_qd = same_q;
  for (int k = 0; k < r; ++k) same_q = same_q && z[k][0] == accepted_z_[k][0];
  for (int k = 0; k < r; ++k) same_qd = same_q && same_qd && z[k][1] == accepted_z_[k][1];
  const TaskV x = first(task_.path.position(i), m), xd = first(velocity_[i], m), xdd = first(task_.path.acceleration(i), m);
  if (same_q) {  // a perturbation of the accepted sample's rates: its joint path and Jacobians
    s.q = accepted_q_;
    s.det = accepted_det_;
    s.alpha = accepted_alpha_;
  } else {
    s.q = accepted_q_;
    for (int k = 0; k < r; ++k) s.q[coordinate_joints_[k]] = z[k][0];
    Mat6N J(6, n_);
    SquareM JS(m, m);
    TaskV res(m);
    bool converged = false, polished = false;
    double rn = std::numeric_limits<double>::infinity();
    for (int it = 0;; ++it) {
      forward_kinematics(chain_, data_, s.q);
      res = x - first(data_.tip.p, m);
      double rr = 0.0;
      for (int a = 0; a < m; ++a) rr += res[a] * res[a];
      rn = std::sqrt(rr);
      converged = converged || rn <= kResidual;
      if ((converged && (polished || rn <= kRounding)) || !std::isfinite(rn) || it == kMaxNewton) break;
      polished = converged;  // one more step once converged: the solution to rounding
      tip_jacobian(chain_, data_, J);
      for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b) JS(a, b) = J(a, solved_[b]);
      const TaskV step = JS.partialPivLu().solve(res);
      if (!step.allFinite()) break;
      for (int b = 0; b < m; ++b) s.q[solved_[b]] += step[b];
    }
    // the Jacobians at s.q (data_ holds its frames)
    tip_jacobian(chain_, data_, J);
    current_JC_.resize(m, r);
    for (int a = 0; a < m; ++a) {
      for (int b = 0; b < m; ++b) JS(a, b) = J(a, solved_[b]);
      for (int k = 0; k < r; ++k) current_JC_(a, k) = J(a, coordinate_joints_[k]);
    }
    current_lu_.compute(JS);
    current_res_ = res;
    s.det = JS.determinant();
    s.violation = converged && std::isfinite(rn) ? 0.0 : (std::isfinite(rn) ? std::max(rn, kResidual) : 1.0);
    s.alpha = m == 2 ? std::atan2(data_.tip.R(1, 0), data_.tip.R(0, 0)) : std::numeric_limits<double>::quiet_NaN();
  }
  // rates: J_S qd_S = xd - J_C zd; accelerations: J_S qdd_S = xdd - J_C zdd - (Jdot qd)
  const Eigen::PartialPivLU<SquareM>& lu = same_q ? accepted_lu_ : current_lu_;
  const JacobianC& JC = same_q ? accepted_JC_ : current_JC_;
  CoordinateV zd(r), zdd(r);
  for (int k = 0; k < r; ++k) zd[k] = z[k][1], zdd[k] = z[k][2];
  if (same_qd) {
    s.qd = accepted_qd_;
    state_.M = accepted_state_.M;  // the objective's weights read it
  } else {
    const TaskV qdS = lu.solve(xd - JC * zd);
    for (int k = 0; k < r; ++k) s.qd[coordinate_joints_[k]] = z[k][1];
    for (int b = 0; b < m; ++b) s.qd[solved_[b]] = qdS[b];
    evaluate_dynamics(chain_, data_, s.q, s.qd, state_, !same_q);  // (Newton's last step left q's frames)
  }
  const ChainState& st = same_qd ? accepted_state_ : state_;
  const TaskV qddS = lu.solve(xdd - JC * zdd - first(st.bias.head<3>(), m));
  for (int k = 0; k < r; ++k) s.qdd[coordinate_joints_[k]] = z[k][2];
  for (int b = 0; b < m; ++b) s.qdd[solved_[b]] = qddS[b];
  s.tau = st.M * s.qdd + st.c + st.g;
}

bool JointExtensionProblem::partials(std::size_t, const double (*z)[3], const ChainGlobalSample& s,
                                     GlobalObjective objective, double weight, ChainSamplePartials& out) const {
  const int r = coordinates(), inputs = 3 * r;
  if (s.violation > 0.0) {
    out.inputs = inputs;
    for (int k = 0; k < inputs; ++k) out.cost[k] = 0.0;
    for (int j = 0; j < n_; ++j)
      for (int k = 0; k < inputs; ++k) out.q[j][k] = out.qd[j][k] = out.tau[j][k] = 0.0;
    if (s.violation < 1.0 && current_res_.size() == rows_ && current_res_.allFinite())
      for (int k = 0; k < r; ++k) out.cost[3 * k] = -2.0 * kViolationPenalty * current_res_.dot(current_JC_.col(k));
    return true;
  }
  JointSampleAt at;
  at.chain = &chain_;
  at.data = &data_;
  at.solved = solved_.data();
  at.coordinate = coordinate_joints_.data();
  at.m = rows_;
  at.r = r;
  at.lu = &current_lu_;
  at.JC = &current_JC_;
  at.q = &s.q, at.qd = &s.qd, at.qdd = &s.qdd, at.tau = &s.tau;
  at.M = &state_.M;
  at.z = z;
  joint_sample_partials(at, objective, weight, out);
  return true;
}

void JointExtensionProblem::coordinates_of(std::size_t, const VecN& q, double* z, Elbow& elbow) const {
  for (int k = 0; k < coordinates(); ++k) z[k] = q[coordinate_joints_[k]];
  elbow = Elbow::positive;
}

std::vector<int> JointExtensionProblem::choose_solved(const Chain& chain, int rows, const Eigen::MatrixXd& q,
                                                      Eigen::Index count, Eigen::Index stride) {
  const int n = chain.dof();
  std::vector<Mat6N> jacobians;
  ChainData data;
  for (Eigen::Index i = 0; i < count; i += std::max<Eigen::Index>(stride, 1)) {
    forward_kinematics(chain, data, q.col(i));
    Mat6N J(6, n);
    tip_jacobian(chain, data, J);
    jacobians.push_back(J);
  }
  std::vector<int> best;
  double best_det = -1.0;
  for (unsigned mask = 0; mask < (1u << n); ++mask) {
    if (std::popcount(mask) != rows) continue;
    std::vector<int> S;
    for (int j = 0; j < n; ++j)
      if (mask & (1u << j)) S.push_back(j);
    double smallest = std::numeric_limits<double>::infinity();
    SquareM JS(rows, rows);
    for (const Mat6N& J : jacobians) {
      for (int a = 0; a < rows; ++a)
        for (int b = 0; b < rows; ++b) JS(a, b) = J(a, S[b]);
      smallest = std::min(smallest, std::abs(JS.determinant()));
    }
    if (smallest > best_det) best_det = smallest, best = S;
  }
  return best;
}

}  // namespace ks
