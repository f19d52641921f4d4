#pragma once
// Shared by `kinesweep info` and `kinesweep query`: a consistent in-memory copy of a results file's
// /runs (through the public store API only) with each column's role and run kinds (its attributes),
// and table/CSV/JSON output.
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/format_double.hpp"
#include "store/record.hpp"
#include "store/store.hpp"

namespace ks::cli {

/// One /runs column held in memory (only the vector of its type is filled).
struct RunsColumn {
  std::string name, unit, description;
  CellType type = CellType::f64;
  Role role = Role::bookkeeping;
  std::vector<std::string> kinds;  ///< run kinds the column applies to; empty: every kind
  std::vector<double> f;
  std::vector<std::int64_t> i;
  std::vector<std::string> s;
  /// Whether load_piece / load_ids read this column (a command reads the columns it needs; the
  /// vectors of the others stay empty).
  bool loaded = true;
  bool angle() const { return unit == "rad"; }  ///< shown in degrees unless --radians
  bool applies_to(const std::string& kind) const;
  bool missing(std::int64_t row) const;  ///< NaN, -1 or ""
};

struct RunsTable {
  store::StoreMeta meta;
  std::int64_t n_runs = 0;  ///< rows held (the file's runs, or the piece's rows: see first, ids)
  std::int64_t first = 0;   ///< run id of row 0 (a piece of a file read in pieces)
  std::vector<std::int64_t> ids;  ///< when not empty: run id (or evaluation index) of each row (gathered rows)
  std::vector<std::uint8_t> done;
  std::vector<RunsColumn> cols;
  std::vector<std::string> kinds;  ///< the run kinds the columns name, first seen first
  bool consistent = true;  ///< false: a writer kept committing during every attempt (rows still done-safe)

  std::int64_t row_id(std::int64_t row) const { return ids.empty() ? first + row : ids[static_cast<std::size_t>(row)]; }
  const RunsColumn* find(const std::string& name) const;
  std::vector<std::string> names() const;
  /// A row's run kind: the kind of the parameter (else metric) columns of a single kind that hold a
  /// value in the row; the file's only kind when it has one; "" when unknown (a pending row).
  std::string kind(std::int64_t row) const;
  /// Marks loaded the columns kind() reads: in a file of several kinds, the first parameter column
  /// of a single kind for each kind, and the first such metric column (pending rows hold neither).
  void load_kind_columns();
  /// Marks every column loaded (`all`) or none.
  void load_all(bool all) {
    for (auto& c : cols) c.loaded = all;
  }
  /// The metric columns of `kind` that compact views show (trajectory: E, E_M, tau_inf; ik:
  /// iterations, error, solution; another kind: its first three metrics).
  std::vector<const RunsColumn*> key_metrics(const std::string& kind) const;
};

/// Fills role and kinds of the /runs columns of a format_version 1 results file, which stores
/// neither (store::ResultsReader::V1ColumnRoles; pass it to every ResultsReader of info and query).
/// Looked up by name in this kinesweep's own tables: the parameters of each kind (block_params), its
/// metrics (metrics(kind)), for the kinds whose metrics the file holds; run_id, block, status,
/// wall_time are bookkeeping. A column found in no table (a file of an older engine whose tables
/// differed) stays bookkeeping.
void v1_column_roles(std::vector<ColumnSpec>& columns);

/// Open `path` and read the whole /runs table. Safe on a file a sweep is writing: the done mask is
/// read before the columns, and the read is repeated (refresh) when a commit happened meanwhile.
/// Throws store::StoreError.
RunsTable load_runs(store::ResultsReader& reader);

/// The /runs columns of `reader` (names, units, roles, kinds) and its metadata, holding no rows.
RunsTable runs_header(store::ResultsReader& reader);
/// Rows a piece holds when a command streams a file (memory bounded whatever the run count).
inline constexpr std::int64_t kPieceRows = 16384;
/// Fills `t` (a runs_header of `reader`) with the rows `first` .. `first + count` (clamped): their
/// done flags and the values of its loaded columns, read like load_runs (done mask first, repeated
/// on a commit meanwhile). The column objects stay in place (pointers to them stay valid); their
/// values are replaced (emptied for the columns not loaded).
void load_piece(store::ResultsReader& reader, RunsTable& t, std::int64_t first, std::int64_t count);
/// Calls f(t) for each piece of kPieceRows rows of the file, in run-id order (t.first: the piece's
/// first run id; rows are indexed from 0 within the piece). Returns false when some piece was read
/// while a writer kept committing (rows marked done are complete either way).
template <class F>
bool for_each_piece(store::ResultsReader& reader, RunsTable& t, F&& f) {
  bool consistent = true;
  const std::int64_t total = reader.n_runs();
  for (std::int64_t first = 0; first < total; first += kPieceRows) {
    load_piece(reader, t, first, kPieceRows);
    consistent = consistent && t.consistent;
    f(static_cast<const RunsTable&>(t));
  }
  return consistent;
}
/// Fills `t` (a runs_header of `reader`) with the rows of `ids` (ascending run ids), row i = ids[i].
void load_ids(store::ResultsReader& reader, RunsTable& t, const std::vector<std::int64_t>& ids);
/// A table with the columns of `t` (names, types, roles, loaded flags) and no rows.
RunsTable empty_like(const RunsTable& t);
/// Equal values in row `a` of column `c` and row `b` of column `d` (of the same type; NaN equals NaN).
bool same_value(const RunsColumn& c, std::int64_t a, const RunsColumn& d, std::int64_t b);
/// Appends row `r` of `t` to `g` (a table with t's columns): the values of the columns whose index
/// is set in `take` (the others stay empty), its done flag and its run id.
void append_row(RunsTable& g, const RunsTable& t, std::int64_t r, const std::vector<bool>& take);

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

using ks::format_double;  ///< %.6g; "nan", "inf" (common/format_double.hpp)
std::string json_string(const std::string& s);
std::string csv_field(const std::string& s);
/// Closest candidate by edit distance (empty when none is close).
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);
std::string join(const std::vector<std::string>& v, const std::string& sep);
/// CLI11 check of a count option (--best, --limit): "" when `value` is not a negative number, else the
/// error ("a count of 0 or more is expected, not -3"; CLI11 then exits with code 2).
std::string check_count(std::string& value);

inline constexpr double kRadToDeg = 57.295779513082320876798154814105;

}  // namespace ks::cli
