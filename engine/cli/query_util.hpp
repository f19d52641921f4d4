#pragma once
// Shared by `kinesweep info` and `kinesweep query`: a consistent in-memory copy of a results file's
// /runs (through the public store API only), column classification, and table/CSV/JSON output.
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "store/record.hpp"
#include "store/store.hpp"

namespace ks::cli {

/// One /runs column held in memory (only the vector of its type is filled).
struct RunsColumn {
  std::string name, unit, description;
  CellType type = CellType::f64;
  std::vector<double> f;
  std::vector<std::int64_t> i;
  std::vector<std::string> s;
  bool angle() const { return unit == "rad"; }  ///< shown in degrees unless --radians
};

enum class ColumnRole { id, block, parameter, metric, status, other };

struct RunsTable {
  store::StoreMeta meta;
  std::int64_t n_runs = 0;
  std::vector<std::uint8_t> done;
  std::vector<RunsColumn> cols;
  bool consistent = true;  ///< false: a writer kept committing during every attempt (rows still done-safe)

  const RunsColumn* find(const std::string& name) const;
  std::vector<std::string> names() const;
  static ColumnRole role(const std::string& name);
  /// Row's kind: "ik" when it holds IK metrics, else "trajectory".
  std::string kind(std::int64_t row) const;
};

/// Open `path` and read the whole /runs table. Safe on a file a sweep is writing: the done mask is
/// read before the columns, and the read is repeated (refresh) when a commit happened meanwhile.
/// Throws store::StoreError.
RunsTable load_runs(store::ResultsReader& reader);

/// Retry helper for other reads (histories, landscapes) on a live file.
template <class F>
auto consistent_read(store::ResultsReader& reader, F&& f) -> decltype(f()) {
  for (int attempt = 0;; ++attempt) {
    try {
      auto out = f();
      if (reader.unchanged_since_open() || attempt >= 4) return out;
    } catch (const store::StoreError&) {
      if (attempt >= 4) throw;
    }
    reader.refresh();
  }
}

/// Output table: header names (units shown beside them in table format), cells.
using OutCell = std::variant<std::monostate, double, std::int64_t, std::string>;
struct OutTable {
  std::vector<std::string> names, units;
  std::vector<std::string> csv_names;  ///< csv header names (default: names); json keys are names
  std::vector<std::vector<OutCell>> rows;
};
enum class Format { table, csv, json };
std::optional<Format> parse_format(const std::string& s);
/// table: aligned text, header "name [unit]", strings left- and numbers right-aligned; csv: header csv_names;
/// json: {"columns": [...], "units": {name: unit}, "rows": [{name: value}, ...]} (NaN -> null).
void print_out(const OutTable& t, Format f, std::ostream& os);

std::string format_double(double v);  ///< %.6g; "nan", "inf"
std::string json_string(const std::string& s);
std::string csv_field(const std::string& s);
/// Closest candidate by edit distance (empty when none is close).
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);
std::string join(const std::vector<std::string>& v, const std::string& sep);

inline constexpr double kRadToDeg = 57.295779513082320876798154814105;

}  // namespace ks::cli
