// ChainGlobalProblem (methods/path_global/chain.hpp): the objective with its chain-rule gradient, the
// limit constraints with theirs, and the run's metrics, for any extension.
#include "methods/path_global/chain.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "common/angles.hpp"

namespace ks {
namespace {

constexpr double kViolationWeight = 1e6;
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

double ChainGlobalProblem::cost(std::size_t i, const ChainGlobalSample& s, GlobalObjective objective) const {
  const std::size_t n = samples();
  const double trapezoid = (i == 0 || i + 1 == n) ? 0.5 * task_.path.dt() : task_.path.dt();
  // a sample off the chart or out of reach: its torques (at the clamped boundary, near singular) are
  // left out, and a floor above any valid sample's cost and a penalty growing with the violation
  // keep the optimiser away
  if (s.violation > 0.0) return kInfeasibleFloor / static_cast<double>(n) + kViolationWeight * s.violation * s.violation;
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
  const std::size_t P = limits ? limits->rows.size() : 0, rows = limits ? limits->count() : 0;
  if (grad) std::fill(grad, grad + static_cast<std::ptrdiff_t>(K) * r, 0.0);
  // per constraint: the largest ratio so far, its sample and the ratio's partials there (z, zd, zdd of each coordinate)
  std::vector<double> top(rows, -std::numeric_limits<double>::infinity()), partial;
  std::vector<std::size_t> top_sample(rows, 0);
  if (jac) partial.assign(rows * static_cast<std::size_t>(width), 0.0);
  std::vector<std::size_t> raised;  // the constraints this sample raised
  std::size_t window = 0;
  double f = 0.0, z[kMaxJoints][3];
  ChainGlobalSample s, up, down;
  begin_pass();
  for (std::size_t i = 0; i < samples(); ++i) {
    for (int k = 0; k < r; ++k) basis.at(i, c + k * K, z[k][0], z[k][1], z[k][2]);
    sample(i, z, s);
    f += cost(i, s, objective);
    accept(i, z, s);
    raised.clear();
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
          const double dfdz = (f_up - f_down) / (2.0 * h);
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

TrajectoryMetrics ChainGlobalProblem::measure(const AlphaBasis& basis, const double* c, const VecN& q_start,
                                              const TrajectoryOptions& o, ChainHistory* history) const {
  const std::size_t n = samples();
  const int K = basis.coefficients, r = coordinates();
  if (history) history->prepare(n, n_, rows_);
  const LimitTable limits = LimitTable::of(chain_);
  SampleSums<double, kMaxJoints> sums(o.tracking_bound, o.orientation_bound, &limits);
  VecN q_prev = q_start;
  RunStatus stop = RunStatus::ok;
  double z[kMaxJoints][3];
  const auto keep = [](double updated, double) { return updated; };
  ChainGlobalSample s;
  begin_pass();
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < r; ++k) basis.at(i, c + k * K, z[k][0], z[k][1], z[k][2]);
    sample(i, z, s);
    accept(i, z, s);
    if (i == 0) sums.start_alpha(s.alpha);
    if (s.violation > 0.0 || !s.tau.allFinite()) {
      stop = s.violation > 0.0 ? RunStatus::infeasible : RunStatus::diverged;
      break;
    }
    if (singular(s, o.singular_tolerance)) {
      stop = RunStatus::singular_extension;
      break;
    }
    for (int j = 0; j < n_; ++j) s.q[j] = q_prev[j] + remainder_2pi(s.q[j] - q_prev[j]);  // continuous joint angles
    q_prev = s.q;
    double abs_tau[kMaxJoints];
    for (int j = 0; j < n_; ++j) abs_tau[j] = std::abs(s.tau[j]);
    if (!(s.tau.cwiseAbs().maxCoeff() <= o.torque_bound)) {
      stop = RunStatus::diverged;
      break;
    }
    const double w2 = std::max(0.0, rows_ == 2 ? (state_.J.topRows<2>() * state_.J.topRows<2>().transpose()).determinant()
                                               : (state_.J.topRows<3>() * state_.J.topRows<3>().transpose()).determinant());
    forward_kinematics(chain_, data_, s.q);
    const Eigen::Vector3d tip = data_.tip.p;
    const Eigen::Vector3d miss = tip - task_.path.position(i);
    const double err2 = rows_ == 2 ? miss.head<2>().squaredNorm() : miss.squaredNorm();
    double p6 = 0;
    for (int j = 0; j < n_; ++j) p6 += (s.tau[j] * s.qd[j]) * (s.tau[j] * s.qd[j]);
    const double qf = s.tau.dot(state_.M.ldlt().solve(s.tau));
    SampleValues<double> v{n_, s.q.data(), s.qd.data(), s.tau.data(), s.tau.squaredNorm(), 0.0, qf, 1.0, p6, w2,
                                 err2, 0.0, s.alpha, 0.0};
    for (int j = 0; j < n_; ++j) v.ke += 0.5 * s.qd[j] * state_.M.row(j).head(n_).dot(s.qd.head(n_));
    const bool off = sums.add(i, task_.path.time(i), v, abs_tau, n_, keep);
    const bool beyond = sums.limits(s.q.data(), s.qd.data(), s.tau.data(), n_);
    sums.mark(off, beyond);
    if (history && (i % static_cast<std::size_t>(history->stride) == 0 || i + 1 == n)) {
      const Eigen::Index col = history->size++;
      history->t[col] = task_.path.time(i);
      history->q.col(col) = s.q;
      history->qd.col(col) = s.qd;
      history->qdd.col(col) = s.qdd;
      history->tau.col(col) = s.tau;
      for (int a = 0; a < rows_; ++a) history->x(a, col) = tip[a];
      history->alpha[col] = s.alpha;
    }
    if ((off || beyond) && o.on_violation == OnViolation::stop) break;
  }
  RunShape shape;
  shape.joints = n_;
  shape.limits = &limits;
  return finish_run(sums.of_lane(0, stop, n_), shape, o);
}

}  // namespace ks
