// ChainGlobalProblem (methods/path_global/chain.hpp): the objective with its chain-rule gradient, the
// limit constraints with theirs, and the run's metrics, for any extension.
#include "methods/path_global/chain.hpp"
#include "methods/loop/trajectory_loop.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "common/angles.hpp"

namespace ks {
namespace {

constexpr double kInfeasibleFloor = 1e4;  // per unit of 1 / samples, in the objective's units
constexpr double kSingularDet = 1e-12;    // an extension this close to singular costs the floor too


}  // namespace

LimitConstraints LimitConstraints::of(const Chain& chain, std::size_t samples, int windows) {
  LimitConstraints L;
  L.table = LimitTable::of(chain);
  for (int j = 0; j < chain.dof(); ++j) {
    if (L.table.inv_half[j] > 0) L.rows.push_back({0, j});
    if (L.table.inv_velocity[j] > 0) L.rows.push_back({1, j});
    if (L.table.inv_effort[j] > 0) L.rows.push_back({2, j});
  }
  if (L.rows.empty() || samples == 0) return L;
  const std::size_t w = std::clamp<std::size_t>(static_cast<std::size_t>(std::max(windows, 1)), 1, samples);
  for (std::size_t k = 1; k <= w; ++k) L.window_end.push_back(samples * k / w);
  return L;
}

ChainGlobalProblem::ChainGlobalProblem(const Chain& chain, const ChainTask& task)
    : chain_(chain), task_(task), n_(chain.dof()), rows_(position_rows(task.space)) {
  if (task.space != TaskSpace::planar_position && task.space != TaskSpace::spatial_position)
    throw std::invalid_argument("global_spline: a position path (planar_position or spatial_position)");
}

double ChainGlobalProblem::ratio(const LimitConstraints& limits, const std::array<int, 2>& row,
                                 const ChainGlobalSample& s) const {
  const LimitTable& L = limits.table;
  const int j = row[1];
  switch (row[0]) {
    case 0: {
      const double off = s.q[j] - L.mid[j];
      return std::abs(wraps_angles() ? remainder_2pi(off) : off) * L.inv_half[j];
    }
    case 1: return std::abs(s.qd[j]) * L.inv_velocity[j];
    default: return std::abs(s.tau[j]) * L.inv_effort[j];
  }
}

double ChainGlobalProblem::term_weight(std::size_t i, GlobalObjective objective) const {
  const std::size_t n = samples();
  if (objective == GlobalObjective::E || objective == GlobalObjective::E_M) return 1.0 / static_cast<double>(n);
  return (i == 0 || i + 1 == n) ? 0.5 * task_.path.dt() : task_.path.dt();
}

double ChainGlobalProblem::ratio_partial(const LimitConstraints& limits, const std::array<int, 2>& row,
                                         const ChainGlobalSample& s, const ChainSamplePartials& d, int input) const {
  const LimitTable& L = limits.table;
  const int j = row[1];
  const auto sign = [](double x) { return static_cast<double>((x > 0.0) - (x < 0.0)); };
  switch (row[0]) {
    case 0: {
      const double off = s.q[j] - L.mid[j];
      return sign(wraps_angles() ? remainder_2pi(off) : off) * L.inv_half[j] * d.q[j][input];
    }
    case 1: return sign(s.qd[j]) * L.inv_velocity[j] * d.qd[j][input];
    default: return sign(s.tau[j]) * L.inv_effort[j] * d.tau[j][input];
  }
}

double ChainGlobalProblem::cost(std::size_t i, const ChainGlobalSample& s, GlobalObjective objective) const {
  const std::size_t n = samples();
  const double trapezoid = (i == 0 || i + 1 == n) ? 0.5 * task_.path.dt() : task_.path.dt();
  // a sample off the chart or out of reach: its torques (at the clamped boundary, near singular) are
  // left out, and a floor above any valid sample's cost and a penalty growing with the violation
  // keep the optimiser away
  if (s.violation > 0.0) return kInfeasibleFloor / static_cast<double>(n) + kViolationPenalty * s.violation * s.violation;
  double f = 0.0;
  if (singular(s, kSingularDet)) f += kInfeasibleFloor / static_cast<double>(n);
  switch (objective) {
    case GlobalObjective::E: return f + s.tau.norm() / static_cast<double>(n);
    case GlobalObjective::E_M: return f + std::sqrt(s.tau.dot(state_.M.ldlt().solve(s.tau))) / static_cast<double>(n);
    case GlobalObjective::torque_sq_integral: return f + trapezoid * s.tau.squaredNorm();
    case GlobalObjective::kinetic_energy: return f + trapezoid * 0.5 * s.qd.dot(state_.M * s.qd);
  }
  return f;
}

double ChainGlobalProblem::objective(const AlphaBasis& basis, const double* c, GlobalObjective objective, double* grad,
                                     const LimitConstraints* limits, double* con, double* jac) const {
  const int K = basis.coefficients, r = coordinates(), width = 3 * r;
  // a penalty instead of constraints: every sample's excess of each limited quantity, squared
  const bool penalised = limits && limits->penalty > 0.0;
  const double weight = penalised ? limits->penalty / static_cast<double>(samples()) : 0.0;
  std::vector<std::pair<std::size_t, double>> excess;  // {quantity, excess} of this sample
  const std::size_t P = limits && !penalised ? limits->rows.size() : 0, rows = P > 0 ? limits->count() : 0;
  if (grad) std::fill(grad, grad + static_cast<std::ptrdiff_t>(K) * r, 0.0);
  // per constraint: the largest ratio so far, its sample and the ratio's partials there (z, zd, zdd of each coordinate)
  std::vector<double> top(rows, -std::numeric_limits<double>::infinity()), partial;
  std::vector<std::size_t> top_sample(rows, 0);
  if (jac) partial.assign(rows * static_cast<std::size_t>(width), 0.0);
  std::vector<std::size_t> raised;  // the constraints this sample raised
  std::size_t window = 0;
  double f = 0.0, z[kMaxJoints][3];
  ChainGlobalSample s, up, down;
  ChainSamplePartials exact;
  begin_pass();
  for (std::size_t i = 0; i < samples(); ++i) {
    for (int k = 0; k < r; ++k) basis.at(i, c + k * K, z[k][0], z[k][1], z[k][2]);
    sample(i, z, s);
    f += cost(i, s, objective);
    accept(i, z, s);
    raised.clear();
    excess.clear();
    if (penalised && !(s.violation > 0.0))
      for (std::size_t p = 0; p < limits->rows.size(); ++p) {
        const double v = ratio(*limits, limits->rows[p], s) - (1.0 - limits->margin);
        if (v > 0.0) f += weight * v * v, excess.emplace_back(p, v);
      }
    if (P > 0) {
      while (limits->window_end[window] <= i) ++window;
      for (std::size_t p = 0; p < P; ++p) {
        const std::size_t row = window * P + p;
        const double v = ratio(*limits, limits->rows[p], s);
        if (v > top[row]) top[row] = v, top_sample[row] = i, raised.push_back(row);
      }
    }
    if (!grad && !(jac && !raised.empty())) continue;
    const BasisRow& brow = basis.rows[i];
    if (partials(i, z, s, objective, term_weight(i, objective), exact)) {
      for (const auto& [p, v] : excess)
        for (int input = 0; input < width; ++input)
          exact.cost[input] += 2.0 * weight * v *
                               ratio_partial(*limits, limits->rows[p], s, exact, input);
      for (int k = 0; k < r; ++k)
        for (int d = 0; d < 3; ++d) {
          const int input = 3 * k + d;
          if (grad)
            for (int m = 0; m < kBasisWidth && brow.first + m < K; ++m)
              grad[k * K + brow.first + m] += exact.cost[input] * brow.w[d][m];
          if (jac)
            for (std::size_t row : raised)
              partial[row * width + static_cast<std::size_t>(input)] =
                  ratio_partial(*limits, limits->rows[row % P], s, exact, input);
        }
      continue;
    }
    for (int k = 0; k < r; ++k)
      for (int d = 0; d < 3; ++d) {
        const double x = z[k][d], h = 1e-6 * std::max(1.0, std::abs(x));
        z[k][d] = x + h;
        sample(i, z, up);
        const double f_up = grad ? cost(i, up, objective) : 0.0;
        z[k][d] = x - h;
        sample(i, z, down);
        const double f_down = grad ? cost(i, down, objective) : 0.0;
        z[k][d] = x;
        if (grad) {
          double dfdz = (f_up - f_down) / (2.0 * h);
          for (const auto& [p, v] : excess) {
            const auto& lim = limits->rows[p];
            dfdz += 2.0 * weight * v * (ratio(*limits, lim, up) - ratio(*limits, lim, down)) / (2.0 * h);
          }
          for (int m = 0; m < kBasisWidth && brow.first + m < K; ++m) grad[k * K + brow.first + m] += dfdz * brow.w[d][m];
        }
        if (jac)
          for (std::size_t row : raised) {
            const auto& lim = limits->rows[row % P];
            partial[row * width + static_cast<std::size_t>(3 * k + d)] =
                (ratio(*limits, lim, up) - ratio(*limits, lim, down)) / (2.0 * h);
          }
      }
  }
  if (con)
    for (std::size_t row = 0; row < rows; ++row)  // (no finite ratio in a window: infeasible)
      con[row] = std::isfinite(top[row]) ? top[row] - (1.0 - limits->margin) : 1.0;
  if (jac) {
    const std::size_t cols = static_cast<std::size_t>(K) * r;
    std::fill(jac, jac + rows * cols, 0.0);
    for (std::size_t row = 0; row < rows; ++row) {
      const BasisRow& brow = basis.rows[top_sample[row]];
      for (int k = 0; k < r; ++k)
        for (int d = 0; d < 3; ++d)
          for (int m = 0; m < kBasisWidth && brow.first + m < K; ++m)
            jac[row * cols + static_cast<std::size_t>(k * K + brow.first + m)] +=
                partial[row * width + static_cast<std::size_t>(3 * k + d)] * brow.w[d][m];
    }
  }
  return f;
}

double ChainGlobalProblem::worst_violation(const AlphaBasis& basis, const double* c) const {
  const int K = basis.coefficients, r = coordinates();
  double worst = 0.0, z[kMaxJoints][3];
  ChainGlobalSample s;
  begin_pass();
  for (std::size_t i = 0; i < samples(); ++i) {
    for (int k = 0; k < r; ++k) basis.at(i, c + k * K, z[k][0], z[k][1], z[k][2]);
    sample(i, z, s);
    accept(i, z, s);
    worst = std::max(worst, s.violation);
  }
  return worst;
}

/// The run of a spline as a prescribed model of the one trajectory loop (methods/loop/trajectory_loop.hpp):
/// each sample's state, torques and dynamics from the spline's coordinates (`sample`, continued
/// from the previous sample's solution), nothing integrated.
class ChainGlobalProblem::MeasureModel {
 public:
  static constexpr int max_joints = kMaxJoints;
  static constexpr bool prismatic_joints = false;
  using Evaluation = ChainGlobalSample;

