#pragma once
// Optimisation pipelines over NLopt: a global stage, then a local stage started from one or
// more points (the global stage's best distinct points and/or given starts, e.g. a landscape's best
// cells), every evaluation recorded. Study-free and HDF5-free: a Problem is variables with bounds
// plus an objective callable; the result is a Summary.
//
// Determinism: the global stage runs in the calling thread after nlopt::srand(seed); the local
// polishes are deterministic algorithms, run concurrently (TBB, `threads`) and merged in start order.
// So a Summary (except wall times) does not depend on the thread count.
#include <atomic>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace ks::opt {

/// The NLopt algorithms offered (names as in NLopt, used in study files and HDF5).
enum class Algorithm {
  GN_ISRES,     ///< global, evolution strategy with stochastic ranking (handles the constraint)
  GN_ESCH,      ///< global, evolutionary (the closest to the seed's MATLAB ga)
  GN_DIRECT_L,  ///< global, deterministic DIRECT-L (locally biased)
  GN_CRS2_LM,   ///< global, controlled random search with local mutation
  GN_MLSL,      ///< global, multi-level single linkage (random starts + the local stage's algorithm)
  LN_BOBYQA,    ///< local, derivative-free quadratic models (bound constraints only)
  LN_COBYLA,    ///< local, derivative-free linear approximations (handles the constraint)
  LD_SLSQP,     ///< local, SQP (as the seed's fmincon), finite-difference gradients (handles the constraint)
  LN_NELDERMEAD,  ///< local, simplex
};
std::string_view to_string(Algorithm a);
bool parse(std::string_view name, Algorithm& out);
bool is_global(Algorithm a);
/// True when NLopt accepts an inequality constraint for this algorithm.
bool supports_constraint(Algorithm a);
/// Every algorithm name, global ones first.
std::span<const std::string_view> algorithm_names();

/// One stage's algorithm and stopping rules. A rule <= 0 is off (NLopt's convention).
struct StageOptions {
  Algorithm algorithm = Algorithm::LN_BOBYQA;
  int max_evals = 0;          ///< objective evaluations (finite-difference ones included); 0: no limit
  double max_time_s = 0.0;    ///< wall time of the stage [s]; 0: no limit
  double xtol_rel = 0.0;      ///< relative change of x
  double xtol_abs = 0.0;      ///< absolute change of x (every variable, in its stored unit)
  double ftol_rel = 0.0;      ///< relative change of the objective
  double ftol_abs = 0.0;      ///< absolute change of the objective
  double stopval = -std::numeric_limits<double>::infinity();  ///< stop when the objective reaches this
  int population = 0;         ///< GN_ESCH / GN_ISRES / GN_CRS2_LM / GN_MLSL population (0: NLopt's default)
  double fd_step = 1e-6;      ///< LD_SLSQP: forward-difference step, relative to the variable's range
  double initial_step = 0.0;  ///< local derivative-free stages: initial step, relative to the range (0: NLopt's)
  /// Global stage: independent runs ("islands"), each with these settings (max_evals per island) and
  /// nlopt::srand(seed + i), run concurrently and merged in island order. NLopt evaluates serially
  /// within a run, so this is how a global stage uses several threads. 1: one run (the seed's way).
  int islands = 1;
};

/// Presets for the two stages. seed_global(): the seed's ga (population 50, <= 100 generations, stop
/// at an objective change < 1e-6) as GN_ESCH; seed_local(): the seed's fmincon SQP (<= 400 iterations).
StageOptions seed_global();
StageOptions seed_local();

/// A design variable: bounds and a start (for a local-only pipeline), in stored units (rad, ...).
struct Variable {
  std::string name, unit;
  double lower = 0.0, upper = 1.0;
  double start = std::numeric_limits<double>::quiet_NaN();  ///< NaN: the middle of the bounds
};

/// What an objective evaluation returns. `value` must be finite and deterministic: an infeasible or
/// failed point returns a deterministic penalty (never a random one), larger than any feasible value.
struct Evaluation {
  double value = 0.0;
  std::string status = "ok";  ///< the run's status ("ok", "unreachable_start", "diverged", ...)
};

