#pragma once
// Landscapes: a block's metrics gridded over its swept dimensions, so a plot needs no re-gridding.
// A run's local index is its position in the grid (mixed radix, last dimension fastest), so filling
// a grid is a write at that index. Blocks larger than kMaxLandscapeCells get no landscape.
#include <vector>

#include "runner/schema.hpp"
#include "store/store.hpp"

namespace ks {

inline constexpr std::uint64_t kMaxLandscapeCells = 1ull << 26;  ///< per block and metric (512 MiB of f64)

/// A block's landscape in a results file: created when the sweep starts (every cell NaN), each run's
/// cell written with its row, so the file of a running or interrupted sweep holds what is done and
/// nothing of the grid is held in memory.
class LandscapeGrid {
 public:
  /// The block's grid; `enabled` false (or a block too large for a grid): none, add() does nothing.
  explicit LandscapeGrid(const Block& block, bool enabled = true);
  bool enabled() const { return enabled_; }
  /// Create the block's landscape in `writer` (replacing one there; a resumed sweep writes the
  /// cells of its done runs again through add). `dense`: every cell is written before the writer's
  /// next commit (store::LandscapeSpec::dense).
  void begin(store::ResultsWriter& writer, bool dense = false);
  /// The writer's handle of the landscape begin() created.
  std::size_t handle() const { return handle_; }
  /// Write the cell of run `local` of this block (block index `b` in the schema) from its row.
  void add(std::uint64_t local, const Record& row, const StudySchema& schema, std::size_t b,
           store::ResultsWriter& writer);
  /// The same from the run's status index `code` (in statuses(kind); NaN for none) and `values`,
  /// the run's values of columns(schema, b) in that order: runs counted without their Records.
  void add_cell(std::uint64_t local, double code, const double* values, const StudySchema& schema, std::size_t b,
                store::ResultsWriter& writer);
  /// The cells of the `count` runs from local index `first` at once: codes[i] as add_cell's `code`,
  /// columns[j][i] the values of columns(schema, b)[j].
  void add_range(std::uint64_t first, std::uint64_t count, const double* codes, const std::vector<const double*>& columns,
                 const StudySchema& schema, std::size_t b, store::ResultsWriter& writer);
  /// The schema columns the grid's metrics take their values from, in order.
  std::vector<std::size_t> columns(const StudySchema& schema, std::size_t b) const;
  /// Which value a grid takes from a row: a metric column, or a status-derived value.
  enum class Source { column, is_ok, status_code };
  /// The axes (one per dimension, named after its axis; string axes take 0..n-1 with the names in
  /// the unit field; a sampled dimension is the axis "sample" ("sample_2", ... for the next ones)
  /// of values 0..n-1 with its axes as coordinates) and the gridded metrics' names, units and
  /// descriptions (their grids empty; status_code: the statuses as flags).
  store::LandscapeSpec spec() const;
  /// Whether dimension `d` is sampled: a group of axes (zip, LHS, Saltelli), a random, LHS or
  /// Saltelli axis, or values not strictly monotonic (no CF coordinate).
  bool is_sampled(const Dim& d) const;

 private:
  const Block& block_;
  bool enabled_ = false;
  std::size_t handle_ = 0;                    // begin_landscape's
  std::vector<std::string> names_;            // metric names
  std::vector<Source> sources_;               // per metric
  std::vector<std::size_t> metric_index_;     // per metric: index into metrics(kind) (Source::column)
  std::vector<double> cell_;                  // one cell's values, per metric
  std::vector<double> values_;                // add(): a row's values of columns()
};

}  // namespace ks
