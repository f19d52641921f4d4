#pragma once
// What flows from a run to the store: a row of named, typed cells and the run's history arrays.
// The store is the only code that knows HDF5; runs only fill these plain structures.
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace ks {

enum class CellType { f64, i64, str };
/// One value of a /runs column. Missing values: NaN (f64), -1 (i64), "" (str).
using Cell = std::variant<double, std::int64_t, std::string>;
/// A numeric cell as a double (an integer converted); NaN for a text cell.
inline double cell_number(const Cell& c) {
  if (const double* d = std::get_if<double>(&c)) return *d;
  if (const std::int64_t* i = std::get_if<std::int64_t>(&c)) return static_cast<double>(*i);
  return std::numeric_limits<double>::quiet_NaN();
}

/// What a /runs column holds (stored as its `role` attribute: "parameter", "metric", "bookkeeping").
enum class Role { parameter, metric, bookkeeping };
/// The attribute word of a role: "parameter", "metric", "bookkeeping".
inline std::string_view to_string(Role r) {
  switch (r) {
    case Role::parameter: return "parameter";
    case Role::metric: return "metric";
    case Role::bookkeeping: return "bookkeeping";
  }
  return "bookkeeping";
}
/// Inverse of to_string(Role); false (out untouched) for any other word.
inline bool parse(std::string_view word, Role& out) {
  if (word == "parameter") out = Role::parameter;
  else if (word == "metric") out = Role::metric;
  else if (word == "bookkeeping") out = Role::bookkeeping;
  else return false;
  return true;
}

/// A column of /runs: its name (the user's word: "alpha1A", "E", "status", ...), type, unit, meaning,
/// role and the run kinds it applies to. All are stored as attributes, so readers need no guessing.
struct ColumnSpec {
  std::string name;
  CellType type = CellType::f64;
  std::string unit;         ///< "rad", "Nm", "" for dimensionless or strings
  std::string description;  ///< one line, stored as an HDF5 attribute
  Role role = Role::bookkeeping;
  std::string kinds;        ///< comma-separated run kinds the column applies to ("trajectory", "ik",
                            ///< "trajectory,ik"); "" for bookkeeping columns that apply to every run
  /// A text column with few distinct values: every value it may hold besides "" (the missing
  /// value), stored as an HDF5 enum of codes 0..labels.size()-1 (FORMAT.md, /runs). Empty: the column
  /// holds any text, stored as variable-length strings. Ignored for numeric columns.
  std::vector<std::string> labels = {};
  /// How plots and reports name the column (metrics: the kind's display label, e.g. "E (mean ‖τ‖)");
  /// empty: its name. Stored as the attribute `display_name` when set.
  std::string display_name = {};
};

/// One result row: one cell per ColumnSpec of the study's schema, in schema order.
struct Record {
  std::vector<Cell> cells;
};

/// One history array of a run: `rows` samples (or iterations) x `cols` components, row-major.
struct HistoryArray {
  std::string name;   ///< "t", "q", "qd", "qdd", "tau", "x", "alpha"; "q", "F", "norm_F", "step", "lambda"
  std::string unit;
  std::size_t rows = 0, cols = 1;
  std::vector<double> data;  ///< rows * cols values, row-major
};

/// A run's full history (empty when histories are off).
struct RunHistory {
  std::vector<HistoryArray> arrays;
};

}  // namespace ks