  MeasureModel(const ChainGlobalProblem& p, const AlphaBasis& basis, const double* c, const VecN& q_start,
               const TrajectoryOptions& o, ChainHistory* history)
      : p_(p), basis_(basis), c_(c), o_(o), history_(history), limits_(LimitTable::of(p.chain_)), q_prev_(q_start) {}

  int joints() const { return p_.n_; }
  LoopShape shape() const {
    return {p_.samples(), p_.task_.path.dt(), o_.integrator, o_.on_violation == OnViolation::stop, true};
  }
  RunShape run_shape() const {
    RunShape shape;
    shape.joints = p_.n_;
    shape.limits = &limits_;
    return shape;
  }
  SampleSums<double, kMaxJoints> sums() const {
    return SampleSums<double, kMaxJoints>(o_.tracking_bound, o_.orientation_bound, &limits_);
  }
  /// The pass begins; the tip angle at the start is sample 0's (alpha()).
  bool start(double*) {
    p_.begin_pass();
    Evaluation s0;
    at(0, s0);
    alpha0_ = s0.alpha;
    return true;
  }
  double alpha(const double*) const { return alpha0_; }
  double torque_bound() const { return o_.torque_bound; }

  RunStatus at_sample(std::size_t i, double, double* q, double* qd, Evaluation& s) {
    at(i, s);
    last_ = &s;
    p_.accept(i, z_, s);
    if (s.violation > 0.0) return RunStatus::infeasible;
    if (!s.tau.allFinite()) return RunStatus::diverged;
    if (p_.singular(s, o_.singular_tolerance)) return RunStatus::singular_extension;
    for (int j = 0; j < p_.n_; ++j) s.q[j] = q_prev_[j] + remainder_2pi(s.q[j] - q_prev_[j]);  // continuous joint angles
    q_prev_ = s.q;
    for (int j = 0; j < p_.n_; ++j) q[j] = s.q[j], qd[j] = s.qd[j];
    return RunStatus::ok;
  }
  void torques(const Evaluation& s, const double*, double* tau) const {
    for (int j = 0; j < p_.n_; ++j) tau[j] = s.tau[j];
  }
  /// tau^T tau as Eigen sums the sample's tau.
  double squared_torque(const double*) const { return last_->tau.squaredNorm(); }

