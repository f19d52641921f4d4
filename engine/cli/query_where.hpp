#pragma once
// `kinesweep query` argument parsing: --where expressions into conditions on /runs columns, the
// row test, and the notes on values no row holds. Output formatting: query_util.hpp.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "cli/query_util.hpp"

namespace ks::cli {

/// A bad argument (exit code 2).
struct ArgError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string trim(const std::string& s);
/// Split at `sep`, each part trimmed (an empty string gives one empty part).
std::vector<std::string> split(const std::string& s, char sep);
/// "unknown column 'X'<where>; did you mean 'Y'?\nvalid columns: ...".
std::string unknown_column_message(const std::string& name, const RunsTable& t, const std::string& where);

enum class Op { eq, ne, lt, le, gt, ge };

/// One condition on one column: `op` against each value (eq: any of them; ne: none of them).
struct Condition {
  const RunsColumn* col = nullptr;
  Op op = Op::eq;
  std::vector<double> nums;
  std::vector<std::string> strs;
};

/// Conditions that all hold (AND).
using Conjunction = std::vector<Condition>;
/// One --where expression in disjunctive form: it holds when any of its conjunctions holds.
using Disjunction = std::vector<Conjunction>;

/// Tests rows against conditions; numbers as shown (angles in degrees unless `radians`).
struct Selector {
  const RunsTable& t;
  bool radians;

  double value(const RunsColumn& c, std::int64_t r) const;
  bool test(const Condition& k, std::int64_t r) const;
  bool test(const Disjunction& d, std::int64_t r) const;  ///< any conjunction whose conditions all hold
};

/// Parse one --where expression. Throws ArgError.
///   COL OP VALUE          OP: = == != < <= > >=   (VALUE OP COL also works)
///   COL=V1,V2,...         any of the values (!=: none of them)
///   COL=LO..HI            LO <= COL <= HI (!=: outside: below LO or above HI)
///   LO<COL<=HI            chained range (< or <=, or > / >= descending)
///   A | B | ...           any of the alternatives (each one of the forms above)
Disjunction parse_where(const std::string& expr, const RunsTable& t);

/// Every condition of the expressions, flattened (for notes and the columns a query mentions).
std::vector<Condition> all_conditions(const std::vector<Disjunction>& filters);

/// For each text value of an = / != condition that no row holds (among the done rows, or all rows
/// with `include_pending`): "no row has method = 'local_weightd'; did you mean 'local_weighted'?"
/// (or the values the column holds, when few and none is close).
std::vector<std::string> unheld_value_notes(const std::vector<Condition>& conditions, const RunsTable& t,
                                            bool include_pending);
/// The text values the rows hold in the columns of = / != text conditions, gathered over the pieces
/// of a file read in pieces (collect_held per piece, then the notes once).
using HeldValues = std::map<const RunsColumn*, std::set<std::string>>;
void collect_held(const std::vector<Condition>& conditions, const RunsTable& t, bool include_pending, HeldValues& held);
std::vector<std::string> unheld_value_notes(const std::vector<Condition>& conditions, const HeldValues& held);

}  // namespace ks::cli
