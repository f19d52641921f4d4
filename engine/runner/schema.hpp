#pragma once
// The /runs schema of a study: run_id, block, every block's parameters (union by name, file order),
// the metrics of each kind present, status and wall time. A row of a block leaves the columns of
// other kinds missing (NaN, -1, "").
#include <vector>

#include "runner/execute.hpp"

namespace ks {

struct StudySchema {
  std::vector<ColumnSpec> columns;
  std::vector<std::vector<std::size_t>> param_column;   ///< per block: parameter i -> column
  std::vector<std::vector<std::size_t>> metric_column;  ///< per block: metric j -> column
  std::size_t run_id = 0, block = 1, status = 0, wall_time = 0;
  Record blank;                                         ///< every cell missing

  /// The full row of one run.
  Record row(std::uint64_t run_id, std::size_t block, const std::string& block_name, std::span<const Cell> params,
             const RunOutcome& outcome, double wall_time_s) const;
};

StudySchema make_schema(const Study& study);

}  // namespace ks
