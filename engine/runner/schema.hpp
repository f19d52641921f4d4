#pragma once
// The /runs schema of a study: run_id, block, every block's parameters (union by name, file order),
// the metrics of each kind present, status and wall time. A row of a block leaves the columns of
// other kinds missing (NaN, -1, ""). Conversion of a typed run and outcome to a row happens here
// only, through the parameter and metric tables.
#include <vector>

#include "runner/execute.hpp"
#include "schema/params.hpp"

namespace ks {

struct StudySchema {
  std::vector<ColumnSpec> columns;
  std::vector<std::vector<std::size_t>> param_column;   ///< per block: parameter i -> column
  std::vector<std::vector<std::size_t>> metric_column;  ///< per block: metric j -> column
  std::size_t run_id = 0, block = 1, status = 0, wall_time = 0;
  Record blank;                                         ///< every cell missing

  /// The full row of one run of block `block` (index into the study's blocks).
  Record row(std::uint64_t run_id, std::size_t block, const Block& b, const RunSpec& run, const RunOutcome& outcome,
             double wall_time_s) const;
};

StudySchema make_schema(const Study& study);

}  // namespace ks
