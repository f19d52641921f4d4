// Optimisation pipelines over NLopt (see optimize.hpp).
#include "optimize/optimize.hpp"

#include <nlopt.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlopt.hpp>
#include <numeric>
#include <ostream>
#include <stdexcept>

namespace ks::opt {

namespace {
constexpr std::array<std::string_view, 9> kNames{"GN_ISRES", "GN_ESCH",   "GN_DIRECT_L", "GN_CRS2_LM",   "GN_MLSL",
                                                 "LN_BOBYQA", "LN_COBYLA", "LD_SLSQP",    "LN_NELDERMEAD"};
using Clock = std::chrono::steady_clock;

nlopt::algorithm nlopt_of(Algorithm a) {
  switch (a) {
    case Algorithm::GN_ISRES: return nlopt::GN_ISRES;
    case Algorithm::GN_ESCH: return nlopt::GN_ESCH;
    case Algorithm::GN_DIRECT_L: return nlopt::GN_DIRECT_L;
    case Algorithm::GN_CRS2_LM: return nlopt::GN_CRS2_LM;
    case Algorithm::GN_MLSL: return nlopt::GN_MLSL_LDS;  // low-discrepancy starts: deterministic given the seed
    case Algorithm::LN_BOBYQA: return nlopt::LN_BOBYQA;
    case Algorithm::LN_COBYLA: return nlopt::LN_COBYLA;
    case Algorithm::LD_SLSQP: return nlopt::LD_SLSQP;
    case Algorithm::LN_NELDERMEAD: return nlopt::LN_NELDERMEAD;
  }
  return nlopt::LN_BOBYQA;
}

std::string result_name(nlopt::result r) {
  const char* s = nlopt_result_to_string(static_cast<nlopt_result>(r));
  return s ? s : "UNKNOWN";
}

/// State of one NLopt run: records every evaluation, computes forward-difference gradients.
struct Runner {
  const Problem* problem = nullptr;
  std::vector<double> lower, upper;
  std::string stage;
  int start = -1;
  double fd_step = 1e-6;
  const std::atomic<bool>* stop = nullptr;
  std::vector<EvalRecord> records;

