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

#include "cli/query_util.hpp"
#include "cli/query_where.hpp"
#include "store/store.hpp"

namespace ks::cli {

namespace {

struct SortKey {
  const RunsColumn* col;
  bool desc;
};

std::string plain_unit(const RunsColumn& c, bool radians) { return c.angle() && !radians ? "deg" : c.unit; }

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

/// Every evaluation of one /optimizations group: index, stage, start, the variables (angles in degrees
/// unless --radians), objective, constraint, status.
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
  const std::size_t d = o.dims(), n = o.size();
  OutTable out;
  auto col = [&](const std::string& name, const std::string& unit, const std::string& csv) {
    out.names.push_back(name);
    out.units.push_back(unit);
    out.csv_names.push_back(csv);
  };
  col("index", "", "index");
  col("stage", "", "stage");
  col("start", "", "start");
  std::vector<bool> deg(d, false);
  std::vector<std::string> converted;
  for (std::size_t j = 0; j < d; ++j) {
    const std::string unit = j < o.units.size() ? o.units[j] : "";
    deg[j] = unit == "rad" && !a.radians;
    col(o.variables[j], deg[j] ? "deg" : unit, deg[j] ? o.variables[j] + " [deg]" : o.variables[j]);
    if (deg[j]) converted.push_back(o.variables[j]);
  }
  col("objective", "", "objective");
  col("constraint", "", "constraint");
  col("status", "", "status");
  std::size_t rows = n;
  if (a.limit >= 0) rows = std::min<std::size_t>(rows, static_cast<std::size_t>(a.limit));
  for (std::size_t i = 0; i < rows; ++i) {
    std::vector<OutCell> row;
    row.emplace_back(static_cast<std::int64_t>(i));
    row.emplace_back(i < o.stage.size() ? o.stage[i] : std::string());
    row.emplace_back(i < o.start.size() ? o.start[i] : std::int64_t{-1});
    for (std::size_t j = 0; j < d; ++j) {
      const double v = i * d + j < o.x.size() ? o.x[i * d + j] : std::nan("");
      row.emplace_back(deg[j] ? v * kRadToDeg : v);
    }
    row.emplace_back(o.value[i]);
    row.emplace_back(i < o.constraint.size() ? o.constraint[i] : std::nan(""));
    row.emplace_back(i < o.status.size() ? o.status[i] : std::string());
    out.rows.push_back(std::move(row));
  }
  print_out(out, fmt, std::cout);
  if (fmt == Format::table) {
    std::cout << "(" << out.rows.size() << " of " << n << " evaluations of optimization " << o.name << ": minimise "
              << o.objective << "; best " << format_double(o.best_objective) << " [" << o.best_status << ", stage "
              << o.best_stage << "]";
    if (!converted.empty()) std::cout << "; angles in degrees (stored in radians): " << join(converted, ", ");
    std::cout << ")\n";
  }
  return 0;
}

int rows_mode(const QueryArgs& a, store::ResultsReader& reader, Format fmt) {
  const RunsTable t = load_runs(reader);
  if (!t.consistent)
    std::cerr << "kinesweep query: note: the file kept changing while it was read (a sweep is writing it)\n";
  Selector sel{t, a.radians};
  // Filters.
  std::vector<Condition> conds;
  std::set<const RunsColumn*> mentioned;
  for (const auto& w : a.where)
    for (auto& c : parse_where(w, t)) mentioned.insert(c.col), conds.push_back(std::move(c));
  for (const std::string& note : unheld_value_notes(conds, t, a.include_pending))
    std::cerr << "kinesweep query: note: " << note << '\n';
  // Sort keys.
  std::vector<SortKey> keys;
  for (const auto& s : a.sort) {
    for (auto& part : split(s, ',')) {
      std::string name = part;
      bool desc = false;
      if (const auto colon = part.rfind(':'); colon != std::string::npos) {
        const std::string dir = part.substr(colon + 1);
        if (dir != "desc" && dir != "asc")
          throw ArgError("--sort '" + part + "': expected COL, COL:asc or COL:desc");
        desc = dir == "desc";
        name = part.substr(0, colon);
      }
      const RunsColumn* c = t.find(name);
      if (!c) throw ArgError(unknown_column_message(name, t, " in --sort"));
      keys.push_back({c, desc});
      mentioned.insert(c);
    }
  }
  // Columns.
  std::vector<const RunsColumn*> cols;
  std::vector<std::int64_t> selected;
  for (std::int64_t r = 0; r < t.n_runs; ++r) {
    if (!a.include_pending && !t.done[static_cast<std::size_t>(r)]) continue;
    bool ok = true;
    for (std::size_t i = 0; i < conds.size() && ok; ++i) {
      if (i + 1 < conds.size() && conds[i + 1].or_prev) {
        ok = sel.test(conds[i], r) || sel.test(conds[i + 1], r);
        ++i;
      } else {
        ok = sel.test(conds[i], r);
      }
    }
    if (ok) selected.push_back(r);
  }
  const bool all = a.columns == "all" || (a.columns.empty() && fmt != Format::table);
  if (all) {
    for (auto& c : t.cols) cols.push_back(&c);
  } else if (!a.columns.empty()) {
    for (auto& name : split(a.columns, ',')) {
      if (name.empty()) continue;
      const RunsColumn* c = t.find(name);
      if (!c) throw ArgError(unknown_column_message(name, t, " in --columns"));
      cols.push_back(c);
    }
  } else {
    // Compact default: run id, block (when several), the parameters that vary, the key metrics of
    // the kinds of the rows shown, status (roles and kinds: the columns' attributes).
    std::set<std::string> kinds;
    for (auto r : selected) kinds.insert(t.kind(r));
    std::set<const RunsColumn*> key_metrics;
    for (const auto& kind : kinds)
      for (const RunsColumn* c : t.key_metrics(kind)) key_metrics.insert(c);
    auto varies = [&](const RunsColumn& c) {
      for (std::size_t i = 1; i < selected.size(); ++i) {
        const auto r0 = selected[0], r = selected[i];
        if (c.type == CellType::str ? c.s[r] != c.s[r0]
            : c.type == CellType::i64 ? c.i[r] != c.i[r0]
                                      : !(c.f[r] == c.f[r0] || (std::isnan(c.f[r]) && std::isnan(c.f[r0]))))
          return true;
      }
      return false;
    };
    for (auto& c : t.cols) {
      bool take = mentioned.count(&c) > 0 || key_metrics.count(&c) > 0;
      if (c.name == "run_id" || c.name == "status") take = true;  // bookkeeping shown always
      if ((c.name == "block" || c.role == Role::parameter) && varies(c)) take = true;
      if (take) cols.push_back(&c);
    }
  }
  // Sort (stable: ties stay in run-id order); NaN last in either direction.
  if (!keys.empty()) {
    std::stable_sort(selected.begin(), selected.end(), [&](std::int64_t x, std::int64_t y) {
      for (const SortKey& k : keys) {
        const RunsColumn& c = *k.col;
        if (c.type == CellType::str) {
          if (c.s[x] == c.s[y]) continue;
          return k.desc ? c.s[x] > c.s[y] : c.s[x] < c.s[y];
        }
        const double u = sel.value(c, x), v = sel.value(c, y);
        const bool nu = std::isnan(u), nv = std::isnan(v);
        if (nu || nv) {
          if (nu && nv) continue;
          return nv;  // the non-NaN one first
        }
        if (u == v) continue;
        return k.desc ? u > v : u < v;
      }
      return false;
    });
  }
  const std::size_t matching = selected.size();
  if (a.limit >= 0 && selected.size() > static_cast<std::size_t>(a.limit)) selected.resize(static_cast<std::size_t>(a.limit));

  OutTable out;
  std::vector<std::string> converted;
  for (const RunsColumn* c : cols) {
    out.names.push_back(c->name);
    out.units.push_back(plain_unit(*c, a.radians));
    const bool deg = c->angle() && !a.radians;
    out.csv_names.push_back(deg ? c->name + " [deg]" : c->name);
    if (deg) converted.push_back(c->name);
  }
  for (auto r : selected) {
    std::vector<OutCell> row;
    for (const RunsColumn* c : cols) {
      switch (c->type) {
        case CellType::f64: row.emplace_back(sel.value(*c, r)); break;
        case CellType::i64: row.emplace_back(c->i[r]); break;
        case CellType::str: row.emplace_back(c->s[r]); break;
      }
    }
    out.rows.push_back(std::move(row));
  }
  print_out(out, fmt, std::cout);
  if (fmt == Format::table) {
    const auto done = std::count(t.done.begin(), t.done.end(), std::uint8_t{1});
    std::cout << "(" << out.rows.size() << " of " << matching << " matching rows; " << done << " of " << t.n_runs
              << " runs done";
    if (!converted.empty()) std::cout << "; angles in degrees (stored in radians): " << join(converted, ", ");
    if (a.columns.empty()) std::cout << "; --columns all shows every column";
    std::cout << ")\n";
  }
  return 0;
}

}  // namespace

