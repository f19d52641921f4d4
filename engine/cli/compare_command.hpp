#pragma once
// `kinesweep compare FILE [--by COLUMN] [--metric M ...] [--end rest|free|any] [--where EXPR ...]
//  [--format table|json|csv]`:
// a verdict table. For each group of runs (by method, or any /runs column), the best run under
// common conditions (the good status of its kind, the same end condition), its grid convergence
// index from /verification, and its margin to the next group with the uncertainty of both, per
// metric.
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace ks::cli {

struct CompareArgs {
  std::string file;
  std::string by = "method";         ///< the /runs column whose values are the groups
  std::vector<std::string> metrics;  ///< empty: each kind's ranking objective
  /// rest | free: only runs that end so; any: every run in one pool; "" (default): each end
  /// condition on its own, never mixed
  std::string end;
  std::string format = "table";      ///< table | json | csv
  /// only the rows where every expression holds (`kinesweep query --where` syntax; angles in degrees),
  /// e.g. "inertia=physical": the same robot model for every group
  std::vector<std::string> where;
};

CompareArgs& add_compare_command(CLI::App& app);
/// Exit codes: 0 ok, 1 file or I/O problem, 2 bad arguments.
int compare_command(const CompareArgs& args);

/// The end condition of a trajectory run (rest: the arm at rest at the last vertex; free: it may
/// still move): its end_state where that parameter has an effect on the run (the parameter table's
/// rule: global_spline) and its spline is not vertex_quintic; rest for vertex_alpha and for
/// vertex_quintic splines (a quintic per segment stops the arm at every vertex); for the local methods
/// their `end` parameter: rest when "rest" (a stopping window brings the self-motion to rest), else free
/// (their integration ends with the rates it has). `spline`, `end_state` and `local_end` are "" when
/// the file has no such column.
std::string end_condition(const std::string& method, const std::string& spline, const std::string& end_state,
                          const std::string& local_end = "");

}  // namespace ks::cli
