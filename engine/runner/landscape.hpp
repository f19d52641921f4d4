#pragma once
// Landscapes: a block's metrics gridded over its swept dimensions, so a plot needs no re-gridding.
// A run's local index is its position in the grid (mixed radix, last dimension fastest), so filling
// a grid is a store at that index. Grids of blocks larger than kMaxLandscapeCells are not kept.
#include <vector>

#include "runner/schema.hpp"
#include "store/store.hpp"

namespace ks {

inline constexpr std::uint64_t kMaxLandscapeCells = 1ull << 26;  ///< per block and metric (512 MiB of f64)

class LandscapeGrid {
 public:
  explicit LandscapeGrid(const Block& block);
  bool enabled() const { return enabled_; }
  /// Record the row of run `local` of this block (block index `b` in the schema).
  void add(std::uint64_t local, const Record& row, const StudySchema& schema, std::size_t b);
  /// Which value a grid takes from a row: a metric column, or a status-derived value.
  enum class Source { column, is_ok, status_code };
  /// The axes (one per dimension; a zipped dimension is named "a+b" and takes the first axis'
  /// values; string axes take 0..n-1 with the names in the unit field) and the gridded metrics. The
  /// grids are moved into the spec (no copy of a large block's grids): call once, when done adding.
  store::LandscapeSpec take_spec();

 private:
  const Block& block_;
  bool enabled_ = false;
  std::vector<std::string> names_;            // metric names
  std::vector<Source> sources_;               // per metric
  std::vector<std::size_t> metric_index_;     // per metric: index into metrics(kind) (Source::column)
  std::vector<std::vector<double>> grids_;    // per metric
};

}  // namespace ks