QueryArgs& add_query_command(CLI::App& app) {
  static QueryArgs a;
  auto* q = app.add_subcommand("query", "Print rows of a results file's /runs (filtered, sorted), one run's history, or one optimisation's evaluations");
  q->add_option("file", a.file, "results file (.h5); may be one a sweep is still writing")->required();
  q->add_option("-w,--where", a.where,
                "filter, repeatable (ANDed): COL OP VALUE with OP = != < <= > >=, COL=A,B,C (any of), "
                "COL=LO..HI or LO<=COL<=HI (range); angles in degrees unless --radians")
      ->allow_extra_args(false);
  q->add_option("-c,--columns", a.columns, "comma-separated columns, or 'all' (default: table: a compact set; csv/json: all)");
  q->add_option("-s,--sort", a.sort, "sort by COL or COL:desc (repeatable or comma list; NaN last)")->allow_extra_args(false);
  q->add_option("-n,--limit", a.limit, "print at most N rows (N >= 0)")->check(CLI::Validator(check_count, "N>=0"));
  q->add_option("-f,--format", a.format, "table | csv | json (default: table; csv for --history)")
      ->check(CLI::IsMember({"table", "csv", "json"}));
  q->add_flag("--radians", a.radians, "show and filter angles in radians (as stored) instead of degrees");
  q->add_flag("--include-pending", a.include_pending, "also rows not done yet (missing values)");
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
    if (optimization && (history || !a.where.empty() || !a.sort.empty() || !a.columns.empty() || a.include_pending))
      throw ArgError("--optimization prints one optimisation's evaluations; --run, --history, --where, --sort, "
                     "--columns and --include-pending do not apply to it (--format, --limit and --radians do)");
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
