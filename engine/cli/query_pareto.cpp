// `kinesweep query --pareto` (see query_pareto.hpp).
#include "cli/query_pareto.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>

#include "cli/kind_meaning.hpp"
#include "cli/query_table.hpp"
#include "cli/query_where.hpp"
#include "pareto/pareto.hpp"

namespace ks::cli {

namespace {

struct Objective {
  std::size_t col;  ///< index into the table's columns
  pareto::Sense sense;
};

std::vector<Objective> parse_objectives(const std::string& spec, const RunsTable& t) {
  const std::string where = " in --pareto '" + spec + "'";
  std::vector<Objective> out;
  for (const std::string& part : split(spec, ',')) {
    std::string name = part, dir = "min";
    if (const auto colon = part.rfind(':'); colon != std::string::npos) {
      name = trim(part.substr(0, colon));
      dir = trim(part.substr(colon + 1));
    }
    if (name.empty()) throw ArgError("--pareto '" + spec + "': an empty metric name; expected M1,M2[,M3], each COL, COL:min or COL:max");
    if (dir != "min" && dir != "max") {
      std::string m = "--pareto '" + spec + "': '" + part + "': expected COL, COL:min or COL:max";
      const std::string dym = did_you_mean(dir, {"min", "max"});
      if (!dym.empty()) m += "; did you mean '" + name + ":" + dym + "'?";
      throw ArgError(m);
    }
    const RunsColumn* c = t.find(name);
    if (!c) throw ArgError(unknown_column_message(name, t, where));
    if (c->type == CellType::str)
      throw ArgError("--pareto '" + spec + "': column " + name + " holds text; a front needs numeric columns");
    const std::size_t col = static_cast<std::size_t>(c - t.cols.data());
    if (std::any_of(out.begin(), out.end(), [&](const Objective& o) { return o.col == col; }))
      throw ArgError("--pareto '" + spec + "': " + name + " is named twice");
    out.push_back({col, dir == "max" ? pareto::Sense::max : pareto::Sense::min});
  }
  if (out.size() < 2 || out.size() > 3)
    throw ArgError("--pareto '" + spec + "': " + std::to_string(out.size()) +
                   " metric(s); a front needs 2 or 3 (e.g. --pareto E,min_manipulability:max)");
  return out;
}

std::vector<double> parse_reference(const std::string& spec, std::size_t dims) {
  std::vector<double> ref;
  for (const std::string& part : split(spec, ',')) {
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || std::isnan(v))
      throw ArgError("--hypervolume '" + spec + "': '" + part + "' is not a number");
    ref.push_back(v);
  }
  if (ref.size() != dims)
    throw ArgError("--hypervolume '" + spec + "': " + std::to_string(ref.size()) + " value(s) for " +
                   std::to_string(dims) + " --pareto metrics; the reference point needs one per metric");
  return ref;
}

std::string sense_name(pareto::Sense s) { return s == pareto::Sense::max ? "max" : "min"; }

}  // namespace

