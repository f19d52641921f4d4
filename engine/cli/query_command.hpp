#pragma once
// `kinesweep query FILE [--where EXPR]... [--columns a,b,c|all] [--sort COL[:desc]]... [--limit N]
//  [--format table|csv|json] [--radians] [--include-pending]`
// `kinesweep query FILE --run ID --history NAME[,NAME...]|all [--format table|csv|json] [--limit N]`
// `kinesweep query FILE --optimization NAME [--where ...] [--sort ...] [--format ...] [--limit N] [--radians]
// `kinesweep query FILE --group-by COL[,COL] [--agg min:E,count,...] [--where ...]`
// `kinesweep query FILE --pareto M1[:min|max],M2[,M3] [--where ...] [--hypervolume R1,R2[,R3]] [--format ...]`
#include <cstdint>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace ks::cli {

struct QueryArgs {
  std::string file;
  std::vector<std::string> where;  ///< ANDed filter expressions
  std::string columns;             ///< comma list, "all", or empty (a compact default)
  std::vector<std::string> sort;   ///< COL or COL:desc, first key first
  std::int64_t limit = -1;         ///< -1: every row
  std::string format = "table";
  bool radians = false;            ///< show (and filter) angles in radians, as stored
  bool include_pending = false;    ///< also rows not done yet (missing values)
  std::int64_t run = -1;           ///< history mode: the run id
  std::string history;             ///< history mode: array name(s)
  std::string optimization;        ///< optimisation mode: the /optimizations group whose evaluations to print
  std::string group_by;            ///< comma list of columns: one output row per group of equal values
  std::string agg;                 ///< with group_by: count, FN:COL (min, max, mean, median, sum, argmin, argmax)
  std::string pareto;              ///< 2 or 3 metrics, each COL, COL:min or COL:max: the runs on their Pareto front
  std::string hypervolume;         ///< with pareto: the reference point (one value per metric); print the indicator
};

/// Register the subcommand; returns the argument struct it fills.
QueryArgs& add_query_command(CLI::App& app);
/// Exit codes: 0 ok, 1 file or I/O problem, 2 bad arguments (unknown column, bad expression, ...).
int query_command(const QueryArgs& args);

}  // namespace ks::cli