  void values(const Evaluation& s, std::size_t i, const double*, const double*, const double*, SampleValues<double>& v) {
    const int n = p_.n_;
    const ChainState& st = p_.state_;
    v.q = s.q.data(), v.qd = s.qd.data(), v.tau = s.tau.data();
    v.qf = s.tau.dot(st.M.ldlt().solve(s.tau)), v.det = 1.0;
    v.w2 = std::max(0.0, p_.rows_ == 2 ? (st.J.topRows<2>() * st.J.topRows<2>().transpose()).determinant()
                                      : (st.J.topRows<3>() * st.J.topRows<3>().transpose()).determinant());
    forward_kinematics(p_.chain_, p_.data_, s.q);
    tip_ = p_.data_.tip.p;
    const Eigen::Vector3d miss = tip_ - p_.task_.path.position(i);
    v.err2 = p_.rows_ == 2 ? miss.head<2>().squaredNorm() : miss.squaredNorm();
    v.orient = 0.0, v.alpha = s.alpha, v.ke = 0.0;
    for (int j = 0; j < n; ++j) v.ke += 0.5 * s.qd[j] * st.M.row(j).head(n).dot(s.qd.head(n));
  }
  void record(std::size_t i, double t, const Evaluation& s, const double*, const double*, const double*, bool) const {
    const std::size_t n = p_.samples();
    if (!history_ || !(i % static_cast<std::size_t>(history_->stride) == 0 || i + 1 == n)) return;
    ChainHistory& h = *history_;
    const Eigen::Index col = h.size++;
    h.t[col] = t;
    h.q.col(col) = s.q;
    h.qd.col(col) = s.qd;
    h.qdd.col(col) = s.qdd;
    h.tau.col(col) = s.tau;
    for (int a = 0; a < p_.rows_; ++a) h.x(a, col) = tip_[a];
    h.alpha[col] = s.alpha;
  }
  void stages(double, double) {}
  bool stage(bool, const double*, const double*, Evaluation&) { return true; }
  void moved(const double*, const double*) {}

