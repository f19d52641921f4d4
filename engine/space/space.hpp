#pragma once
// The parameter space of a study: blocks of axes -> run ids -> run parameters.
//
// A block has one parameter column per parameter of its kind (every run row is complete), a list of
// axes (each a parameter with a list of values, in stored units: angles in rad), and dimensions: every
// axis is its own dimension unless it advances together with others (a zip group, or the LHS group),
// in which case the group is one dimension. The runs of a block are the cartesian product of its
// dimensions in order, the last dimension varying fastest. A run's parameters are decoded from its
// local index (mixed radix); nothing is materialised per run.
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "schema/params.hpp"
#include "store/record.hpp"

namespace ks {

/// Names accepted for [task] integrator and [robot] inertia (from the trajectory table).
std::vector<std::string> integrator_names();
std::vector<std::string> inertia_names();
/// True for "scara": lengths in mm and q0_3 is the prismatic d [mm]; false for the planar 3R problems
/// (lengths in m, q0_3 an angle).
bool ik_problem_is_scara(std::string_view problem);

/// The parameters of a kind for a path of `path_vertices` vertices (IK: of the SCARA family or not).
std::vector<ParamDef> block_params(BlockKind kind, std::size_t path_vertices = 5, bool scara = true);

/// An axis: a parameter and its values, in stored units (angles in rad).
struct Axis {
  std::string name;          ///< the parameter
  std::string unit;          ///< unit of the stored values ("rad", "mm", "", ...)
  std::vector<Cell> values;  ///< >= 1 values, of the parameter's CellType
  std::string form;          ///< how the file wrote it: "values", "range", "linspace", "random", "lhs"
};

/// A dimension of a block's product: one axis, or axes advancing together (zip or LHS group).
struct Dim {
  std::vector<std::size_t> axes;  ///< indices into Block::axes(), file order
  std::uint64_t size = 0;
};

/// A block as described (before defaults): what the parser hands to Block.
struct BlockSpec {
  std::string name;
  BlockKind kind = BlockKind::trajectory;
  std::vector<std::pair<std::string, Cell>> fixed;  ///< explicit fixed parameters, stored units
  std::vector<Axis> axes;                           ///< file order; its units are filled by Block
  std::vector<std::vector<std::string>> groups;     ///< axes advancing together (zip groups, LHS group)
};

class Block {
 public:
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();

  /// Throws std::invalid_argument on an inconsistent spec (unknown parameter, bad cell type, a
  /// parameter both fixed and swept, unequal lengths in a group, an axis in two groups, empty axis,
  /// IK problems of both families). `context.scara` is derived from the block's problems.
  Block(BlockSpec spec, const KindContext& context);

  const std::string& name() const { return name_; }
  BlockKind kind() const { return kind_; }
  /// The parameter columns, in order (every parameter of the kind).
  const std::vector<ColumnSpec>& columns() const { return columns_; }
  /// The kind's parameter table for this block (units resolved for its context), columns() order.
  const std::vector<ParamDef>& table() const { return table_; }
  const KindContext& context() const { return context_; }
  /// The kind's metrics for this block's robot (per-joint columns), /runs order.
  const std::vector<MetricDef>& metrics() const { return metrics_; }
  /// Column of a parameter, or npos.
  std::size_t column_index(std::string_view param) const;
  const std::vector<Axis>& axes() const { return axes_; }
  /// Dimensions in order (the first varies slowest); for landscapes: the grid dims.
  const std::vector<Dim>& dims() const { return dims_; }
  /// Size of each dimension.
  std::vector<std::uint64_t> shape() const;
  std::uint64_t run_count() const { return runs_; }
  /// True when the product overflowed 64 bits (run_count() is then meaningless).
  bool overflowed() const { return overflow_; }

  /// Multi-index of a run over dims() (mixed radix, last dim fastest).
  std::vector<std::uint64_t> grid_index(std::uint64_t local) const;
  /// Inverse of grid_index.
  std::uint64_t local_index(std::span<const std::uint64_t> grid) const;

