// `kinesweep query`: the three modes (rows of /runs, one run's history, one optimisation's
// evaluations). Argument and --where parsing: query_where.cpp; output formatting: query_util.cpp.
#include "cli/query_command.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <numeric>
#include <set>

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

/// Rows of /runs: the file is read in pieces; the rows that pass --where (and are done, unless
/// --include-pending) are gathered with the columns the query reads, then filtered, sorted and
/// printed by table_mode. Memory: the matching rows' needed columns, not the file's.
int rows_mode(const QueryArgs& a, store::ResultsReader& reader, Format fmt) {
  RunsTable t = runs_header(reader);
  TableWording w;
  std::vector<Disjunction> filters;
  for (const auto& expr : a.where) filters.push_back(parse_where(expr, t));
  const std::vector<Condition> conds = all_conditions(filters);
  const std::vector<bool> take = columns_read(a, t, fmt, w);
  RunsTable g = runs_header(reader);
  HeldValues held;
  std::int64_t done = 0;
  const Selector sel{t, a.radians};
  // Rows in file order up to --limit are all table_mode prints (no sort, no groups): gather only those.
  const bool head_only = a.limit >= 0 && a.sort.empty() && a.group_by.empty();
  const bool consistent = for_each_piece(reader, t, [&](const RunsTable& p) {
    collect_held(conds, p, a.include_pending, held);
    for (std::int64_t r = 0; r < p.n_runs; ++r) {
      const bool is_done = p.done[static_cast<std::size_t>(r)] != 0;
      done += is_done;
      if (!a.include_pending && !is_done) continue;
      if (!std::all_of(filters.begin(), filters.end(), [&](const Disjunction& d) { return sel.test(d, r); })) continue;
      if (!head_only || g.n_runs < a.limit) {
        append_row(g, p, r, take);
        continue;
      }
      // Beyond the --limit rows printed: counted, and what the compact default shows learns from it.
      ++w.more_matching;
      w.more_kinds.insert(p.kind(r));
      for (std::size_t c = 0; c < p.cols.size(); ++c)
        if (take[c] && g.n_runs > 0 && !w.more_varying.count(p.cols[c].name) && !same_value(p.cols[c], r, g.cols[c], 0))
          w.more_varying.insert(p.cols[c].name);
    }
  });
  if (!consistent)
    std::cerr << "kinesweep query: note: the file kept changing while it was read (a sweep is writing it)\n";
  for (const std::string& note : unheld_value_notes(conds, held)) std::cerr << "kinesweep query: note: " << note << '\n';
  w.notes_said = true;
  w.summary = std::to_string(done) + " of " + std::to_string(reader.n_runs()) + " runs done";
  return table_mode(a, g, fmt, w);
}

}  // namespace

QueryArgs& add_query_command(CLI::App& app) {
  static QueryArgs a;
  auto* q = app.add_subcommand("query", "Print rows of a results file's /runs (filtered, sorted), one run's history, or one optimisation's evaluations");
  q->add_option("file", a.file, "results file (.h5); may be one a sweep is still writing")->required();
  q->add_option("-w,--where", a.where,
                "filter, repeatable (ANDed): COL OP VALUE with OP = != < <= > >=, COL=A,B,C (any of), "
                "COL=LO..HI or LO<=COL<=HI (range), 'A | B' (either); angles in degrees unless --radians; "
                "also on --optimization evaluations")
      ->allow_extra_args(false);
  q->add_option("-c,--columns", a.columns, "comma-separated columns, or 'all' (default: table: a compact set; csv/json: all)");
  q->add_option("-s,--sort", a.sort, "sort by COL or COL:desc (repeatable or comma list; NaN last)")->allow_extra_args(false);
  q->add_option("-n,--limit", a.limit, "print at most N rows (N >= 0)")->check(CLI::Validator(check_count, "N>=0"));
  q->add_option("-f,--format", a.format, "table | csv | json (default: table; csv for --history)")
      ->check(CLI::IsMember({"table", "csv", "json"}));
  q->add_flag("--radians", a.radians, "show and filter angles in radians (as stored) instead of degrees");
  q->add_flag("--include-pending", a.include_pending, "also rows not done yet (missing values)");
  q->add_option("-g,--group-by", a.group_by, "one row per group of rows with equal COL (comma list: equal in each)");
  q->add_option("--agg", a.agg, "with --group-by, the group's columns: count, FN:COL with FN min, max, mean, median, "
                "sum, argmin, argmax (run_id of the min/max); comma list (default count)");
  q->add_option("--run", a.run, "history mode: the run id");
  q->add_option("--history", a.history, "history mode: array name(s), comma list, or 'all' (default all)");
  q->add_option("--optimization", a.optimization,
                "optimisation mode: print every evaluation of /optimizations/NAME (index, stage, start, the "
                "variables, objective, constraint, status)");
  a.format.clear();
  return a;
}

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
    const Format fmt = *parse_format(a.format.empty() ? (history ? "csv" : "table") : a.format);
    store::ResultsReader reader(a.file, v1_column_roles);
    if (optimization) return optimization_mode(a, reader, fmt);
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
