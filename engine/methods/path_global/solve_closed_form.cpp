// solve_global_spline (methods/path_global/solve_closed_form.hpp): the start, the SLSQP solve and the final measure.
#include "methods/path_global/solve_closed_form.hpp"

#include <nlopt.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/slsqp.hpp"
#include "methods/path_global/closed_form.hpp"
#include "methods/path_global/verify.hpp"

namespace ks {
namespace {

constexpr double kPi = std::numbers::pi;

/// The chart coordinates of tip angles alpha[i] on branches elbow[i] (sample i), unwrapped: the
/// coordinate moves by less than pi between samples.
std::vector<double> coordinates(const PathGlobalProblem& problem, const double* alpha, const double* theta2,
                                std::size_t count, Elbow elbow) {
  std::vector<double> x(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Elbow e = theta2 ? (std::sin(theta2[i]) >= 0.0 ? Elbow::positive : Elbow::negative) : elbow;
    x[i] = problem.coordinate(i, alpha[i], e);
    if (i > 0) x[i] = x[i - 1] + std::remainder(x[i] - x[i - 1], 2.0 * kPi);
  }
  return x;
}

/// The coefficients the optimiser starts from (before the start posture is imposed on a fixed start).
std::vector<double> start_coefficients(const PlanarArm3& arm, const PathGlobalProblem& problem,
                                       const TrajectoryOptions& o, const AlphaBasis& basis, bool& reachable) {
  const SampledPath& path = problem.path();
  const PathGlobalOptions& g = o.global;
  reachable = true;
  switch (g.start) {
    case GlobalStart::local: {
      TrajectoryOptions lo = o;
      lo.method = g.start_method == StartMethod::local_unweighted ? TrajectoryMethod::local_unweighted
                                                                 : TrajectoryMethod::local_weighted;
      lo.on_violation = OnViolation::ignore;
      TrajectoryHistory h;
      h.stride = 1;
      const TrajectoryMetrics m = simulate(arm, path, lo, &h);
      if (m.status == RunStatus::unreachable_start || h.size == 0) {
        reachable = false;
        return std::vector<double>(basis.coefficients, o.alpha1A);
      }
      const std::size_t count = std::min<std::size_t>(static_cast<std::size_t>(h.size), path.size());
      const Eigen::VectorXd theta2 = h.q.row(1).head(static_cast<Eigen::Index>(count)).transpose();
      const std::vector<double> x = coordinates(problem, h.alpha.data(), theta2.data(), count, o.elbow);
      return fit_basis(basis, x.data(), count);
    }
    case GlobalStart::vertex: {
      const AlphaBasis v = vertex_quintic_basis(path);
      std::vector<double> c{o.alpha1A};
      c.insert(c.end(), o.vertex_alpha.begin(), o.vertex_alpha.end());
      c.resize(v.coefficients, c.back());
      std::vector<double> alpha(path.size());
      for (std::size_t i = 0; i < path.size(); ++i) {
        double ad, add;
        v.at(i, c.data(), alpha[i], ad, add);
      }
      const std::vector<double> x = coordinates(problem, alpha.data(), nullptr, alpha.size(), o.elbow);
      return fit_basis(basis, x.data(), x.size());
    }
    case GlobalStart::random: {
      std::mt19937_64 rng(static_cast<std::uint64_t>(g.start_seed));
      std::uniform_real_distribution<double> u(-0.5, 0.5);
      std::vector<double> c(basis.coefficients);
      const double x0 = problem.coordinate(0, o.alpha1A, o.elbow);
      for (double& x : c) x = x0 + u(rng);
      return c;
    }
  }
  return std::vector<double>(basis.coefficients, problem.coordinate(0, o.alpha1A, o.elbow));
}

/// The optimiser's view: the free coefficients (all, or all but alpha at the start) as x.
struct Solve {
  const PathGlobalProblem* problem;
  const AlphaBasis* basis;
  GlobalObjective objective;
  std::vector<double> c;  // all coefficients; the free ones from `first`
  int first = 0;
  long evaluations = 0;
  std::vector<double> grad, jac;

