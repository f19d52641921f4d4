#pragma once
// `kinesweep query` on a table in memory (the /runs rows, or one optimisation's evaluations): the
// --where filter, --sort, --columns, --limit, and --group-by with --agg.
#include <set>
#include <string>
#include <vector>

#include "cli/query_command.hpp"
#include "cli/query_util.hpp"

namespace ks::cli {

/// What a table's rows are called in the trailer of table output.
struct TableWording {
  std::string rows = "matching rows";  ///< "(3 of 10 matching rows; ...)"
  std::string summary;                 ///< the trailer's second part, e.g. "8 of 10 runs done"
  bool compact_default = true;         ///< table format without --columns: run_id, varying parameters, key metrics
  std::vector<std::string> shown;      ///< columns the compact default shows too (--pareto's metrics)
  bool notes_said = false;             ///< the caller printed the --where value notes (over rows `t` lacks)
  /// Matching rows the caller left out of `t` (it holds the first --limit of them, unsorted): their
  /// number, the kinds they hold and the columns in which they differ from t's first row.
  std::int64_t more_matching = 0;
  std::set<std::string> more_kinds;
  std::set<std::string> more_varying;
};

/// The columns table_mode reads for these arguments (by index into t.cols): the ones it filters,
/// sorts, groups, aggregates and prints; for the compact default, every parameter and metric (the
/// row kinds and the varying parameters decide what it prints). Throws ArgError on an unknown name.
std::vector<bool> columns_read(const QueryArgs& a, const RunsTable& t, Format fmt, const TableWording& wording);

/// Sorts `rows` (indices into t) by --sort (stable; NaN last), numbers as shown. Throws ArgError.
void sort_table_rows(std::vector<std::int64_t>& rows, const QueryArgs& a, const RunsTable& t);

/// Filter, sort and print `t` (or its groups, with --group-by) as the arguments say.
/// Throws ArgError on a bad argument.
int table_mode(const QueryArgs& a, const RunsTable& t, Format fmt, const TableWording& wording);

}  // namespace ks::cli
