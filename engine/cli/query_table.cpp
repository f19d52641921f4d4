// `kinesweep query` on a table in memory (see query_table.hpp).
#include "cli/query_table.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <set>

#include "cli/query_groups.hpp"
#include "cli/query_where.hpp"

namespace ks::cli {

namespace {

struct SortKey {
  const RunsColumn* col;
  bool desc;
};

std::string shown_unit(const RunsColumn& c, bool radians) { return c.angle() && !radians ? "deg" : c.unit; }

std::vector<SortKey> parse_sort(const QueryArgs& a, const RunsTable& t) {
  std::vector<SortKey> keys;
  for (const auto& s : a.sort) {
    for (auto& part : split(s, ',')) {
      std::string name = part;
      bool desc = false;
      if (const auto colon = part.rfind(':'); colon != std::string::npos) {
        const std::string dir = part.substr(colon + 1);
        if (dir != "desc" && dir != "asc") throw ArgError("--sort '" + part + "': expected COL, COL:asc or COL:desc");
        desc = dir == "desc";
        name = part.substr(0, colon);
      }
      const RunsColumn* c = t.find(name);
      if (!c) throw ArgError(unknown_column_message(name, t, " in --sort"));
      keys.push_back({c, desc});
    }
  }
  return keys;
}

/// Stable sort (ties stay in row order); NaN last in either direction.
void sort_rows(std::vector<std::int64_t>& rows, const std::vector<SortKey>& keys, const Selector& sel) {
  if (keys.empty()) return;
  std::stable_sort(rows.begin(), rows.end(), [&](std::int64_t x, std::int64_t y) {
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

OutCell cell(const RunsColumn& c, std::int64_t r, const Selector& sel) {
  switch (c.type) {
    case CellType::f64: return sel.value(c, r);
    case CellType::i64: return c.i[r];
    case CellType::str: return c.s[r];
  }
  return {};
}

/// The default columns of table output: run id, block (when several), the parameters that vary, the
/// key metrics of the kinds of the rows shown, status, every column a filter or sort mentions, and
/// the columns the wording names (`shown`).
std::vector<const RunsColumn*> compact_columns(const RunsTable& t, const std::vector<std::int64_t>& selected,
                                               const std::set<const RunsColumn*>& mentioned,
                                               const TableWording& more) {
  std::set<std::string> kinds = more.more_kinds;
  for (auto r : selected) kinds.insert(t.kind(r));
  std::set<const RunsColumn*> key_metrics;
  for (const auto& kind : kinds)
    for (const RunsColumn* c : t.key_metrics(kind)) key_metrics.insert(c);
  auto varies = [&](const RunsColumn& c) {
    if (more.more_varying.count(c.name)) return true;
    for (std::size_t i = 1; i < selected.size(); ++i) {
      const auto r0 = selected[0], r = selected[i];
      if (c.type == CellType::str ? c.s[r] != c.s[r0]
          : c.type == CellType::i64 ? c.i[r] != c.i[r0]
                                    : !(c.f[r] == c.f[r0] || (std::isnan(c.f[r]) && std::isnan(c.f[r0]))))
        return true;
    }
    return false;
  };
  std::vector<const RunsColumn*> cols;
  for (auto& c : t.cols) {
    bool take = mentioned.count(&c) > 0 || key_metrics.count(&c) > 0;
    if (c.name == "run_id" || c.name == "status") take = true;  // bookkeeping shown always
    if (std::find(more.shown.begin(), more.shown.end(), c.name) != more.shown.end()) take = true;
    if ((c.name == "block" || c.role == Role::parameter) && varies(c)) take = true;
    if (take) cols.push_back(&c);
  }
  return cols;
}

}  // namespace

void sort_table_rows(std::vector<std::int64_t>& rows, const QueryArgs& a, const RunsTable& t) {
  sort_rows(rows, parse_sort(a, t), Selector{t, a.radians});
}

std::vector<bool> columns_read(const QueryArgs& a, const RunsTable& t, Format fmt, const TableWording& wording) {
  std::vector<bool> take(t.cols.size(), false);
  auto mark = [&](const std::string& name, const char* where) {
    const RunsColumn* c = t.find(name);
    if (!c) throw ArgError(unknown_column_message(name, t, where));
    take[static_cast<std::size_t>(c - t.cols.data())] = true;
  };
  for (const auto& w : a.where)
    for (const Condition& k : all_conditions({parse_where(w, t)})) take[static_cast<std::size_t>(k.col - t.cols.data())] = true;
  for (const SortKey& k : parse_sort(a, t)) take[static_cast<std::size_t>(k.col - t.cols.data())] = true;
  for (const std::string& name : split(a.group_by, ','))
    if (!name.empty()) mark(name, " in --group-by");
  if (!a.group_by.empty())
    for (std::size_t c : GroupAggregator(a, t).columns()) take[c] = true;
  if (t.find("run_id") && a.group_by.empty()) mark("run_id", "");
  const bool all = a.columns == "all" || (a.columns.empty() && (fmt != Format::table || !wording.compact_default));
  for (std::size_t c = 0; c < t.cols.size(); ++c) {
    const RunsColumn& col = t.cols[c];
    if (all) take[c] = true;
    if (a.columns.empty() && a.group_by.empty() &&
        (col.role != Role::bookkeeping || col.name == "block" || col.name == "status"))
      take[c] = true;  // the compact default's candidates, and what a row's kind is read from
  }
  if (!all && a.group_by.empty())
    for (const std::string& name : split(a.columns, ','))
      if (!name.empty()) mark(name, " in --columns");
  return take;
}

int table_mode(const QueryArgs& a, const RunsTable& t, Format fmt, const TableWording& wording) {
  Selector sel{t, a.radians};
  std::vector<Disjunction> filters;
  for (const auto& w : a.where) filters.push_back(parse_where(w, t));
  const std::vector<Condition> conds = all_conditions(filters);
  if (!wording.notes_said)
    for (const std::string& note : unheld_value_notes(conds, t, a.include_pending))
      std::cerr << "kinesweep query: note: " << note << '\n';
  std::set<const RunsColumn*> mentioned;
  for (const Condition& c : conds) mentioned.insert(c.col);
  const std::vector<SortKey> keys = parse_sort(a, t);
  for (const SortKey& k : keys) mentioned.insert(k.col);

  std::vector<std::int64_t> selected;
  for (std::int64_t r = 0; r < t.n_runs; ++r) {
    if (!a.include_pending && !t.done[static_cast<std::size_t>(r)]) continue;
    if (std::all_of(filters.begin(), filters.end(), [&](const Disjunction& d) { return sel.test(d, r); }))
      selected.push_back(r);
  }
  if (!a.group_by.empty()) {
    GroupAggregator groups(a, t);
    for (std::int64_t r : selected) groups.add(t, r, sel);
    groups.print(fmt, a.limit, a.radians, std::cout);
    return 0;
  }
  if (!a.agg.empty()) throw ArgError("--agg needs --group-by COL (e.g. --group-by method --agg min:E,count)");

  std::vector<const RunsColumn*> cols;
  if (a.columns == "all" || (a.columns.empty() && (fmt != Format::table || !wording.compact_default))) {
    for (auto& c : t.cols) cols.push_back(&c);
  } else if (!a.columns.empty()) {
    for (auto& name : split(a.columns, ',')) {
      if (name.empty()) continue;
      const RunsColumn* c = t.find(name);
      if (!c) throw ArgError(unknown_column_message(name, t, " in --columns"));
      cols.push_back(c);
    }
  } else {
    cols = compact_columns(t, selected, mentioned, wording);
  }
  sort_rows(selected, keys, sel);
  const std::size_t matching = selected.size() + static_cast<std::size_t>(wording.more_matching);
  if (a.limit >= 0 && selected.size() > static_cast<std::size_t>(a.limit)) selected.resize(static_cast<std::size_t>(a.limit));

  OutTable out;
  std::vector<std::string> converted;
  for (const RunsColumn* c : cols) {
    const bool deg = c->angle() && !a.radians;
    out.names.push_back(c->name);
    out.units.push_back(shown_unit(*c, a.radians));
    out.csv_names.push_back(deg ? c->name + " [deg]" : c->name);
    if (deg) converted.push_back(c->name);
  }
  for (auto r : selected) {
    std::vector<OutCell> row;
    for (const RunsColumn* c : cols) row.push_back(cell(*c, r, sel));
    out.rows.push_back(std::move(row));
  }
  print_out(out, fmt, std::cout);
  if (fmt == Format::table) {
    std::cout << "(" << out.rows.size() << " of " << matching << " " << wording.rows;
    if (!wording.summary.empty()) std::cout << "; " << wording.summary;
    if (!converted.empty()) std::cout << "; angles in degrees (stored in radians): " << join(converted, ", ");
    if (a.columns.empty() && wording.compact_default) std::cout << "; --columns all shows every column";
    std::cout << ")\n";
  }
  return 0;
}

}  // namespace ks::cli