struct Problem {
  std::vector<Variable> variables;
  /// f(x); called concurrently from several threads during the local stage (must be thread-safe).
  std::function<Evaluation(std::span<const double> x)> objective;
  /// Optional inequality constraint c(x) <= 0 (feasible), cheap; e.g. the start's reach margin
  /// |cos theta2| - 1. Given to NLopt by the algorithms that support it (see ConstraintMode).
  std::function<double(std::span<const double> x)> constraint;
};

enum class ConstraintMode {
  automatic,  ///< an NLopt constraint where the algorithm supports one; the objective's penalty elsewhere
  penalty,    ///< never an NLopt constraint: the objective's deterministic penalty only
};

/// A start of the local stage given from outside (e.g. a landscape cell), with its known value.
struct Start {
  std::vector<double> x;
  double value = std::numeric_limits<double>::quiet_NaN();  ///< NaN: unknown
  std::string status = "ok";  ///< the cell's run status
  std::int64_t run = -1;      ///< the cell's run id (recorded as the sweep evaluation's `start`)
};

struct PipelineOptions {
  std::optional<StageOptions> global;  ///< none: no global stage
  std::optional<StageOptions> local;   ///< none: no local stage
  /// The local stage starts from the best `local_starts` distinct points of the global stage (distinct:
  /// farther than `distinct` apart in range-normalised max norm) ...
  int local_starts = 1;
  double distinct = 1e-2;
  /// ... plus these (sweep then polish). With neither a global stage nor starts: from the variables' start.
  std::vector<Start> starts;
  int threads = 0;                 ///< local polishes in parallel (0: all cores)
  std::uint64_t seed = 42;         ///< nlopt::srand before the global stage
  ConstraintMode constraint = ConstraintMode::automatic;
  /// When set (e.g. by SIGINT), every running stage ends before its next evaluation (FORCED_STOP)
  /// and no later stage starts; the evaluations made so far are kept.
  const std::atomic<bool>* stop = nullptr;
};

/// One objective evaluation.
struct EvalRecord {
  std::vector<double> x;
  double value = 0.0;
  double constraint = std::numeric_limits<double>::quiet_NaN();  ///< c(x) when the problem has one
  std::string stage;   ///< "sweep", "global", "local"
  std::string status;  ///< the objective's status
  std::int64_t start = -1;  ///< local: index of the start; sweep: the cell's run id; global: -1
};

struct StageResult {
  std::string name;       ///< "sweep", "global", "local" (the local stage summarises all its starts)
  std::string algorithm;  ///< NLopt name ("" for sweep)
  std::string result;     ///< NLopt's result (e.g. "XTOL_REACHED", "MAXEVAL_REACHED"); several starts: the best one's
  double wall_time_s = 0.0;
  std::size_t evaluations = 0;
  double best_value = std::numeric_limits<double>::infinity();
  std::vector<double> best_x;
  std::string best_status;
};

struct Summary {
  std::vector<std::string> variables, units;
  std::vector<EvalRecord> evaluations;  ///< in stage order; local: start 0's, then start 1's, ...
  std::vector<StageResult> stages;      ///< in order run
  /// Per local start: where it started and ended.
  std::vector<std::vector<double>> local_from, local_to;
  std::vector<double> local_values;
  double best_value = std::numeric_limits<double>::infinity();
  std::vector<double> best_x;
  std::string best_status;
  std::string best_stage;
  double wall_time_s = 0.0;
  bool stopped = false;  ///< PipelineOptions::stop ended it early
  /// Human-readable: stages (algorithm, evaluations, time, best), the best point.
  void print(std::ostream& os) const;
};

/// Run the pipeline. Throws std::invalid_argument on a malformed problem (no variables, bad bounds, a
/// local algorithm in the global slot, ...). Never throws for NLopt's failures: they are the stage's
/// result string (the evaluations made so far are kept).
Summary optimize(const Problem& problem, const PipelineOptions& options);

}  // namespace ks::opt
