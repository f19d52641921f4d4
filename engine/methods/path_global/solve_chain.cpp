// solve_global_spline_chain (methods/path_global/chain.hpp): the start from the chain's local run,
// the extension, the SLSQP solve over every coordinate's spline with the robot's limits as a
// penalty (or constraints), and the final measure.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>

#include "methods/path_global/slsqp.hpp"
#include "methods/path_global/joint_chart.hpp"
#include "methods/path_global/planar_chart.hpp"
#include "methods/path_global/verify.hpp"
#include "model/planar_chain_dynamics.hpp"

namespace ks {
namespace {

constexpr double kFirstPenalty = 10.0;  // the penalty's first weight: this times the objective over the penalty
constexpr double kPenaltyGrowth = 1e9;  // the largest weight over the first
constexpr double kPenaltyStep = 10.0;   // each weight over the last
constexpr double kPenaltyStall = 0.5;  // a level that leaves more than this of the last one's excess ends it
constexpr double kPenaltyExcess = 0.1;  // the largest excess accepted at a penalty's end, over the margin
constexpr int kMaxRestarts = 2;    // SLSQP's restarts from its end under the limit constraints
constexpr int kDescentSteps = 30;  // steps of the steepest-descent check, each half the last
constexpr double kFirstStep = 0.1; // [rad]: the first step's largest change of a coefficient

}  // namespace

TrajectoryMetrics solve_global_spline_chain(const Chain& chain, const ChainTask& task, const VecN& q0,
                                            const TrajectoryOptions& o, ChainHistory* history,
                                            std::vector<double>* coefficients) {
  if (std::string why; !o.IsValid(&why)) throw std::invalid_argument("global_spline: " + why);
  const PathGlobalOptions& g = o.global;
  if (g.spline != AlphaSpline::cubic || g.start == GlobalStart::vertex)
    throw std::invalid_argument("global_spline on a chain: cubic splines from a local or random start only");
  const bool chart = g.extension != Extension::joints;
  if (chart && !(planar_revolute(chain) && task.space == TaskSpace::planar_position))
    throw std::invalid_argument("global_spline: the " + std::string(to_string(g.extension)) +
                                " extension needs a planar chain of revolute joints on a position path (else: joints)");
  if (task.space != TaskSpace::planar_position && task.space != TaskSpace::spatial_position)
    throw std::invalid_argument("global_spline on a chain: a position path");
  const int n = chain.dof();
  // the start: the chain's local run (its first sample is the start solve's configuration), each
  // coordinate along it unwrapped and fitted by the spline
  ChainHistory h;
  h.stride = 1;
  const auto local_run = [&](StartMethod method) {
    TrajectoryOptions lo = o;
    lo.method = method == StartMethod::local_unweighted ? TrajectoryMethod::local_unweighted
                                                        : TrajectoryMethod::local_weighted;
    lo.on_violation = OnViolation::ignore;
    return simulate(chain, task, q0, lo, &h);
  };
  const TrajectoryMetrics local = local_run(g.start_method);
  if (local.status == RunStatus::unreachable_start || h.size == 0) return not_simulated(RunStatus::unreachable_start, n);
  const VecN q_start = h.q.col(0);
  // the extension: the planar chart on the start's elbow branch, or joint coordinates with the solved
  // joints chosen along the local run in h
  double solved_code = 0.0;
  Elbow chart_elbow = Elbow::positive;
  std::vector<int> solved;
  // the extension on a task sampled at any step (the run's, or a finer one for verification)
  const auto extension_on = [&](const ChainTask& t) -> std::unique_ptr<ChainGlobalProblem> {
    if (chart) return std::make_unique<PlanarChartProblem>(chain, t, g.extension, chart_elbow);
    return std::make_unique<JointExtensionProblem>(chain, t, solved, q_start);
  };
  const auto extension_of_run = [&]() -> std::unique_ptr<ChainGlobalProblem> {
    if (chart) {
      double z[kMaxJoints];
      PlanarChartProblem(chain, task, Extension::alpha, Elbow::positive).coordinates_of(0, q_start, z, chart_elbow);
      return extension_on(task);
    }
    solved = JointExtensionProblem::choose_solved(chain, position_rows(task.space), h.q, h.size);
    solved_code = 0.0;
    for (int j : solved) solved_code = 10 * solved_code + j + 1;
    return extension_on(task);
  };
  std::unique_ptr<ChainGlobalProblem> extension = extension_of_run();
  const AlphaBasis basis = cubic_spline_basis(task.path.size(), task.path.dt(), task.path.path().duration(),
                                              static_cast<int>(g.knots), g.end == EndState::rest);
  const int K = basis.coefficients, r = extension->coordinates();
  std::vector<double> first(r);
  const auto fitted = [&]() {  // the coefficients of the run in h
    const std::size_t count = std::min<std::size_t>(static_cast<std::size_t>(h.size), extension->samples());
    std::vector<std::vector<double>> series(r, std::vector<double>(count));
    for (std::size_t i = 0; i < count; ++i) {
      double z[kMaxJoints];
      Elbow e;
      extension->coordinates_of(i, h.q.col(static_cast<Eigen::Index>(i)), z, e);
      for (int k = 0; k < r; ++k)
        series[k][i] = i == 0 ? z[k] : series[k][i - 1] + std::remainder(z[k] - series[k][i - 1], 2.0 * std::numbers::pi);
    }
    std::vector<double> c(static_cast<std::size_t>(K) * r);
    for (int k = 0; k < r; ++k) {
      const std::vector<double> ck = fit_basis(basis, series[k].data(), count);
      std::copy(ck.begin(), ck.end(), c.begin() + k * K);
      first[k] = series[k][0];
    }
    return c;
  };
  const auto usable = [&](const std::vector<double>& cs) {
    for (double v : cs)
      if (!std::isfinite(v)) return false;
    return extension->worst_violation(basis, cs.data()) == 0.0;
  };
  std::vector<double> c = fitted();
  if (g.start == GlobalStart::random) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(g.start_seed));
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    for (int k = 0; k < r; ++k)
      for (int j = 0; j < K; ++j) c[k * K + j] = first[k] + u(rng);
  } else if (!usable(c)) {
    // a local run far off its path can leave the chart (or the solved joints' reach) once put on the
    // path: the other local method's run, when it stays on it
    const std::vector<double> keep = c, keep_first = first;
    const double keep_code = solved_code;
    const Elbow keep_elbow = chart_elbow;
    const std::vector<int> keep_solved = solved;
    const StartMethod other = g.start_method == StartMethod::local_unweighted ? StartMethod::local_weighted
                                                                              : StartMethod::local_unweighted;
    local_run(other);
    std::unique_ptr<ChainGlobalProblem> kept = std::move(extension);
    if (h.size > 0) extension = extension_of_run(), c = fitted();
    if (h.size == 0 || !usable(c)) {
      extension = std::move(kept), c = keep, first = keep_first, solved_code = keep_code;
      chart_elbow = keep_elbow, solved = keep_solved;
    }
  }
  const ChainGlobalProblem& problem = *extension;
  for (double v : c)  // a local run that diverged at both methods: nothing to start from
    if (!std::isfinite(v)) return not_simulated(RunStatus::infeasible, n);
  const bool fixed = g.posture == StartPosture::fixed;
  if (fixed)
    for (int k = 0; k < r; ++k) c[k * K] = first[k];
  // the free coefficients: all, or all but each coordinate's first (its value at the start)
  std::vector<int> free;
  for (int k = 0; k < r; ++k)
    for (int j = fixed ? 1 : 0; j < K; ++j) free.push_back(k * K + j);
  const double bound = 4.0 * std::numbers::pi + std::ranges::max(c, {}, [](double v) { return std::abs(v); });
  std::vector<double> x(free.size()), full = c, grad(c.size());
  for (std::size_t m = 0; m < free.size(); ++m) x[m] = c[free[m]];
  long evaluations = 0;
  const auto at = [&](const double* xs) {
    for (std::size_t m = 0; m < free.size(); ++m) full[free[m]] = xs[m];
    return full.data();
  };
  const double start_f = problem.objective(basis, c.data(), g.objective, nullptr);
  // the problem the optimiser solves: the run's grid first, a finer one when the run departs between
  // its samples (the spline's coefficients are functions of time: the same on every grid)
  const ChainGlobalProblem* solving = &problem;
  const AlphaBasis* solving_basis = &basis;
  // the robot's limits, one constraint per window of samples (as many windows as knots) and limited quantity
  LimitConstraints limits = LimitConstraints::of(chain, problem.samples(), static_cast<int>(g.knots));
  unsigned rows = limits.count();
  // one pass gives the objective, the constraints and both gradients: NLopt asks for them in turn at each point
  std::vector<double> cached_x, con(rows), jac(static_cast<std::size_t>(rows) * c.size());
  double cached_f = 0.0;
  // the limits the objective evaluates: none, as constraints (limits), or as a penalty (penalised)
  LimitConstraints penalised;
  const LimitConstraints* bound_by = nullptr;
  const auto evaluate = [&](const double* xs) {
    if (!cached_x.empty() && std::equal(cached_x.begin(), cached_x.end(), xs)) return;
    cached_f = solving->objective(*solving_basis, at(xs), g.objective, grad.data(), bound_by, con.data(), jac.data());
    cached_x.assign(xs, xs + free.size());
  };
  const auto bind = [&](const LimitConstraints* by) { bound_by = by, cached_x.clear(); };
  SlsqpSpec spec;
  spec.bound = bound;
  spec.tolerance = g.tolerance;
  spec.f = [&](const double* xs, double* gx) {  // (NLopt's count, as max_evaluations counts)
    ++evaluations;
    evaluate(xs);
    if (gx)
      for (std::size_t m = 0; m < free.size(); ++m) gx[m] = grad[free[m]];
    return cached_f;
  };
  spec.con = [&](const double* xs, double* cs, double* jx) {
    evaluate(xs);
    std::copy(con.begin(), con.end(), cs);
    if (jx)
      for (unsigned row = 0; row < rows; ++row)
        for (std::size_t m = 0; m < free.size(); ++m) jx[row * free.size() + m] = jac[row * c.size() + free[m]];
  };
  // whether a step from x along the objective's steepest descent (over the free coefficients, each
  // step halving the last, the first moving a coefficient by kFirstStep) lowers the objective by
  // more than the tolerance without leaving the limits further; x moves to the first that does. A
  // point where no limit binds and the gradient is not zero fails it (SLSQP's restarts can end at one)
  const auto descends = [&]() {
    evaluate(x.data());
    const double f_end = cached_f, worst_end = *std::ranges::max_element(con);
    std::vector<double> d(free.size()), y(free.size());
    double largest = 0.0;
    for (std::size_t m = 0; m < free.size(); ++m) d[m] = -grad[free[m]], largest = std::max(largest, std::abs(d[m]));
    if (!(largest > 0.0) || !std::isfinite(largest)) return false;
    for (int k = 0; k < kDescentSteps; ++k) {
      const double t = kFirstStep / largest * std::ldexp(1.0, -k);
      for (std::size_t m = 0; m < free.size(); ++m) y[m] = std::clamp(x[m] + t * d[m], -bound, bound);
      ++evaluations;
      evaluate(y.data());
      if (f_end - cached_f > g.tolerance * std::abs(f_end) && *std::ranges::max_element(con) <= std::max(worst_end, 0.0)) {
        x = y;
        return true;
      }
    }
    return false;
  };
  // the first weight of the limits' penalty (each sample's excess over 1 - margin, squared), from x,
  // the unconstrained optimum: kFirstPenalty times the objective there over the penalty there at
  // weight 1, taken within [1e-12, 1] (1: an optimum far beyond the limits; 1e-12: excess only at
  // samples off the extension, which the penalty leaves to the objective's own floor)
  const auto first_penalty = [&]() {
    bind(nullptr);
    evaluate(x.data());
    const double f_x = cached_f;
    penalised = limits;
    penalised.penalty = 1.0;
    bind(&penalised);
    evaluate(x.data());
    return kFirstPenalty * std::max(std::abs(f_x), 1e-12) / std::clamp(cached_f - f_x, 1e-12, 1.0);
  };
  // the penalty continuation from x: the weight grows tenfold from first, each SLSQP solve from the
  // last one's end (a level SLSQP ends short of its tolerance leaves its best point to the next),
  // until the end keeps every limit within the margin but kPenaltyExcess of it (true; status: the
  // last solve's). False when a level leaves more than kPenaltyStall of the last one's excess, the
  // weight reaches kPenaltyGrowth times the first, or the phase's budget runs out
  const auto penalty = [&](double first, RunStatus& status) {
    const long begun = evaluations;
    penalised = limits;
    double last = std::numeric_limits<double>::infinity();  // the last level's largest constraint
    for (double mu = first; mu <= first * kPenaltyGrowth; mu *= kPenaltyStep) {
      const long left = g.max_evaluations - (evaluations - begun);
      if (left <= 0) return status = RunStatus::max_evaluations, false;
      penalised.penalty = mu;
      bind(&penalised);
      spec.max_evaluations = left;
      status = minimise_slsqp(spec, x);
      bind(&limits);
      if (status == RunStatus::interrupted || status == RunStatus::max_evaluations) return false;
      evaluate(x.data());
      const double worst = *std::ranges::max_element(con);
      if (worst <= kPenaltyExcess * limits.margin) return true;
      if (!(worst <= kPenaltyStall * last)) return status = RunStatus::not_converged, false;
      last = worst;
    }
    return false;
  };
  // without the limits first; when the optimum leaves them, the limits as a penalty from there, and
  // when that does not end within them (an optimum far beyond them, near a singularity of the
  // extension), from the start; when neither does, again from the start with the limits as
  // constraints, one per window of samples and limited quantity. Each phase has the whole budget.
  const auto solve = [&](std::vector<double> from) {
    bind(nullptr);
    spec.constraints = 0;
    spec.max_evaluations = g.max_evaluations;
    x = from;
    RunStatus status = minimise_slsqp(spec, x);
    if (status == RunStatus::interrupted || status == RunStatus::max_evaluations || rows == 0) return status;
    bind(&limits);
    evaluate(x.data());
    if (std::ranges::all_of(con, [](double v) { return v <= 0.0; })) return status;
    const double first = first_penalty();
    const std::vector<double> unconstrained = x;
    for (const std::vector<double>* origin : std::array<const std::vector<double>*, 2>{&unconstrained, &from}) {
      x = *origin;
      if (penalty(first, status)) {
        if (status == RunStatus::ok && descends()) status = RunStatus::not_converged;
        return status;
      }
      if (status == RunStatus::interrupted) return status;
    }
    const long begun = evaluations;
    bind(&limits);
    spec.constraints = rows;
    spec.max_evaluations = g.max_evaluations;
    x = from;
    status = minimise_slsqp(spec, x);
    // SLSQP can stall on these constraints (their gradients jump where a window's largest sample
    // changes, which spoils its quasi-Newton model): it is restarted from its end with a fresh
    // model while a restart lowers the objective by more than the tolerance within the limits;
    // a run whose last restart still did is not_converged
    for (int restart = 0; status == RunStatus::ok; ++restart) {
      const long left = g.max_evaluations - (evaluations - begun);
      if (left <= 0) break;
      evaluate(x.data());
      const double f_end = cached_f, worst_end = *std::ranges::max_element(con);
      std::vector<double> y = x;
      spec.max_evaluations = left;
      const RunStatus again = minimise_slsqp(spec, y);
      if (again == RunStatus::interrupted) return again;
      evaluate(y.data());
      const double worst = *std::ranges::max_element(con);
      if (!(f_end - cached_f > g.tolerance * std::abs(f_end)) || !(worst <= std::max(worst_end, 0.0))) break;
      x = y, status = again;
      if (restart + 1 == kMaxRestarts) status = RunStatus::not_converged;
    }
    if (status == RunStatus::ok && descends()) status = RunStatus::not_converged;
    return status;
  };
  const std::vector<double> x_start = x;
  RunStatus outcome = solve(x_start);
  if (outcome == RunStatus::interrupted) return not_simulated(outcome, n);
  std::vector<double> best(at(x.data()), at(x.data()) + c.size());
  TrajectoryMetrics m = problem.measure(basis, best.data(), q_start, o, history);
  // the same trajectory on the grid of step h (figures only)
  const auto basis_on = [&](const ChainTask& t) {
    return cubic_spline_basis(t.path.size(), t.path.dt(), t.path.path().duration(), static_cast<int>(g.knots),
                              g.end == EndState::rest);
  };
  const auto measure_at = [&](double h) {
    const ChainTask fine(task.space, task.path.path(), h);
    const AlphaBasis fb = basis_on(fine);
    TrajectoryOptions fo = o;
    fo.dt = h;
    return extension_on(fine)->measure(fb, best.data(), q_start, fo, nullptr);
  };
  const int factor = static_cast<int>(g.verify_factor);
  m.dense = verify_between_samples(m, o.dt, factor, o.tracking_bound, measure_at);
  // while the run departs between its samples, the optimiser solves again from its start on a grid
  // verify_factor times finer (the spline's coefficients are functions of time: the same on every grid)
  double step = o.dt;
  std::optional<ChainTask> fine_task;
  std::optional<AlphaBasis> fine_basis;
  std::unique_ptr<ChainGlobalProblem> fine_problem;
  for (int level = 1; level <= g.refinements && m.dense.departure > g.verify_tolerance;
       ++level) {
    step = o.dt / std::pow(static_cast<double>(factor), level);
    fine_problem.reset();
    fine_task.emplace(task.space, task.path.path(), step);
    fine_basis.emplace(basis_on(*fine_task));
    fine_problem = extension_on(*fine_task);
    solving = fine_problem.get();
    solving_basis = &*fine_basis;
    limits = LimitConstraints::of(chain, solving->samples(), static_cast<int>(g.knots));
    outcome = solve(x_start);
    if (outcome == RunStatus::interrupted) return not_simulated(outcome, n);
    best.assign(at(x.data()), at(x.data()) + c.size());
    m = problem.measure(basis, best.data(), q_start, o, history);
    m.dense = verify_between_samples(m, o.dt, factor, o.tracking_bound, measure_at);
  }
  if (coefficients) *coefficients = best;
  const bool departs = factor > 1 && !(m.dense.departure <= g.verify_tolerance);
  if (m.status == RunStatus::ok) m.status = departs ? RunStatus::undersampled : outcome;
  m.opt_objective = solving->objective(*solving_basis, best.data(), g.objective, grad.data(), rows ? &limits : nullptr,
                                       con.data(), jac.data());
  // stationarity: the gradient over the free coefficients not held by their box bound, with the limit
  // constraints within 1e-4 of their bound as active ones (the KKT residual; without any, the
  // projected gradient's norm)
  std::vector<double> g_kept, jac_active;
  std::vector<std::size_t> kept;
  for (std::size_t v = 0; v < free.size(); ++v) {
    const int idx = free[v];
    const bool at_lower = best[idx] <= -bound && grad[idx] > 0, at_upper = best[idx] >= bound && grad[idx] < 0;
    if (!at_lower && !at_upper) kept.push_back(v), g_kept.push_back(grad[idx]);
  }
  std::size_t active = 0;
  for (unsigned row = 0; row < rows; ++row)
    if (con[row] > -1e-4) {
      ++active;
      for (std::size_t v : kept) jac_active.push_back(jac[row * c.size() + static_cast<std::size_t>(free[v])]);
    }
  m.opt_gradient_norm = kkt_residual(g_kept, jac_active, active);
  m.opt_dt = step;
  m.opt_solved_joints = chart ? std::numeric_limits<double>::quiet_NaN() : solved_code;
  if (rows > 0) m.opt_active_limits = static_cast<double>(active);
  m.opt_start_objective = start_f;
  m.opt_evaluations = static_cast<double>(evaluations);
  return m;
}

}  // namespace ks