  const double* coefficients(const double* x) {
    std::copy(x, x + (c.size() - first), c.begin() + first);
    return c.data();
  }
  double objective_at(const double* x, double* g) {
    ++evaluations;
    const double f = problem->objective(*basis, coefficients(x), objective, g ? grad.data() : nullptr);
    if (g) std::copy(grad.begin() + first, grad.end(), g);
    return f;
  }
  void reach_at(unsigned m, double* con, unsigned n, const double* x, double* g) {
    const std::size_t K = c.size();
    if (g) jac.resize(m * K);
    problem->reach(*basis, coefficients(x), con, g ? jac.data() : nullptr);
    if (!g) return;
    for (unsigned i = 0; i < m; ++i)
      std::copy(jac.begin() + i * K + first, jac.begin() + (i + 1) * K, g + std::size_t(i) * n);
  }
};

/// Feasibility restoration: the coefficients nearest (least squares) to the start's whose samples all
/// keep cos(theta2)^2 <= bound (SLSQP on the reach constraints); false when it finds none.
bool restore_reach(Solve& s, std::vector<double>& x, double bound) {
  struct Restore {
    Solve* s;
    std::vector<double> from;
    double bound;
  } r{&s, x, bound};
  nlopt::opt opt(nlopt::LD_SLSQP, static_cast<unsigned>(x.size()));
  opt.set_lower_bounds(-kPi);
  opt.set_upper_bounds(kPi);
  opt.set_xtol_abs(1e-10);
  opt.set_maxeval(500);
  opt.set_min_objective([](const std::vector<double>& x, std::vector<double>& g, void* data) {
    const auto& r = *static_cast<Restore*>(data);
    double f = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k) {
      f += (x[k] - r.from[k]) * (x[k] - r.from[k]);
      if (!g.empty()) g[k] = 2.0 * (x[k] - r.from[k]);
    }
    return f;
  }, &r);
  opt.add_inequality_mconstraint(
      [](unsigned m, double* con, unsigned n, const double* x, double* grad, void* data) {
        const auto& r = *static_cast<Restore*>(data);
        r.s->reach_at(m, con, n, x, grad);
        for (unsigned i = 0; i < m; ++i) con[i] += 1.0 - r.bound;
      },
      &r, std::vector<double>(s.problem->samples(), 0.0));
  try {
    double f = 0.0;
    opt.optimize(x, f);
  } catch (const std::exception&) {
  }
  std::vector<double> con(s.problem->samples());
  s.reach_at(static_cast<unsigned>(con.size()), con.data(), static_cast<unsigned>(x.size()), x.data(), nullptr);
  return *std::max_element(con.begin(), con.end()) <= 0.0;
}

}  // namespace