 private:
  /// Sample i of the spline into s (its coordinates in z_).
  void at(std::size_t i, Evaluation& s) {
    const int K = basis_.coefficients;
    for (int k = 0; k < p_.coordinates(); ++k) basis_.at(i, c_ + k * K, z_[k][0], z_[k][1], z_[k][2]);
    p_.sample(i, z_, s);
  }

  const ChainGlobalProblem& p_;
  const AlphaBasis& basis_;
  const double* c_;
  const TrajectoryOptions& o_;
  ChainHistory* history_;
  const LimitTable limits_;
  VecN q_prev_;
  double z_[kMaxJoints][3] = {};
  double alpha0_ = 0.0;
  const Evaluation* last_ = nullptr;  // the sample at_sample() filled
  Eigen::Vector3d tip_ = Eigen::Vector3d::Zero();
};

TrajectoryMetrics ChainGlobalProblem::measure(const AlphaBasis& basis, const double* c, const VecN& q_start,
                                              const TrajectoryOptions& o, ChainHistory* history) const {
  if (history) history->prepare(samples(), n_, rows_);
  MeasureModel model(*this, basis, c, q_start, o, history);
  RunSums sums;
  trajectory_loop<double>(model, &sums);
  return finish_run(sums, model.run_shape(), o);
}

}  // namespace ks