int pareto_mode(const QueryArgs& a, store::ResultsReader& reader, Format fmt) {
  RunsTable t = runs_header(reader);
  const std::vector<Objective> objectives = parse_objectives(a.pareto, t);
  const std::size_t dims = objectives.size();
  std::vector<pareto::Sense> senses;
  for (const Objective& o : objectives) senses.push_back(o.sense);
  const std::vector<double> ref = a.hypervolume.empty() ? std::vector<double>{} : parse_reference(a.hypervolume, dims);
  std::vector<Disjunction> filters;
  for (const auto& expr : a.where) filters.push_back(parse_where(expr, t));
  const std::vector<Condition> conds = all_conditions(filters);
  TableWording w;
  std::vector<bool> take = columns_read(a, t, fmt, w);  // checks --columns and --sort too

  // One pass over the pieces: the --where columns, the metrics, status and what a row's kind is read from.
  const RunsColumn* status = t.find("status");
  if (!status || status->type != CellType::str) throw ArgError("the file's /runs has no status column");
  t.load_all(false);
  t.load_kind_columns();
  for (const Condition& k : conds) t.cols[static_cast<std::size_t>(k.col - t.cols.data())].loaded = true;
  for (const Objective& o : objectives) t.cols[o.col].loaded = true;
  t.cols[static_cast<std::size_t>(status - t.cols.data())].loaded = true;
  std::vector<bool> loaded(t.cols.size());
  for (std::size_t c = 0; c < t.cols.size(); ++c) loaded[c] = t.cols[c].loaded;
  const Selector sel{t, a.radians};
  std::map<std::string, KindMeaning> meanings;
  // The candidates: the front so far and the good rows with values read since it was last reduced to
  // its front (a point off the front of some rows is off the front of any superset of them), so that
  // memory is bounded by the front and a few pieces, whatever the file's size.
  std::vector<std::int64_t> ids;
  std::vector<double> values;
  auto reduce = [&] {
    std::vector<std::int64_t> kept_ids;
    std::vector<double> kept_values;
    for (std::size_t i : pareto::front(values, dims, senses)) {
      kept_ids.push_back(ids[i]);
      kept_values.insert(kept_values.end(), values.begin() + static_cast<std::ptrdiff_t>(i * dims),
                         values.begin() + static_cast<std::ptrdiff_t>((i + 1) * dims));
    }
    ids = std::move(kept_ids), values = std::move(kept_values);
  };
  std::size_t reduced_size = 0;
  std::int64_t matching = 0, bad_status = 0, no_value = 0;
  HeldValues held;
  bool consistent = true;
  const std::int64_t total = reader.n_runs();
  std::vector<double> point(dims);
  for (std::int64_t first = 0; first < total; first += kPieceRows) {
    for (std::size_t c = 0; c < t.cols.size(); ++c) t.cols[c].loaded = loaded[c];
    load_piece(reader, t, first, kPieceRows);
    consistent = consistent && t.consistent;
    collect_held(conds, t, false, held);
    for (std::int64_t r = 0; r < t.n_runs; ++r) {
      if (!t.done[static_cast<std::size_t>(r)]) continue;
      if (!std::all_of(filters.begin(), filters.end(), [&](const Disjunction& d) { return sel.test(d, r); })) continue;
      ++matching;
      const std::string kind = t.kind(r);
      auto it = meanings.find(kind);
      if (it == meanings.end()) it = meanings.emplace(kind, kind_meaning(t.meta, kind)).first;
      if (!it->second.is_good(status->s[static_cast<std::size_t>(r)])) {
        ++bad_status;
        continue;
      }
      bool nan = false;
      for (std::size_t k = 0; k < dims; ++k) {
        const RunsColumn& c = t.cols[objectives[k].col];
        point[k] = c.missing(r) ? std::nan("") : sel.value(c, r);  // an integer column's -1: no value
        nan = nan || std::isnan(point[k]);
      }
      if (nan) {
        ++no_value;
        continue;
      }
      values.insert(values.end(), point.begin(), point.end());
      ids.push_back(t.row_id(r));
    }
    if (ids.size() > reduced_size + static_cast<std::size_t>(4 * kPieceRows)) {
      reduce();
      reduced_size = ids.size();
    }
  }
  if (!consistent)
    std::cerr << "kinesweep query: note: the file kept changing while it was read (a sweep is writing it)\n";
  for (const std::string& note : unheld_value_notes(conds, held)) std::cerr << "kinesweep query: note: " << note << '\n';
  reduce();  // rows in run-id order: the front's ids ascend
  std::vector<std::size_t> on_front(ids.size());
  for (std::size_t i = 0; i < on_front.size(); ++i) on_front[i] = i;

  std::vector<std::string> names, described;
  for (const Objective& o : objectives) {
    names.push_back(t.cols[o.col].name);
    described.push_back(t.cols[o.col].name + " " + sense_name(o.sense));
  }
  const std::int64_t candidates = matching - bad_status - no_value;
  std::string counted = std::to_string(candidates) + " good runs with values";
  if (bad_status) counted += "; " + std::to_string(bad_status) + " of another status left out";
  if (no_value) counted += "; " + std::to_string(no_value) + " without a value left out";

  if (!ref.empty()) {
    std::vector<double> front_values;
    std::int64_t inside = 0;
    for (std::size_t i : on_front) {
      bool in = true;
      for (std::size_t k = 0; k < dims; ++k) {
        const double v = values[i * dims + k];
        front_values.push_back(v);
        in = in && (senses[k] == pareto::Sense::min ? v < ref[k] : v > ref[k]);
      }
      inside += in;
    }
    OutTable out;
    std::string unit;
    for (const Objective& o : objectives) {
      const RunsColumn& c = t.cols[o.col];
      const std::string u = c.angle() && !a.radians ? "deg" : c.unit.empty() ? "1" : c.unit;
      unit += (unit.empty() ? "" : "*") + (u.find(' ') == std::string::npos ? u : "(" + u + ")");
    }
    out.names = {"hypervolume", "front_runs", "front_runs_inside", "good_runs"};
    out.units = {unit, "", "", ""};
    for (std::size_t k = 0; k < dims; ++k) {
      const RunsColumn& c = t.cols[objectives[k].col];
      out.names.push_back("reference_" + c.name);
      out.units.push_back(c.angle() && !a.radians ? "deg" : c.unit);
    }
    out.csv_names = out.names;
    std::vector<OutCell> row = {pareto::hypervolume(front_values, dims, senses, ref),
                                static_cast<std::int64_t>(on_front.size()), inside, candidates};
    for (double v : ref) row.emplace_back(v);
    out.rows.push_back(std::move(row));
    print_out(out, fmt, std::cout);
    if (fmt == Format::table)
      std::cout << "(front of " << join(described, ", ") << " over " << counted
                << "; the region the front dominates up to the reference point)\n";
    return 0;
  }

  // The front's runs, with the columns the query prints, through table_mode.
  std::vector<std::int64_t> front_ids;
  for (std::size_t i : on_front) front_ids.push_back(ids[i]);
  RunsTable g = runs_header(reader);
  for (std::size_t c = 0; c < g.cols.size(); ++c) g.cols[c].loaded = take[c] || loaded[c];
  load_ids(reader, g, front_ids);
  QueryArgs shown = a;
  shown.where.clear();  // applied above
  if (shown.sort.empty())
    for (const Objective& o : objectives)
      shown.sort.push_back(g.cols[o.col].name + (o.sense == pareto::Sense::max ? ":desc" : ""));
  w.rows = "runs on the front";
  w.summary = "front of " + join(described, ", ") + " over " + counted;
  w.notes_said = true;
  w.shown = names;
  return table_mode(shown, g, fmt, w);
}

}  // namespace ks::cli