TrajectoryMetrics solve_global_spline(const PlanarArm3& arm, const SampledPath& path, const TrajectoryOptions& o,
                                      TrajectoryHistory* history, std::vector<double>* coefficients) {
  if (std::string why; !o.IsValid(&why)) throw std::invalid_argument("global_spline: " + why);
  if (o.method != TrajectoryMethod::global_spline) throw std::invalid_argument("global_spline: another method");
  if (path.dt() != o.dt) throw std::invalid_argument("global_spline: path sampled at another dt");
  const PathGlobalOptions& g = o.global;
  if (g.spline == AlphaSpline::cubic && g.extension == Extension::joints)
    throw std::invalid_argument("global_spline: the seed's closed-form arm takes the self_motion or alpha extension "
                                "(joints: the arm as a chain robot)");
  const AlphaBasis basis =
      g.spline == AlphaSpline::cubic ? cubic_spline_basis(path, static_cast<int>(g.knots), g.end == EndState::rest)
                                      : vertex_quintic_basis(path);
  const Extension extension = g.spline == AlphaSpline::cubic ? g.extension : Extension::alpha;
  const PathGlobalProblem problem(arm, path, o.elbow, o.singular_tolerance, extension);
  if (!problem.chart_defined()) return not_simulated(RunStatus::singular_extension, 3);
  if (!inverse_kinematics(arm, path.position(0), o.alpha1A, o.elbow)) return not_simulated(RunStatus::unreachable_start, 3);
  bool reachable = true;
  std::vector<double> c = start_coefficients(arm, problem, o, basis, reachable);
  if (!reachable) return not_simulated(RunStatus::unreachable_start, 3);
  const bool fixed = g.posture == StartPosture::fixed;
  // alpha within [-pi, pi] as the seed bounds it; psi may wind up to twice around the self-motion circle
  const double bound = extension == Extension::alpha ? kPi : 4.0 * kPi;
  for (double& x : c) x = std::clamp(x, -bound, bound);
  if (fixed) c[0] = problem.coordinate(0, o.alpha1A, o.elbow);

  Solve s{&problem, &basis, g.objective, c, fixed ? 1 : 0, 0, std::vector<double>(basis.coefficients), {}};
  const double start_f = problem.objective(basis, c.data(), g.objective, nullptr);
  std::vector<double> x(c.begin() + s.first, c.end());
  if (extension == Extension::alpha) {  // a start with every sample within reach, with a margin where the fixed start allows one
    std::vector<double> con(problem.samples());
    s.reach_at(static_cast<unsigned>(con.size()), con.data(), static_cast<unsigned>(x.size()), x.data(), nullptr);
    if (*std::max_element(con.begin(), con.end()) > 0.0) {
      const double bound = std::max(1.0 - 1e-3, con[0] + 1.0);
      if (!restore_reach(s, x, bound)) {
        TrajectoryMetrics m = problem.measure(basis, s.coefficients(x.data()), o, history);
        m.status = RunStatus::infeasible;
        m.opt_start_objective = start_f;
        m.opt_evaluations = static_cast<double>(s.evaluations);
        return m;
      }
    }
  }
  SlsqpSpec spec;
  spec.bound = bound;
  spec.tolerance = g.tolerance;
  spec.max_evaluations = g.max_evaluations;
  spec.f = [&s](const double* x, double* grad) { return s.objective_at(x, grad); };
  if (extension == Extension::alpha) {  // the self-motion chart reaches by construction
    spec.constraints = static_cast<unsigned>(problem.samples());
    spec.con = [&s, n = static_cast<unsigned>(x.size())](const double* x, double* con, double* jac) {
      s.reach_at(static_cast<unsigned>(s.problem->samples()), con, n, x, jac);
    };
  }
  const std::vector<double> x_start = x;
  RunStatus outcome = minimise_slsqp(spec, x);
  if (outcome == RunStatus::interrupted) return not_simulated(outcome, 3);
  std::vector<double> best(s.coefficients(x.data()), s.coefficients(x.data()) + basis.coefficients);
  TrajectoryMetrics m = problem.measure(basis, best.data(), o, history);
  const auto basis_on = [&](const SampledPath& p) {
    return g.spline == AlphaSpline::cubic ? cubic_spline_basis(p, static_cast<int>(g.knots), g.end == EndState::rest)
                                          : vertex_quintic_basis(p);
  };
  // the same trajectory on the grid of step h (figures only)
  const auto measure_at = [&](double h) {
    const SampledPath fine(path.path(), h);
    const AlphaBasis fb = basis_on(fine);
    const PathGlobalProblem fp(arm, fine, o.elbow, o.singular_tolerance, extension);
    if (!fp.chart_defined()) return not_simulated(RunStatus::singular_extension, 3);
    TrajectoryOptions fo = o;
    fo.dt = h;
    return fp.measure(fb, best.data(), fo, nullptr);
  };
  const int factor = static_cast<int>(g.verify_factor);
  m.dense = verify_between_samples(m, o.dt, factor, o.tracking_bound, measure_at);
  // while the run departs between its samples, the optimiser solves again from its start on a grid
  // verify_factor times finer (the trajectory's coefficients are functions of time: the same on every grid)
  double step = o.dt;
  std::optional<SampledPath> fine_path;
  std::optional<AlphaBasis> fine_basis;
  std::optional<PathGlobalProblem> fine_problem;
  for (int level = 1; level <= g.refinements && m.dense.departure > g.verify_tolerance;
       ++level) {
    step = o.dt / std::pow(static_cast<double>(factor), level);
    fine_problem.reset();
    fine_path.emplace(path.path(), step);
    fine_basis.emplace(basis_on(*fine_path));
    fine_problem.emplace(arm, *fine_path, o.elbow, o.singular_tolerance, extension);
    if (!fine_problem->chart_defined()) break;
    s.problem = &*fine_problem;
    s.basis = &*fine_basis;
    if (extension == Extension::alpha) spec.constraints = static_cast<unsigned>(fine_problem->samples());
    spec.max_evaluations = g.max_evaluations;  // each solve its budget
    x = x_start;
    outcome = minimise_slsqp(spec, x);
    if (outcome == RunStatus::interrupted) return not_simulated(outcome, 3);
    best.assign(s.coefficients(x.data()), s.coefficients(x.data()) + basis.coefficients);
    m = problem.measure(basis, best.data(), o, history);
    m.dense = verify_between_samples(m, o.dt, factor, o.tracking_bound, measure_at);
  }
  if (coefficients) *coefficients = best;
  const bool departs = factor > 1 && !(m.dense.departure <= g.verify_tolerance);
  if (m.status == RunStatus::ok) m.status = departs ? RunStatus::undersampled : outcome;
  // the projected gradient at the optimum, on the grid the optimiser last solved on: components
  // pushing against an active bound count 0
  std::vector<double> grad(basis.coefficients);
  m.opt_objective = s.problem->objective(*s.basis, best.data(), g.objective, grad.data());
  double norm = 0.0;
  for (int k = s.first; k < basis.coefficients; ++k) {
    const bool at_lower = best[k] <= -bound && grad[k] > 0, at_upper = best[k] >= bound && grad[k] < 0;
    if (!at_lower && !at_upper) norm = std::max(norm, std::abs(grad[k]));
  }
  m.opt_gradient_norm = norm;
  m.opt_start_objective = start_f;
  m.opt_evaluations = static_cast<double>(s.evaluations);
  m.opt_dt = step;
  return m;
}

}  // namespace ks
