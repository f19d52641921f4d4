#include "cli/query_groups.hpp"

#include <algorithm>
#include <cmath>
#include <ostream>

namespace ks::cli {

namespace {
std::string shown_unit(const RunsColumn& c, bool radians) { return c.angle() && !radians ? "deg" : c.unit; }
}  // namespace

GroupAggregator::GroupAggregator(const QueryArgs& a, const RunsTable& t) {
  if (!a.sort.empty() || !a.columns.empty())
    throw ArgError("--group-by prints one row per group, in the order of the group values; --sort and --columns "
                   "apply to rows (use --agg to choose the group's columns)");
  for (const RunsColumn& c : t.cols) header_.push_back(&c);
  auto index = [&](const RunsColumn* c) { return static_cast<std::size_t>(c - t.cols.data()); };
  for (const std::string& name : split(a.group_by, ',')) {
    const RunsColumn* c = t.find(name);
    if (!c) throw ArgError(unknown_column_message(name, t, " in --group-by"));
    keys_.push_back(index(c));
  }
  static const std::map<std::string, Agg> fns = {{"min", Agg::min},       {"max", Agg::max},   {"mean", Agg::mean},
                                                 {"median", Agg::median}, {"sum", Agg::sum}, {"argmin", Agg::argmin},
                                                 {"argmax", Agg::argmax}};
  for (const std::string& part : split(a.agg.empty() ? "count" : a.agg, ',')) {
    if (part == "count") {
      specs_.push_back({Agg::count, 0, "count"});
      continue;
    }
    const auto colon = part.find(':');
    const std::string fn = colon == std::string::npos ? part : part.substr(0, colon);
    const auto it = fns.find(fn);
    if (it == fns.end() || colon == std::string::npos) {
      std::vector<std::string> names{"count"};
      for (auto& [k, v] : fns) names.push_back(k);
      std::string m = "--agg '" + part + "': expected count or FN:COL with FN one of min, max, mean, median, sum, "
                      "argmin, argmax (e.g. --agg min:E,count)";
      if (it == fns.end() && !fn.empty()) {
        const std::string dym = did_you_mean(fn, names);
        if (!dym.empty()) m += "; did you mean '" + dym + "'?";
      }
      throw ArgError(m);
    }
    const std::string name = part.substr(colon + 1);
    const RunsColumn* c = t.find(name);
    if (!c) throw ArgError(unknown_column_message(name, t, " in --agg '" + part + "'"));
    if (c->type == CellType::str)
      throw ArgError("--agg '" + part + "': column " + name + " holds text; " + fn + " needs a numeric column");
    specs_.push_back({it->second, index(c), fn + "(" + name + ")"});
  }
  const RunsColumn* id = t.find("run_id");
  if (id && id->type == CellType::i64) id_col_ = static_cast<std::ptrdiff_t>(index(id));
  groups_ = std::map<std::vector<Part>, Group, Less>(Less{this});
}

std::vector<std::size_t> GroupAggregator::columns() const {
  std::vector<std::size_t> out = keys_;
  for (const Spec& s : specs_)
    if (s.fn != Agg::count) out.push_back(s.col);
  return out;
}

bool GroupAggregator::Less::operator()(const std::vector<Part>& x, const std::vector<Part>& y) const {
  for (std::size_t k = 0; k < g->keys_.size(); ++k) {
    const RunsColumn& c = *g->header_[g->keys_[k]];
    if (c.type == CellType::str) {
      if (x[k].s != y[k].s) return x[k].s < y[k].s;
      continue;
    }
    const double u = x[k].num, v = y[k].num;
    const bool nu = std::isnan(u), nv = std::isnan(v);
    if (nu || nv) {
      if (nu && nv) continue;
      return nv;  // the non-NaN one first
    }
    if (u != v) return u < v;
    if (c.type == CellType::i64 && x[k].i != y[k].i) return x[k].i < y[k].i;
  }
  return false;
}

bool GroupAggregator::in_last(const RunsTable& t, std::int64_t r, const Selector& sel) const {
  if (!last_) return false;
  for (std::size_t k = 0; k < keys_.size(); ++k) {
    const RunsColumn& c = t.cols[keys_[k]];
    const Part& p = last_->first[k];
    if (c.type == CellType::str) {
      if (c.s[r] != p.s) return false;
    } else if (c.type == CellType::i64) {
      if (c.i[r] != p.i) return false;
    } else {
      const double v = sel.value(c, r);
      if (!(v == p.num || (std::isnan(v) && std::isnan(p.num)))) return false;
    }
  }
  return true;
}

void GroupAggregator::add(const RunsTable& t, std::int64_t r, const Selector& sel) {
  // rows of a group mostly follow each other: the previous row's group first (no key built)
  if (!in_last(t, r, sel)) {
    std::vector<Part> key(keys_.size());
    for (std::size_t k = 0; k < keys_.size(); ++k) {
      const RunsColumn& c = t.cols[keys_[k]];
      if (c.type == CellType::str) key[k].s = c.s[r];
      else key[k].num = sel.value(c, r);
      if (c.type == CellType::i64) key[k].i = c.i[r];
    }
    last_ = &*groups_.try_emplace(std::move(key)).first;
  }
  Group& g = last_->second;
  if (g.acc.empty()) g.acc.resize(specs_.size());
  ++g.rows;
  ++rows_;
  // run_id is the row's id in /runs (row i holds run i): the column itself is not needed to name it
  const RunsColumn* ids = id_col_ >= 0 ? &t.cols[static_cast<std::size_t>(id_col_)] : nullptr;
  const std::int64_t id = ids && !ids->i.empty() ? ids->i[r] : t.row_id(r);
  for (std::size_t j = 0; j < specs_.size(); ++j) {
    const Spec& s = specs_[j];
    if (s.fn == Agg::count) continue;
    const double x = sel.value(t.cols[s.col], r);
    if (std::isnan(x)) continue;
    Acc& a = g.acc[j];
    const bool first = a.n == 0;
    ++a.n;
    switch (s.fn) {
      case Agg::min:
      case Agg::argmin:
        if (first || x < a.best) a.best = x, a.id = id;
        break;
      case Agg::max:
      case Agg::argmax:
        if (first || x > a.best) a.best = x, a.id = id;
        break;
      case Agg::sum:
      case Agg::mean: a.sum += x; break;
      case Agg::median: a.values.push_back(x); break;
      case Agg::count: break;
    }
  }
}

void GroupAggregator::print(Format fmt, std::int64_t limit, bool radians, std::ostream& os) const {
  OutTable out;
  std::vector<std::string> converted;
  for (std::size_t k : keys_) {
    const RunsColumn& c = *header_[k];
    out.names.push_back(c.name);
    out.units.push_back(shown_unit(c, radians));
    out.csv_names.push_back(c.angle() && !radians ? c.name + " [deg]" : c.name);
    if (c.angle() && !radians) converted.push_back(c.name);
  }
  for (const Spec& s : specs_) {
    const RunsColumn* c = s.fn == Agg::count ? nullptr : header_[s.col];
    const bool value = c && s.fn != Agg::argmin && s.fn != Agg::argmax;
    const std::string unit = value ? shown_unit(*c, radians) : "";
    out.names.push_back(s.name);
    out.units.push_back(unit);
    out.csv_names.push_back(unit == "deg" && c->angle() ? s.name + " [deg]" : s.name);
  }
  for (const auto& [key, g] : groups_) {
    if (limit >= 0 && out.rows.size() >= static_cast<std::size_t>(limit)) break;
    std::vector<OutCell> row;
    for (std::size_t k = 0; k < keys_.size(); ++k) {
      const RunsColumn& c = *header_[keys_[k]];
      if (c.type == CellType::str) row.emplace_back(key[k].s);
      else if (c.type == CellType::i64) row.emplace_back(key[k].i);
      else row.emplace_back(key[k].num);
    }
    for (std::size_t j = 0; j < specs_.size(); ++j) {
      const Spec& s = specs_[j];
      const Acc& a = g.acc[j];
      if (s.fn == Agg::count) {
        row.emplace_back(g.rows);
        continue;
      }
      if (a.n == 0) {
        row.push_back(s.fn == Agg::argmin || s.fn == Agg::argmax ? OutCell{std::int64_t{-1}} : OutCell{std::nan("")});
        continue;
      }
      switch (s.fn) {
        case Agg::min:
        case Agg::max: row.emplace_back(a.best); break;
        case Agg::argmin:
        case Agg::argmax: row.emplace_back(a.id); break;
        case Agg::sum: row.emplace_back(a.sum); break;
        case Agg::mean: row.emplace_back(a.sum / static_cast<double>(a.n)); break;
        case Agg::median: {
          std::vector<double> v = a.values;
          std::sort(v.begin(), v.end());
          const std::size_t n = v.size();
          row.emplace_back(n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
          break;
        }
        case Agg::count: break;
      }
    }
    out.rows.push_back(std::move(row));
  }
  print_out(out, fmt, os);
  if (fmt == Format::table) {
    os << "(" << out.rows.size() << " of " << groups_.size() << " groups of " << rows_ << " rows"
       << (id_col_ >= 0 ? "; argmin/argmax give the run_id" : "; argmin/argmax give the row index");
    if (!converted.empty()) os << "; angles in degrees (stored in radians): " << join(converted, ", ");
    os << ")\n";
  }
}

}  // namespace ks::cli