  double eval(const double* x, std::size_t n) {
    EvalRecord r;
    r.x.assign(x, x + n);
    Evaluation e = problem->objective(std::span<const double>(r.x));
    if (!std::isfinite(e.value)) e.value = std::numeric_limits<double>::max() / 4;  // never hand NaN to NLopt
    r.value = e.value;
    r.status = std::move(e.status);
    if (problem->constraint) r.constraint = problem->constraint(std::span<const double>(r.x));
    r.stage = stage;
    r.start = start;
    records.push_back(std::move(r));
    return records.back().value;
  }
  /// Forward differences of f (or of the constraint when `fn` is given) into grad; steps stay inside the bounds.
  template <class F>
  void gradient(const double* x, std::size_t n, double f0, double* grad, F&& f) {
    std::vector<double> xp(x, x + n);
    for (std::size_t i = 0; i < n; ++i) {
      double h = fd_step * (upper[i] - lower[i]);
      if (h <= 0) h = 1e-8;
      if (xp[i] + h > upper[i]) h = -h;
      const double keep = xp[i];
      xp[i] = keep + h;
      grad[i] = (f(xp.data()) - f0) / h;
      xp[i] = keep;
    }
  }
};

double objective_cb(unsigned n, const double* x, double* grad, void* data) {
  auto* r = static_cast<Runner*>(data);
  if (r->stop && r->stop->load()) throw nlopt::forced_stop();  // NLopt's wrapper ends optimize() with it
  const double f0 = r->eval(x, n);
  if (grad) r->gradient(x, n, f0, grad, [&](const double* xp) { return r->eval(xp, n); });
  return f0;
}

double constraint_cb(unsigned n, const double* x, double* grad, void* data) {
  auto* r = static_cast<Runner*>(data);
  auto c = [&](const double* xp) { return r->problem->constraint(std::span<const double>(xp, n)); };
  const double c0 = c(x);
  if (grad) r->gradient(x, n, c0, grad, c);
  return c0;
}

void apply_stopping(nlopt::opt& o, const StageOptions& s, std::size_t n, const std::vector<double>& lo,
                    const std::vector<double>& hi) {
  if (s.max_evals > 0) o.set_maxeval(s.max_evals);
  if (s.max_time_s > 0) o.set_maxtime(s.max_time_s);
  if (s.xtol_rel > 0) o.set_xtol_rel(s.xtol_rel);
  if (s.xtol_abs > 0) o.set_xtol_abs(std::vector<double>(n, s.xtol_abs));
  if (s.ftol_rel > 0) o.set_ftol_rel(s.ftol_rel);
  if (s.ftol_abs > 0) o.set_ftol_abs(s.ftol_abs);
  if (std::isfinite(s.stopval)) o.set_stopval(s.stopval);
  if (s.population > 0) o.set_population(static_cast<unsigned>(s.population));
  if (s.initial_step > 0 && !is_global(s.algorithm)) {
    std::vector<double> dx(n);
    for (std::size_t i = 0; i < n; ++i) dx[i] = s.initial_step * (hi[i] - lo[i]);
    o.set_initial_step(dx);
  }
}

struct StageRun {
  std::vector<EvalRecord> records;
  std::string result;
  std::vector<double> x;
  double value = std::numeric_limits<double>::infinity();
};

/// One NLopt run of `s` from x0. `local_for_mlsl`: the local algorithm MLSL uses.
StageRun run_stage(const Problem& p, const StageOptions& s, const std::vector<double>& x0, const std::string& stage,
                   int start, ConstraintMode mode, const StageOptions* local_for_mlsl,
                   const std::atomic<bool>* stop) {
  const std::size_t n = p.variables.size();
  Runner r;
  r.stop = stop;
  r.problem = &p;
  r.stage = stage;
  r.start = start;
  r.fd_step = s.fd_step;
  for (const auto& v : p.variables) {
    r.lower.push_back(v.lower);
    r.upper.push_back(v.upper);
  }
  nlopt::opt o(nlopt_of(s.algorithm), static_cast<unsigned>(n));
  o.set_lower_bounds(r.lower);
  o.set_upper_bounds(r.upper);
  o.set_min_objective(objective_cb, &r);
  apply_stopping(o, s, n, r.lower, r.upper);
  if (p.constraint && mode == ConstraintMode::automatic && supports_constraint(s.algorithm))
    o.add_inequality_constraint(constraint_cb, &r, 0.0);
  if (s.algorithm == Algorithm::GN_MLSL) {
    StageOptions ls = local_for_mlsl ? *local_for_mlsl : StageOptions{};
    if (is_global(ls.algorithm)) ls.algorithm = Algorithm::LN_BOBYQA;
    if (ls.xtol_rel <= 0 && ls.ftol_rel <= 0 && ls.ftol_abs <= 0 && ls.xtol_abs <= 0) ls.xtol_rel = 1e-6;
    nlopt::opt lo(nlopt_of(ls.algorithm), static_cast<unsigned>(n));
    ls.max_evals = ls.max_evals > 0 ? ls.max_evals : 200;
    ls.max_time_s = 0;
    apply_stopping(lo, ls, n, r.lower, r.upper);
    o.set_local_optimizer(lo);
  }
  std::vector<double> x = x0;
  StageRun out;
  double f = std::numeric_limits<double>::infinity();
  try {
    out.result = result_name(o.optimize(x, f));
  } catch (const nlopt::roundoff_limited&) {
    out.result = "ROUNDOFF_LIMITED";
  } catch (const nlopt::forced_stop&) {
    out.result = "FORCED_STOP";
  } catch (const std::bad_alloc&) {
    out.result = "OUT_OF_MEMORY";
  } catch (const std::invalid_argument& e) {
    out.result = std::string("INVALID_ARGS: ") + e.what();
  } catch (const std::exception& e) {
    out.result = std::string("FAILURE: ") + e.what();
  }
  out.records = std::move(r.records);
  // The stage's answer: its best recorded evaluation (NLopt's x may be a constraint-violating point).
  for (const auto& e : out.records)
    if (e.value < out.value) {
      out.value = e.value;
      out.x = e.x;
    }
  if (out.x.empty()) out.x = x0;
  return out;
}

StageResult summarise(const std::string& name, const std::string& algorithm, const std::vector<EvalRecord>& recs,
                      std::size_t first, double wall) {
  StageResult s;
  s.name = name;
  s.algorithm = algorithm;
  s.wall_time_s = wall;
  s.evaluations = recs.size() - first;
  for (std::size_t i = first; i < recs.size(); ++i)
    if (recs[i].value < s.best_value) {
      s.best_value = recs[i].value;
      s.best_x = recs[i].x;
      s.best_status = recs[i].status;
    }
  return s;
}

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

std::string_view to_string(Algorithm a) { return kNames[static_cast<std::size_t>(a)]; }
bool parse(std::string_view name, Algorithm& out) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (kNames[i] == name) {
      out = static_cast<Algorithm>(i);
      return true;
    }
  return false;
}
bool is_global(Algorithm a) { return to_string(a).starts_with("GN_"); }
bool supports_constraint(Algorithm a) {
  return a == Algorithm::GN_ISRES || a == Algorithm::LN_COBYLA || a == Algorithm::LD_SLSQP;
}
std::span<const std::string_view> algorithm_names() { return kNames; }

StageOptions seed_global() {
  StageOptions s;
  s.algorithm = Algorithm::GN_ESCH;
  s.population = 50;
  s.max_evals = 50 * 100;
  s.ftol_abs = 1e-6;
  return s;
}
StageOptions seed_local() {
  StageOptions s;
  s.algorithm = Algorithm::LD_SLSQP;
  s.max_evals = 400;
  s.xtol_rel = 1e-8;
  s.ftol_abs = 1e-9;
  return s;
}

Summary optimize(const Problem& p, const PipelineOptions& o) {
  const auto t_all = Clock::now();
  const std::size_t n = p.variables.size();
  if (n == 0) throw std::invalid_argument("optimize: no variables");
  if (!p.objective) throw std::invalid_argument("optimize: no objective");
  for (const auto& v : p.variables)
    if (!(std::isfinite(v.lower) && std::isfinite(v.upper) && v.lower < v.upper))
      throw std::invalid_argument("optimize: variable " + v.name + " needs finite bounds lower < upper");
  if (o.global && !is_global(o.global->algorithm))
    throw std::invalid_argument("optimize: " + std::string(to_string(o.global->algorithm)) + " is not a global algorithm");
  if (o.local && is_global(o.local->algorithm))
    throw std::invalid_argument("optimize: " + std::string(to_string(o.local->algorithm)) + " is not a local algorithm");
  for (const auto& s : o.starts)
    if (s.x.size() != n) throw std::invalid_argument("optimize: a start has the wrong number of coordinates");

  Summary out;
  for (const auto& v : p.variables) {
    out.variables.push_back(v.name);
    out.units.push_back(v.unit);
  }
  auto clamp_x = [&](std::vector<double> x) {
    for (std::size_t i = 0; i < n; ++i) x[i] = std::clamp(x[i], p.variables[i].lower, p.variables[i].upper);
    return x;
  };
  std::vector<double> x_default(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& v = p.variables[i];
    x_default[i] = std::isnan(v.start) ? 0.5 * (v.lower + v.upper) : std::clamp(v.start, v.lower, v.upper);
  }

  // Stage "sweep": the given starts with known values (recorded, not re-evaluated).
  if (!o.starts.empty()) {
    const std::size_t first = out.evaluations.size();
    for (const auto& s : o.starts) {
      EvalRecord r;
      r.x = s.x;
      r.value = s.value;
      r.stage = "sweep";
      r.status = s.status;
      r.start = s.run;
      if (p.constraint) r.constraint = p.constraint(std::span<const double>(r.x));
      out.evaluations.push_back(std::move(r));
    }
    out.stages.push_back(summarise("sweep", "", out.evaluations, first, 0.0));
    out.stages.back().result = "GIVEN";
  }

  // Global stage: serial, in this thread, after seeding NLopt's (thread-local) generator.
  std::vector<std::vector<double>> local_starts;
  if (o.global) {
    const auto t0 = Clock::now();
    const int islands = std::max(1, o.global->islands);
    std::vector<StageRun> runs(static_cast<std::size_t>(islands));
    auto island = [&](std::size_t i) {
      nlopt::srand(static_cast<unsigned long>(o.seed + i));  // NLopt's generator is thread-local
      runs[i] = run_stage(p, *o.global, x_default, "global", -1, o.constraint, o.local ? &*o.local : nullptr, o.stop);
    };
    if (islands == 1) {
      island(0);
    } else {
      tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);
      arena.execute([&] { tbb::parallel_for(std::size_t(0), runs.size(), island); });
    }
    const std::size_t first = out.evaluations.size();
    std::size_t best_island = 0;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      for (auto& e : runs[i].records) out.evaluations.push_back(std::move(e));
      if (runs[i].value < runs[best_island].value) best_island = i;
    }
    out.stages.push_back(summarise("global", std::string(to_string(o.global->algorithm)), out.evaluations, first,
                                   seconds_since(t0)));
    out.stages.back().result = runs[best_island].result;
    // The best distinct points of the global stage.
    std::vector<std::size_t> idx(out.evaluations.size() - first);
    std::iota(idx.begin(), idx.end(), first);
    std::stable_sort(idx.begin(), idx.end(),
                     [&](std::size_t a, std::size_t b) { return out.evaluations[a].value < out.evaluations[b].value; });
    for (std::size_t i : idx) {
      if (static_cast<int>(local_starts.size()) >= std::max(0, o.local_starts)) break;
      const auto& x = out.evaluations[i].x;
      bool far = true;
      for (const auto& y : local_starts) {
        double d = 0;
        for (std::size_t j = 0; j < n; ++j)
          d = std::max(d, std::abs(x[j] - y[j]) / (p.variables[j].upper - p.variables[j].lower));
        if (d <= o.distinct) far = false;
      }
      if (far) local_starts.push_back(x);
    }
  }
  for (const auto& s : o.starts) local_starts.push_back(clamp_x(s.x));
  if (local_starts.empty()) local_starts.push_back(x_default);

  // Local stage: one polish per start, concurrently; merged in start order.
  const auto stopped = [&] { return o.stop && o.stop->load(); };
  if (o.local && !stopped()) {
    const auto t0 = Clock::now();
    std::vector<StageRun> runs(local_starts.size());
    auto body = [&](std::size_t i) {
      runs[i] = run_stage(p, *o.local, local_starts[i], "local", static_cast<int>(i), o.constraint, nullptr, o.stop);
    };
    tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);
    arena.execute([&] {
      tbb::parallel_for(std::size_t(0), runs.size(), [&](std::size_t i) { body(i); });
    });
    const std::size_t first = out.evaluations.size();
    std::size_t best_run = 0;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      for (auto& e : runs[i].records) out.evaluations.push_back(std::move(e));
      out.local_from.push_back(local_starts[i]);
      out.local_to.push_back(runs[i].x);
      out.local_values.push_back(runs[i].value);
      if (runs[i].value < runs[best_run].value) best_run = i;
    }
    out.stages.push_back(summarise("local", std::string(to_string(o.local->algorithm)), out.evaluations, first,
                                   seconds_since(t0)));
    out.stages.back().result = runs.empty() ? "" : runs[best_run].result;
  }

  for (const auto& e : out.evaluations)
    if (e.value < out.best_value) {
      out.best_value = e.value;
      out.best_x = e.x;
      out.best_status = e.status;
      out.best_stage = e.stage;
    }
  out.wall_time_s = seconds_since(t_all);
  out.stopped = stopped();
  return out;
}

void Summary::print(std::ostream& os) const {
  char line[256];
  for (const auto& s : stages) {
    std::snprintf(line, sizeof line, "  %-6s %-13s %6zu evals %8.3f s  best %.6g  (%s)\n", s.name.c_str(),
                  s.algorithm.empty() ? "-" : s.algorithm.c_str(), s.evaluations, s.wall_time_s, s.best_value,
                  s.result.c_str());
    os << line;
  }
  os << "  best " << best_value << " [" << best_status << ", " << best_stage << "] at";
  for (std::size_t i = 0; i < best_x.size(); ++i) {
    os << ' ';
    if (i < variables.size()) os << variables[i];
    else os << 'x' << i;
    os << '=' << best_x[i];
    if (i < units.size() && !units[i].empty()) os << ' ' << units[i];
  }
  os << "  (" << evaluations.size() << " evaluations, " << wall_time_s << " s)\n";
}

}  // namespace ks::opt
