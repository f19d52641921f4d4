#pragma once
// `kinesweep query --group-by COLS --agg SPECS`: one row per group of rows with equal values in
// COLS, aggregated as the rows stream by (memory: one state per group, plus the values of the
// groups' median columns), so a file of any size is grouped in one pass over its pieces.
#include <cstdint>
#include <iosfwd>
#include <map>
#include <string>
#include <vector>

#include "cli/query_command.hpp"
#include "cli/query_util.hpp"
#include "cli/query_where.hpp"

namespace ks::cli {

class GroupAggregator {
 public:
  /// Parses --group-by and --agg against `t`'s columns (a header or a table: only its column list
  /// is used; the rows given to add() must come from tables with the same columns). Throws ArgError.
  GroupAggregator(const QueryArgs& a, const RunsTable& t);
  GroupAggregator(const GroupAggregator&) = delete;  // its map's order refers to it
  GroupAggregator& operator=(const GroupAggregator&) = delete;
  /// Indices into t.cols of the columns add() reads (keys and aggregated columns; a row's run id is
  /// its row_id, or its run_id cell when the table holds that column).
  std::vector<std::size_t> columns() const;
  /// Adds row `r` of `t` (rows in run-id order across calls: ties of argmin/argmax go to the first).
  void add(const RunsTable& t, std::int64_t r, const Selector& sel);
  /// Prints the groups in the order of their key values (numbers as shown, NaN last; text
  /// lexicographic), at most `limit` of them (negative: all), and in table format a trailer.
  void print(Format fmt, std::int64_t limit, bool radians, std::ostream& os) const;

 private:
  enum class Agg { count, min, max, mean, median, sum, argmin, argmax };
  struct Spec {
    Agg fn;
    std::size_t col = 0;  ///< index into the columns (unused for count)
    std::string name;     ///< output column name: "count", "min(E)", ...
  };
  /// One key value: a number as shown (NaN last), an integer column's value, or text.
  struct Part {
    double num = 0;
    std::int64_t i = 0;
    std::string s;
  };
  struct Less {
    const GroupAggregator* g;
    bool operator()(const std::vector<Part>& x, const std::vector<Part>& y) const;
  };
  struct Acc {
    double best = 0;        ///< min / max so far (valid when n > 0)
    std::int64_t id = -1;   ///< its run id (argmin / argmax)
    double sum = 0;
    std::int64_t n = 0;     ///< finite values seen
    std::vector<double> values;  ///< median only
  };
  struct Group {
    std::int64_t rows = 0;
    std::vector<Acc> acc;  ///< per spec
  };
  std::vector<const RunsColumn*> header_;  // the columns as parsed (names, units, types)
  std::vector<std::size_t> keys_;           // key columns (indices)
  std::vector<Spec> specs_;
  std::ptrdiff_t id_col_ = -1;              // run_id (i64), or -1: argmin/argmax give the row index
  std::map<std::vector<Part>, Group, Less> groups_;
  std::pair<const std::vector<Part>, Group>* last_ = nullptr;  // the group of the previous row
  /// Row `r` of `t` belongs to last_'s group (the same key values, NaN equal to NaN).
  bool in_last(const RunsTable& t, std::int64_t r, const Selector& sel) const;
  std::int64_t rows_ = 0;
};

}  // namespace ks::cli