  /// Run `local`, decoded straight into its typed spec: the kind's defaults, then the leading
  /// parameters (a preset), then the block's fixed values and the run's axis values.
  RunSpec run(std::uint64_t local) const;
  /// All parameter cells of a run, in columns() order (table().get of run(local)).
  std::vector<Cell> params(std::uint64_t local) const;
  /// One parameter cell of a run (by column index or name; throws std::out_of_range when unknown).
  Cell value(std::uint64_t local, std::size_t column) const;
  Cell value(std::uint64_t local, std::string_view param) const;

 private:
  std::string name_;
  BlockKind kind_;
  KindContext context_;
  std::vector<ParamDef> table_;
  std::vector<MetricDef> metrics_;
  std::vector<ColumnSpec> columns_;
  RunSpec defaults_;          // the kind's defaults in this context
  RunSpec base_;              // defaults_ with the fixed values applied (leading ones first)
  bool leading_swept_ = false;  // a leading parameter is an axis: runs start from defaults_
  std::vector<std::pair<std::size_t, Cell>> fixed_;  // column, value
  std::vector<Axis> axes_;
  std::vector<std::size_t> axis_column_;
  std::vector<std::size_t> axis_dim_;
  std::vector<Dim> dims_;
  std::uint64_t runs_ = 1;
  bool overflow_ = false;
};

/// Global run ids: the blocks' runs concatenated in order.
struct RunRef {
  std::size_t block = 0;
  std::uint64_t local = 0;
};
std::uint64_t total_runs(std::span<const Block> blocks);
/// Global id of a block's first run.
std::uint64_t first_run(std::span<const Block> blocks, std::size_t block);
/// Block and local index of a global run id; throws std::out_of_range past the end.
RunRef locate_run(std::span<const Block> blocks, std::uint64_t global);

// ---- Deterministic draws (the same on every machine: mt19937_64 raw output, own mapping) ----

/// Uniform in (0, 1) from one raw 64-bit draw: ((x >> 11) + 0.5) * 2^-53.
double unit_open01(std::uint64_t raw);
/// `count` values uniform in [from, to) from seed.
std::vector<double> uniform_draws(std::uint64_t seed, std::uint64_t count, double from, double to);
/// Latin hypercube: count points in `ranges.size()` dimensions; result[d][i] is point i's coordinate
/// d, in stratum perm_d[i] of [from, to) cut in `count` equal strata (each stratum hit exactly once).
std::vector<std::vector<double>> lhs_draws(std::uint64_t seed, std::uint64_t count,
                                           std::span<const std::pair<double, double>> ranges);
/// Saltelli's design for first-order and total Sobol' indices of d = ranges.size() factors from
/// `count` base samples (saltelli.cpp): count (d + 2) points, result[i][r] is point r's factor i in
/// [from, to): rows 0..count-1 are matrix A, count..2 count-1 matrix B, and rows (2 + m) count ..
/// (3 + m) count - 1 matrix AB_m (A with column m taken from B). A and B are the first and last d
/// coordinates of the 2d-dimensional Sobol' sequence (origin skipped), shifted modulo 1 by uniform
/// draws of `seed`.
std::vector<std::vector<double>> saltelli_draws(std::uint64_t seed, std::uint64_t count,
                                                std::span<const std::pair<double, double>> ranges);

/// Values of a range from..to by step, inclusive of `to` within 1e-9 relative (values from + i step;
/// the last snapped to `to` when within tolerance). Empty when the range is empty or step == 0.
std::uint64_t range_count(double from, double to, double step);
std::vector<double> range_values(double from, double to, double step);
/// count values evenly spaced from..to inclusive (count 1: {from}).
std::vector<double> linspace_values(double from, double to, std::uint64_t count);

}  // namespace ks
