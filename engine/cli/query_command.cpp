// `kinesweep query`: the modes (rows of /runs, one run's history, one optimisation's evaluations,
// the runs on a Pareto front: query_pareto.cpp). Argument and --where parsing: query_where.cpp;
// output formatting: query_util.cpp.
#include "cli/query_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <numeric>
#include <optional>
#include <set>

#include "cli/query_groups.hpp"
#include "cli/query_pareto.hpp"
#include "cli/query_table.hpp"
#include "cli/query_util.hpp"
#include "cli/query_where.hpp"
#include "store/store.hpp"

namespace ks::cli {

namespace {

int history_mode(const QueryArgs& a, store::ResultsReader& reader, Format fmt) {
  const std::int64_t n = reader.n_runs();
  if (a.run < 0 || a.run >= n)
    throw ArgError("--run " + std::to_string(a.run) + ": the file has run ids 0.." + std::to_string(n - 1));
  auto got = consistent_read(reader, [&] {
    auto done = reader.done_mask();
    return std::make_pair(done[static_cast<std::size_t>(a.run)] != 0, reader.read_history(a.run));
  });
  if (!got.first) throw ArgError("run " + std::to_string(a.run) + " is not done yet (no committed row or history)");
  const RunHistory& h = got.second;
  if (h.arrays.empty())
    throw ArgError("run " + std::to_string(a.run) +
                   " has no history (the study's histories = \"none\", or the run stopped before its first sample)");
  std::vector<std::string> valid;
  for (auto& arr : h.arrays) valid.push_back(arr.name);
  std::vector<std::string> want;
  const std::string spec = a.history.empty() ? "all" : a.history;
  if (spec == "all") want = valid;
  else want = split(spec, ',');
  const HistoryArray* index = nullptr;
  for (auto& arr : h.arrays)
    if ((arr.name == "t" || arr.name == "k") && arr.cols == 1) index = &arr;
  std::vector<const HistoryArray*> arrays;
  if (index) arrays.push_back(index);
  for (auto& w : want) {
    const HistoryArray* found = nullptr;
    for (auto& arr : h.arrays)
      if (arr.name == w) found = &arr;
    if (!found) {
      std::string m = "run " + std::to_string(a.run) + " has no history array '" + w + "'";
      const std::string dym = did_you_mean(w, valid);
      if (!dym.empty()) m += "; did you mean '" + dym + "'?";
      throw ArgError(m + "\nvalid arrays: " + join(valid, ", ") + " (or all)");
    }
    if (found != index) arrays.push_back(found);
  }
  OutTable out;
  struct Src {
    const HistoryArray* arr;
    std::size_t col;
    bool to_deg;
  };
  std::vector<Src> src;
  std::size_t rows = SIZE_MAX;
  for (const HistoryArray* arr : arrays) {
    rows = std::min(rows, arr->rows);
    auto units = split(arr->unit, ',');
    if (units.size() != arr->cols) units.assign(arr->cols, arr->unit);
    for (std::size_t c = 0; c < arr->cols; ++c) {
      const bool deg = units[c] == "rad" && !a.radians;
      const std::string name = arr->cols == 1 ? arr->name : arr->name + "_" + std::to_string(c + 1);
      out.names.push_back(name);
      out.units.push_back(deg ? "deg" : units[c]);
      out.csv_names.push_back(deg ? name + " [deg]" : name);
      src.push_back({arr, c, deg});
    }
  }
  if (rows == SIZE_MAX) rows = 0;
  if (a.limit >= 0) rows = std::min<std::size_t>(rows, static_cast<std::size_t>(a.limit));
  for (std::size_t r = 0; r < rows; ++r) {
    std::vector<OutCell> row;
    for (const Src& s : src) {
      const double v = s.arr->data[r * s.arr->cols + s.col];
      if (s.arr->name == "k") row.emplace_back(static_cast<std::int64_t>(v));
      else row.emplace_back(s.to_deg ? v * kRadToDeg : v);
    }
    out.rows.push_back(std::move(row));
  }
  print_out(out, fmt, std::cout);
  return 0;
}

/// Every evaluation of one /optimizations group as a table: index, stage, start, the variables
/// (stored units; angles shown in degrees unless --radians), objective, constraint, status.
RunsTable evaluations_table(const store::OptimizationRecord& o) {
  const std::size_t d = o.dims(), n = o.size();
  RunsTable t;
  t.n_runs = static_cast<std::int64_t>(n);
  t.done.assign(n, 1);
  t.cols.reserve(6 + d);  // add() hands out references into t.cols
  auto add = [&](const std::string& name, CellType type, Role role, const std::string& unit,
                 const std::string& description) -> RunsColumn& {
    RunsColumn c;
    c.name = name, c.type = type, c.role = role, c.unit = unit, c.description = description;
    t.cols.push_back(std::move(c));
    return t.cols.back();
  };
  auto& index = add("index", CellType::i64, Role::bookkeeping, "", "evaluation number");
  auto& stage = add("stage", CellType::str, Role::bookkeeping, "", "sweep, global or local");
  auto& start = add("start", CellType::i64, Role::bookkeeping, "", "local: index of its start; sweep: run id");
  for (std::size_t i = 0; i < n; ++i) {
    index.i.push_back(static_cast<std::int64_t>(i));
    stage.s.push_back(i < o.stage.size() ? o.stage[i] : std::string());
    start.i.push_back(i < o.start.size() ? o.start[i] : std::int64_t{-1});
  }
  for (std::size_t j = 0; j < d; ++j) {
    auto& v = add(o.variables[j], CellType::f64, Role::parameter, j < o.units.size() ? o.units[j] : "", "variable");
    for (std::size_t i = 0; i < n; ++i) v.f.push_back(i * d + j < o.x.size() ? o.x[i * d + j] : std::nan(""));
  }
  auto& objective = add("objective", CellType::f64, Role::metric, "", o.objective);
  auto& constraint = add("constraint", CellType::f64, Role::metric, "", "reach margin (<= 0 feasible)");
  auto& status = add("status", CellType::str, Role::bookkeeping, "", "the run's status");
  for (std::size_t i = 0; i < n; ++i) {
    objective.f.push_back(o.value[i]);
    constraint.f.push_back(i < o.constraint.size() ? o.constraint[i] : std::nan(""));
    status.s.push_back(i < o.status.size() ? o.status[i] : std::string());
  }
  return t;
}

int optimization_mode(const QueryArgs& a, store::ResultsReader& reader, Format fmt) {
  const auto names = consistent_read(reader, [&] { return reader.optimizations(); });
  if (std::find(names.begin(), names.end(), a.optimization) == names.end()) {
    if (names.empty()) throw ArgError("--optimization " + a.optimization + ": the file holds no optimizations");
    std::string m = "no optimization '" + a.optimization + "'";
    const std::string dym = did_you_mean(a.optimization, names);
    if (!dym.empty()) m += "; did you mean '" + dym + "'?";
    throw ArgError(m + "\nvalid optimizations: " + join(names, ", "));
  }
  const store::OptimizationRecord o = consistent_read(reader, [&] { return reader.read_optimization(a.optimization); });
  TableWording w;
  w.rows = "evaluations of optimization " + o.name;
  w.summary = "minimise " + o.objective + "; best " + format_double(o.best_objective) + " [" + o.best_status +
              ", stage " + o.best_stage + "]";
  w.compact_default = false;
  return table_mode(a, evaluations_table(o), fmt, w);
}

/// What the matching rows left out of the table table_mode gets add to the compact default: their
/// number, their kinds, and the columns in which some of them differ from `ref` (a matching row).
struct LeftOut {
  std::int64_t rows = 0;
  std::set<std::string> kinds;
  std::vector<bool> varying;  ///< per column

  /// Notes rows `rows_of` of `t` (whose columns `take` are loaded).
  void note(const RunsTable& t, const std::vector<std::int64_t>& rows_of, const RunsTable& ref,
            const std::vector<bool>& take) {
    if (rows_of.empty()) return;
    rows += static_cast<std::int64_t>(rows_of.size());
    if (t.kinds.size() == 1) kinds.insert(t.kinds.front());
    else
      for (std::int64_t r : rows_of) kinds.insert(t.kind(r));
    varying.resize(t.cols.size(), false);
    if (ref.n_runs == 0) return;
    for (std::size_t c = 0; c < t.cols.size(); ++c) {
      if (!take[c] || varying[c]) continue;
      for (std::int64_t r : rows_of)
        if (!same_value(t.cols[c], r, ref.cols[c], 0)) {
          varying[c] = true;
          break;
        }
    }
  }
  /// Into the wording of table_mode.
  void into(const RunsTable& t, TableWording& w) const {
    w.more_matching = rows;
    w.more_kinds.insert(kinds.begin(), kinds.end());
    for (std::size_t c = 0; c < varying.size(); ++c)
      if (varying[c]) w.more_varying.insert(t.cols[c].name);
  }
};

/// Keeps the `limit` first rows of `g` in --sort order (in run-id order among themselves, as
/// gathered), noting the others in `out`: a sorted query holds at most a few times --limit rows.
void keep_best(RunsTable& g, const QueryArgs& a, const std::vector<bool>& take, const RunsTable& ref, LeftOut& out) {
  std::vector<std::int64_t> order(static_cast<std::size_t>(g.n_runs));
  for (std::int64_t r = 0; r < g.n_runs; ++r) order[static_cast<std::size_t>(r)] = r;
  sort_table_rows(order, a, g);
  std::vector<std::int64_t> keep(order.begin(), order.begin() + a.limit), drop(order.begin() + a.limit, order.end());
  std::sort(keep.begin(), keep.end());
  out.note(g, drop, ref, take);
  RunsTable kept = empty_like(g);
  for (std::int64_t r : keep) append_row(kept, g, r, take);
  g = std::move(kept);
}

/// Rows of /runs, read in pieces: first the done flags and the --where columns; only a piece with
/// a matching row reads the other columns the query needs. Matching rows are gathered with those
/// columns and printed by table_mode; with --sort and --limit only the best few times --limit are
/// held; with --group-by the rows are aggregated as they come (GroupAggregator). Memory: the
/// gathered rows' needed columns (bounded by --limit when sorted or by the groups), plus a piece.
int rows_mode(const QueryArgs& a, store::ResultsReader& reader, Format fmt) {
  RunsTable t = runs_header(reader);
  TableWording w;
  std::vector<Disjunction> filters;
  for (const auto& expr : a.where) filters.push_back(parse_where(expr, t));
  const std::vector<Condition> conds = all_conditions(filters);
  std::vector<bool> take = columns_read(a, t, fmt, w);
  std::vector<bool> filter_cols(t.cols.size(), false);
  for (const Condition& k : conds) filter_cols[static_cast<std::size_t>(k.col - t.cols.data())] = true;
  std::optional<GroupAggregator> groups;
  if (!a.group_by.empty()) groups.emplace(a, t);
  std::vector<bool> kind_cols(t.cols.size(), false);  // what a row's kind is read from
  t.load_all(false);
  t.load_kind_columns();
  for (std::size_t c = 0; c < t.cols.size(); ++c) kind_cols[c] = t.cols[c].loaded;
  // The gathered rows hold the columns the query reads and those their kind is read from.
  for (std::size_t c = 0; c < t.cols.size(); ++c) take[c] = take[c] || kind_cols[c];
  RunsTable g = runs_header(reader), ref = runs_header(reader);
  for (std::size_t c = 0; c < t.cols.size(); ++c) g.cols[c].loaded = ref.cols[c].loaded = take[c];
  HeldValues held;
  std::int64_t done = 0;
  const Selector sel{t, a.radians};
  // Rows in file order up to --limit are all table_mode prints (no sort, no groups): gather only those.
  const bool head_only = a.limit >= 0 && a.sort.empty() && a.group_by.empty();
  const bool best_only = a.limit >= 0 && !a.sort.empty() && a.group_by.empty();
  const std::int64_t hold = std::max<std::int64_t>(4 * a.limit, 4096);
  bool consistent = true;
  std::vector<std::int64_t> match, beyond;
  LeftOut left_out;
  const std::int64_t total = reader.n_runs();
  for (std::int64_t first = 0; first < total; first += kPieceRows) {
    for (std::size_t c = 0; c < t.cols.size(); ++c) t.cols[c].loaded = filter_cols[c];
    load_piece(reader, t, first, kPieceRows);
    consistent = consistent && t.consistent;
    match.clear();
    for (std::int64_t r = 0; r < t.n_runs; ++r) {
      const bool is_done = t.done[static_cast<std::size_t>(r)] != 0;
      done += is_done;
      if (!a.include_pending && !is_done) continue;
      if (std::all_of(filters.begin(), filters.end(), [&](const Disjunction& d) { return sel.test(d, r); }))
        match.push_back(r);
    }
    collect_held(conds, t, a.include_pending, held);
    if (match.empty()) continue;
    for (std::size_t c = 0; c < t.cols.size(); ++c) t.cols[c].loaded = take[c] || filter_cols[c];
    load_piece(reader, t, first, kPieceRows);  // the same rows, now with every column the query needs
    consistent = consistent && t.consistent;
    beyond.clear();
    for (std::int64_t r : match) {
      if (groups) {
        groups->add(t, r, sel);
        continue;
      }
      if (ref.n_runs == 0) append_row(ref, t, r, take);
      if (!head_only || g.n_runs < a.limit) {
        append_row(g, t, r, take);
        if (best_only && g.n_runs >= hold) keep_best(g, a, take, ref, left_out);
        continue;
      }
      beyond.push_back(r);  // beyond the --limit rows printed: what the compact default learns from
    }
    left_out.note(t, beyond, ref, take);
  }
  if (!consistent)
    std::cerr << "kinesweep query: note: the file kept changing while it was read (a sweep is writing it)\n";
  for (const std::string& note : unheld_value_notes(conds, held)) std::cerr << "kinesweep query: note: " << note << '\n';
  if (groups) {
    groups->print(fmt, a.limit, a.radians, std::cout);
    return 0;
  }
  if (best_only && g.n_runs > a.limit) keep_best(g, a, take, ref, left_out);
  if (left_out.rows > 0) {  // rows left out: the kept ones may differ from them only through ref
    std::vector<std::int64_t> all(static_cast<std::size_t>(g.n_runs));
    for (std::int64_t r = 0; r < g.n_runs; ++r) all[static_cast<std::size_t>(r)] = r;
    const std::int64_t n = left_out.rows;
    left_out.note(g, all, ref, take);
    left_out.rows = n;
  }
  left_out.into(g, w);
  w.notes_said = true;
  w.summary = std::to_string(done) + " of " + std::to_string(reader.n_runs()) + " runs done";
  return table_mode(a, g, fmt, w);
}

}  // namespace

int query_command(const QueryArgs& a) {
  try {
    if (!a.history.empty() && a.run < 0) throw ArgError("--history needs --run ID");
    const bool history = a.run >= 0;
    if (history && (!a.where.empty() || !a.sort.empty() || !a.columns.empty()))
      throw ArgError("--run/--history prints one run's history; --where, --sort and --columns apply to rows only");
    const bool optimization = !a.optimization.empty();
    if (history && (!a.group_by.empty() || !a.agg.empty()))
      throw ArgError("--run/--history prints one run's history; --group-by and --agg apply to rows only");
    if (optimization && (history || a.include_pending))
      throw ArgError("--optimization prints one optimisation's evaluations; --run, --history and --include-pending "
                     "do not apply to it");
    const bool front = !a.pareto.empty();
    if (!a.hypervolume.empty() && !front) throw ArgError("--hypervolume needs --pareto M1,M2[,M3] (its metrics)");
    if (front && (history || optimization || !a.group_by.empty() || !a.agg.empty()))
      throw ArgError("--pareto prints the runs on a front of /runs; --run, --history, --optimization, --group-by and "
                     "--agg do not apply to it");
    const Format fmt = *parse_format(a.format.empty() ? (history ? "csv" : "table") : a.format);
    store::ResultsReader reader(a.file, v1_column_roles);
    if (optimization) return optimization_mode(a, reader, fmt);
    if (front) return pareto_mode(a, reader, fmt);
    return history ? history_mode(a, reader, fmt) : rows_mode(a, reader, fmt);
  } catch (const ArgError& e) {
    std::cerr << "kinesweep query: error: " << e.what() << '\n';
    return 2;
  } catch (const store::StoreError& e) {
    std::cerr << "kinesweep query: error: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "kinesweep query: error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace ks::cli
