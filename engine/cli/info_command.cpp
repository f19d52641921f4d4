#include "cli/info_command.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <iomanip>
#include <limits>
#include <tuple>
#include <map>
#include <sstream>

#include "cli/kind_meaning.hpp"
#include "cli/query_util.hpp"
#include "schema/params.hpp"
#include "runner/verify_best.hpp"
#include "store/store.hpp"

namespace ks::cli {

namespace {

/// A block's rows as info summarises them, gathered piece by piece (bounded memory).
struct BlockSummary {
  std::string name, kind;
  std::int64_t rows = 0;  ///< all rows of the block (done or not)
  std::int64_t done = 0, good_runs = 0;  ///< good_runs: done runs whose status is ok / converged
  std::vector<std::pair<std::string, std::int64_t>> statuses;  ///< first-seen order
  std::vector<RankKey> best;    ///< its best good runs under ranking(kind), at most --best
  RunsTable first;              ///< its first done row (parameters that differ from it vary)
  std::vector<bool> varies;     ///< per column
  // Its kind's ranking, once its kind is known: the good status and the ranked columns.
  bool ranked = false;
  std::string good;
  const RunsColumn* key = nullptr;
  const RunsColumn* tie = nullptr;
};

std::string cell_for_humans(const RunsColumn& c, std::int64_t r) {
  switch (c.type) {
    case CellType::str: return c.s[r];
    case CellType::i64: return std::to_string(c.i[r]);
    case CellType::f64: return format_double(c.angle() ? c.f[r] * kRadToDeg : c.f[r]) + (c.angle() ? " deg" : "");
  }
  return "";
}

/// A value of variable `unit` for humans: angles (stored "rad") in degrees.
std::string var_value(double v, const std::string& unit) {
  if (unit == "rad") return format_double(v * kRadToDeg) + " deg";
  return format_double(v) + (unit.empty() ? "" : " " + unit);
}

std::string point_text(const store::OptimizationRecord& o, const std::vector<double>& x) {
  std::string s;
  for (std::size_t i = 0; i < o.variables.size() && i < x.size(); ++i)
    s += (i ? ", " : "") + o.variables[i] + " = " + var_value(x[i], i < o.units.size() ? o.units[i] : "");
  return s;
}

std::string seconds(double s) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(s < 10 ? 3 : 1) << s << " s";
  return o.str();
}

/// The /optimizations section (nothing when the file has none). Metric units: the /runs columns'.
/// False when the kind's table says parameter `c` has no effect on row `r` (its controlling column,
/// e.g. method, holds a value outside the parameter's effect rule).
bool has_effect_in_row(const RunsTable& t, const std::string& kind, const RunsColumn& c, std::int64_t r) {
  BlockKind k{};
  if (!parse(kind, k)) return true;
  const auto table = params(k);
  const ParamDef* p = find_param(table, c.name);
  if (!p || p->effect.always()) return true;
  const RunsColumn* ctl = t.find(p->effect.controller);
  return !ctl || ctl->type != CellType::str || p->effect.applies(ctl->s[r]);
}

/// The /runs columns by role and run kind, with their units (from the columns' attributes).
void print_columns(const RunsTable& t, std::ostream& os) {
  std::vector<std::string> kinds;
  for (const RunsColumn& c : t.cols)
    for (const std::string& k : c.kinds)
      if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) kinds.push_back(k);
  auto line = [&](const char* label, Role role, const std::string* kind) {
    std::string names;
    for (const RunsColumn& c : t.cols)
      if (c.role == role && (!kind || c.applies_to(*kind)))
        names += (names.empty() ? "" : ", ") + c.name + (c.unit.empty() ? "" : " [" + c.unit + "]");
    if (names.empty()) return;
    os << "            " << label << (kind ? " " + *kind : std::string()) << ": " << names << '\n';
  };
  os << "columns     (role and kinds from the columns' attributes; kinesweep schema describes each)\n";
  for (const std::string& k : kinds) line("parameters", Role::parameter, &k);
  for (const std::string& k : kinds) line("metrics", Role::metric, &k);
  line("bookkeeping", Role::bookkeeping, nullptr);
}

void print_optimizations(store::ResultsReader& reader, const RunsTable& t, std::ostream& os) {
  const auto names = consistent_read(reader, [&] { return reader.optimizations(); });
  if (names.empty()) return;
  os << "optimizations " << names.size() << "  (kinesweep query FILE --optimization NAME: every evaluation)\n";
  for (const auto& name : names) {
    const store::OptimizationRecord o = consistent_read(reader, [&] { return reader.read_optimization(name); });
    const auto unit = [&](std::size_t i) { return i < o.units.size() ? o.units[i] : std::string(); };
    os << "  " << o.name << ": " << (o.kind.empty() ? "trajectory" : o.kind)
       << (o.preset.empty() ? "" : ", preset " + o.preset) << ", minimise " << o.objective << '\n';
    os << "    variables   ";
    for (std::size_t i = 0; i < o.variables.size(); ++i) {
      const bool deg = unit(i) == "rad";
      const double k = deg ? kRadToDeg : 1.0;
      os << (i ? ", " : "") << o.variables[i] << " in [" << format_double(o.lower.at(i) * k) << ", "
         << format_double(o.upper.at(i) * k) << "]";
      if (deg) os << " deg";
      else if (!unit(i).empty()) os << ' ' << unit(i);
    }
    os << '\n';
    os << "    evaluations " << o.size() << " in " << seconds(o.wall_time_s) << " (seed " << o.seed << ")\n";
    std::size_t wa = 9;
    for (const auto& st : o.stages) wa = std::max(wa, st.algorithm.size());
    for (std::size_t i = 0; i < o.stages.size(); ++i) {
      const auto& st = o.stages[i];
      os << (i ? "                " : "    stages      ") << std::left << std::setw(7) << st.name
         << std::setw(static_cast<int>(wa)) << (st.algorithm.empty() ? "-" : st.algorithm) << std::right
         << std::setw(8) << st.evaluations << " evals" << std::setw(11) << seconds(st.wall_time_s) << "  best "
         << std::left << std::setw(12) << format_double(st.best_objective) << std::right << " [" << st.best_status
         << "]  " << st.result << '\n';
    }
    os << "    best        " << o.objective << " = " << format_double(o.best_objective) << " [" << o.best_status
       << ", stage " << o.best_stage << "] at " << point_text(o, o.best_x) << '\n';
    if (!o.best_metrics.empty()) {
      auto metric = [&](const std::string& k) -> const double* {
        for (const auto& [n, v] : o.best_metrics)
          if (n == k) return &v;
        return nullptr;
      };
      auto with_unit = [&](const std::string& k, double v) {
        const RunsColumn* c = t.find(k);
        return format_double(v) + (c && !c->unit.empty() ? " " + c->unit : "");
      };
      // The kind's key metrics (E_M only when the objective names it), a peak torque followed by the
      // joints' own (tau<i>_inf); else every metric of the run.
      std::vector<std::string> parts;
      for (const std::string& k : kind_meaning(t.meta, o.kind).key_metrics) {
          const double* v = metric(k);
          if (!v || (k == "E_M" && o.objective.find(k) == std::string::npos)) continue;
          std::string s = k + " = " + with_unit(k, *v);
          std::vector<std::string> joints;
          for (int j = 1; k.ends_with("_inf"); ++j) {
            const double* p = metric(k.substr(0, k.size() - 4) + std::to_string(j) + "_inf");
            if (!p) break;
            joints.push_back(format_double(*p));
          }
          if (!joints.empty()) s += " (joints " + join(joints, ", ") + ")";
          parts.push_back(s);
        }
      if (parts.empty())
        for (const auto& [k, v] : o.best_metrics) parts.push_back(k + " = " + format_double(v));
      os << "    best run    " << join(parts, ", ") << '\n';
    }
    if (!o.reference.empty()) {
      auto ref = [&](const std::string& k) -> const double* {
        for (const auto& [n, v] : o.reference)
          if (n == k) return &v;
        return nullptr;
      };
      // a normalised objective: the design and metrics at its reference, the best beside them
      std::vector<double> rx;
      for (const auto& v : o.variables)
        if (const double* p = ref(v + "_0")) rx.push_back(*p);
      if (rx.size() == o.variables.size() && !rx.empty()) {
        os << "    reference   at " << point_text(o, rx);
        const double* k = ref("trade_off_k");
        if (k) os << " (trade_off k = " << format_double(*k) << ")";
        os << '\n';
        for (const auto& [m, best] : o.best_metrics)
          if (const double* r = ref(m + "_0"))
            os << "                " << m << " = " << format_double(*r) << " there, " << format_double(best)
               << " at the best (x " << format_double(best / *r) << ")\n";
      }
      if (!ref("thesis_E")) continue;
      os << "    thesis      ";
      if (const double* e = ref("thesis_E")) os << "E = " << format_double(*e);
      std::vector<double> tx;
      bool all = true;
      for (const auto& v : o.variables) {
        const double* p = ref("thesis_" + v);
        if (!p) all = false;
        tx.push_back(p ? *p : std::nan(""));
      }
      if (all && !o.variables.empty()) os << " at " << point_text(o, tx);
      std::vector<std::string> taus;
      for (const char* t : {"thesis_tau1_inf", "thesis_tau2_inf", "thesis_tau3_inf"})
        if (const double* p = ref(t)) taus.push_back(format_double(*p));
      if (!taus.empty()) os << "; |tau|inf per joint " << join(taus, ", ");
      if (const double* ob = ref("objective_at_thesis_x"))
        os << "\n                kinesweep's " << o.objective << " at the thesis point = " << format_double(*ob);
      os << '\n';
    }
  }
}

std::string axis_text(const store::LandscapeAxis& a) {
  std::ostringstream o;
  o << a.name << " (" << a.values.size();
  if (!a.coordinates.empty()) {  // a sampled dimension: the parameters along it
    o << ": ";
    for (std::size_t i = 0; i < a.coordinates.size(); ++i) o << (i ? ", " : "") << axis_text(a.coordinates[i]);
  } else if (a.unit.rfind("labels:", 0) == 0) {
    o << ": " << a.unit.substr(7);
  } else if (!a.values.empty()) {
    const bool deg = a.unit == "rad";
    const double k = deg ? kRadToDeg : 1.0;
    // Grid axes in their order (a descending one stays descending); drawn ones (random, LHS) by range.
    const bool up = std::is_sorted(a.values.begin(), a.values.end());
    const bool down = std::is_sorted(a.values.rbegin(), a.values.rend());
    const auto [lo, hi] = std::minmax_element(a.values.begin(), a.values.end());
    const double first = up || down ? a.values.front() : *lo, last = up || down ? a.values.back() : *hi;
    o << (up || down ? ", " : ", drawn in ") << format_double(first * k) << " .. " << format_double(last * k);
    if (deg) o << " deg";
    else if (!a.unit.empty()) o << " " << a.unit;
  }
  o << ")";
  return o.str();
}

/// The value of numeric column c at row r, as a double.
double value_at(const RunsColumn* c, std::int64_t r) {
  return c->type == CellType::i64 ? static_cast<double>(c->i[r]) : c->f[r];
}

/// The metric column `name` of kind `kind` in t, or null.
const RunsColumn* metric_column(const RunsTable& t, const std::string& kind, std::string_view name) {
  const RunsColumn* c = t.find(std::string(name));
  return c && c->role == Role::metric && c->applies_to(kind) ? c : nullptr;
}

int run_info(const InfoArgs& args) {
  store::ResultsReader reader(args.file, v1_column_roles);
  RunsTable t = runs_header(reader);
  const store::StoreMeta& m = t.meta;
  std::ostream& os = std::cout;
  const std::size_t n_best = static_cast<std::size_t>(std::max(0, args.best));
  const std::int64_t n_runs = reader.n_runs();

  // One pass over the rows, piece by piece: blocks in run-id order, status counts, best rows, the
  // parameters that vary, and which done runs hold a history.
  std::vector<BlockSummary> blocks;
  std::int64_t n_done = 0, with = 0, first_h = -1, last_h = -1;
  std::map<std::string, std::int64_t> example;  // kind -> a run with a history
  const RunsColumn* block = t.find("block");
  const RunsColumn* status = t.find("status");
  // The columns the summary reads: block, status, the parameters, the kinds' ranked metrics and
  // what a row's kind is read from (the others are read for the best rows only, by run id).
  t.load_all(false);
  t.load_kind_columns();
  for (RunsColumn& c : t.cols) {
    if (&c == block || &c == status || c.role == Role::parameter) c.loaded = true;
    for (const std::string& k : declared_kinds(m)) {
      const KindMeaning km = kind_meaning(m, k);
      if (c.role == Role::metric && (c.name == km.objective() || c.name == km.tie())) c.loaded = true;
    }
  }
  std::vector<bool> loaded;
  for (const RunsColumn& c : t.cols) loaded.push_back(c.loaded);
  std::size_t at = 0;  // the block of the previous row (rows of a block mostly follow each other)
  const bool consistent = for_each_piece(reader, t, [&](const RunsTable& p) {
    const bool any_history = reader.has_histories();  // else no row is asked (a lookup per row)
    for (std::int64_t r = 0; r < p.n_runs; ++r) {
      const std::int64_t id = p.row_id(r);
      static const std::string all("(all)");
      const std::string& name = block ? block->s[r] : all;
      const bool is_done = p.done[static_cast<std::size_t>(r)] != 0;
      if (name.empty() && !is_done) {  // a pending row holds no block name: count it apart
        if (blocks.empty() || blocks.back().name != "(pending)") blocks.push_back(BlockSummary{}), blocks.back().name = "(pending)";
        ++blocks.back().rows;
        continue;
      }
      if (at >= blocks.size() || blocks[at].name != name) {
        auto it = std::find_if(blocks.begin(), blocks.end(), [&](const BlockSummary& b) { return b.name == name; });
        if (it == blocks.end()) {
          blocks.push_back(BlockSummary{}), blocks.back().name = name;
          it = blocks.end() - 1;
        }
        at = static_cast<std::size_t>(it - blocks.begin());
      }
      BlockSummary& b = blocks[at];
      ++b.rows;
      if (!is_done) continue;
      ++n_done;
      ++b.done;
      if (b.kind.empty()) b.kind = p.kind(r);
      static const std::string none;
      const std::string& st = status ? status->s[r] : none;
      auto s = std::find_if(b.statuses.begin(), b.statuses.end(), [&](auto& x) { return x.first == st; });
      if (s == b.statuses.end()) b.statuses.push_back({st, 1});
      else ++s->second;
      // Parameters that differ from the block's first done row.
      if (b.first.cols.empty()) {
        b.first = runs_header(reader);
        append_row(b.first, p, r, loaded);
        b.varies.assign(p.cols.size(), false);
      }
      for (std::size_t c = 0; c < p.cols.size(); ++c)
        if (!b.varies[c] && p.cols[c].role == Role::parameter && !same_value(p.cols[c], r, b.first.cols[c], 0))
          b.varies[c] = true;
      // Best rows: the kind's ranking among its good runs, as the file declares them.
      if (!b.ranked && !b.kind.empty()) {
        const KindMeaning km = kind_meaning(m, b.kind);
        if (km.known && !km.objective().empty()) {
          b.ranked = true;
          b.good = km.good();
          b.key = metric_column(p, b.kind, km.objective());
          b.tie = km.tie().empty() ? nullptr : metric_column(p, b.kind, km.tie());
        }
      }
      if (b.ranked && st == b.good) {
        const RunsColumn* key = b.key;
        if (key) ++b.good_runs;
        if (key && n_best > 0) {
          const RunsColumn* tie = b.tie;
          const RankKey c = rank_key(value_at(key, r), tie ? value_at(tie, r) : 0.0, static_cast<std::uint64_t>(id));
          // as the run summary: a good run without a finite objective is never a best one
          if (std::isfinite(c.objective) && (b.best.size() < n_best || c < b.best.back())) {
            b.best.insert(std::upper_bound(b.best.begin(), b.best.end(), c), c);
            if (b.best.size() > n_best) b.best.pop_back();
          }
        }
      }
      if (any_history && reader.has_history(id)) {
        ++with;
        if (first_h < 0) first_h = id;
        last_h = id;
        example.emplace(p.kind(r), id);
      }
    }
  });

  os << "file        " << args.file << '\n';
  os << "study       " << m.study_name << (m.study_path.empty() ? "" : "  (source " + m.study_path + ")") << '\n';
  if (m.robot_text.empty()) {
    os << "sha256      " << m.study_sha256 << "  (of the study file's text, stored in /study/text)\n";
  } else {
    const bool urdf = m.robot_path.ends_with(".urdf");  // else a DH robot file (TOML)
    os << "robot       " << m.robot_path << (urdf ? "  (URDF" : "  (DH table") << ", stored in /study/robot)\n";
    os << "sha256      " << m.study_sha256 << "  (of the study file's text and the " << (urdf ? "URDF's" : "robot file's") << ")\n";
  }
  os << "engine      kinesweep " << m.engine_version << "; format " << m.format << " v" << m.format_version
     << "; created " << m.created << '\n';
  if (!m.histories.empty()) os << "histories   " << m.histories << "  (the policy the runs were written with)\n";
  if (m.format_version == 1)
    os << "note        format v" << m.format_version << " stores no column roles: taken from this kinesweep's "
       << "tables (kinesweep run --overwrite rewrites the file as v" << store::kFormatVersion << ")\n";
  os << "runs        " << n_done << " of " << n_runs << " done";
  if (n_done < n_runs) os << " (" << (n_runs - n_done) << " pending: a sweep is running, was interrupted, or resume is needed)";
  os << '\n';
  if (!consistent) os << "note        the file kept changing while it was read (a sweep is writing it)\n";

  std::size_t wn = 5;
  for (auto& b : blocks) wn = std::max(wn, b.name.size());
  os << '\n' << std::left;
  os << std::setw(static_cast<int>(wn)) << "block" << "  " << std::setw(10) << "kind" << std::right << std::setw(9)
     << "runs" << std::setw(9) << "done" << "  status\n";
  for (auto& b : blocks) {
    os << std::left << std::setw(static_cast<int>(wn)) << b.name << "  " << std::setw(10) << b.kind << std::right
       << std::setw(9) << b.rows << std::setw(9) << b.done << "  ";
    std::stable_sort(b.statuses.begin(), b.statuses.end(), [](auto& x, auto& y) { return x.second > y.second; });
    for (std::size_t i = 0; i < b.statuses.size(); ++i)
      os << (i ? ", " : "") << b.statuses[i].first << " " << b.statuses[i].second;
    os << '\n';
  }

  // Best rows per block: the candidates' rows read back by run id.
  os << "\nbest rows per block (the lowest objective among the runs of the good status, ties by the\n"
        "second metric, then run id:";
  const std::vector<std::string> kinds = declared_kinds(m);
  for (const std::string& k : kinds) {
    const KindMeaning km = kind_meaning(m, k);
    os << (k == kinds.front() ? " " : "; ") << k << ": " << km.objective() << " among " << km.good() << " runs"
       << (km.tie().empty() ? "" : ", then " + km.tie());
  }
  os << ")\n";
  for (const auto& b : blocks) {
    if (b.done == 0 || b.name == "(pending)") continue;
    const KindMeaning km = kind_meaning(m, b.kind);
    if (!km.known || km.objective().empty()) continue;  // no ranking declared for the kind
    const RunsColumn* key = metric_column(t, b.kind, km.objective());
    const RunsColumn* tie = km.tie().empty() ? nullptr : metric_column(t, b.kind, km.tie());
    if (!key || !status) continue;
    if (b.good_runs == 0) {
      os << "  " << b.name << ": no " << km.good() << " run\n";
      continue;
    }
    std::vector<std::int64_t> ids;
    for (const auto& c : b.best) ids.push_back(static_cast<std::int64_t>(c.run));
    std::vector<std::int64_t> sorted = ids;
    std::sort(sorted.begin(), sorted.end());
    load_ids(reader, t, sorted);
    for (const std::int64_t id : ids) {
      const auto r = static_cast<std::int64_t>(std::lower_bound(sorted.begin(), sorted.end(), id) - sorted.begin());
      os << "  " << std::left << std::setw(static_cast<int>(wn)) << b.name << std::right << "  run " << std::setw(6)
         << id << "  " << key->name << " = " << cell_for_humans(*key, r) << (key->unit.empty() ? "" : " " + key->unit);
      if (tie) os << ", " << tie->name << " = " << cell_for_humans(*tie, r) << " " << tie->unit;
      std::string label;  // the varying parameters that have an effect on this row (the tables' rules)
      for (std::size_t c = 0; c < t.cols.size(); ++c)
        if (b.varies[c] && t.cols[c].applies_to(b.kind) && has_effect_in_row(t, b.kind, t.cols[c], r))
          label += (label.empty() ? "" : ", ") + t.cols[c].name + " = " + cell_for_humans(t.cols[c], r);
      if (!label.empty()) os << "   (" << label << ")";
      os << '\n';
    }
  }

  // The best runs against their grid (/verification, written by kinesweep run).
  const store::VerificationTable verification = consistent_read(reader, [&] { return reader.read_verification(); });
  if (!verification.rows.empty()) os << '\n';
  print_verification(os, verification);

  // Histories: which runs hold one, and the arrays of each kind.
  os << '\n';
  print_columns(t, os);
  os << "histories   ";
  if (with == 0) {
    os << "none\n";
  } else {
    os << with << " of " << n_done << " done runs (run ids " << first_h << " .. " << last_h
       << "); kinesweep query FILE --run ID --history NAME\n";
    for (auto& [kind, run] : example) {
      const std::int64_t r = run;  // a plain variable: a lambda cannot capture a structured binding (C++17/20)
      const RunHistory h = consistent_read(reader, [&] { return reader.read_history(r); });
      os << "            " << kind << ": ";
      for (std::size_t i = 0; i < h.arrays.size(); ++i) {
        const auto& a = h.arrays[i];
        os << (i ? ", " : "") << a.name;
        if (a.cols > 1) os << "[" << a.cols << "]";
        if (!a.unit.empty()) os << " (" << a.unit << ")";
      }
      os << "   (run " << r << ": " << (h.arrays.empty() ? 0 : h.arrays.front().rows) << " rows)\n";
    }
  }
  // Landscapes.
  const auto names = consistent_read(reader, [&] { return reader.landscapes(); });
  os << "landscapes  " << (names.empty() ? "none" : "") << (names.empty() ? "\n" : "");
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto spec = consistent_read(reader, [&] { return reader.read_landscape(names[i], false); });
    os << (i ? "            " : "") << spec.block << ": ";
    for (std::size_t j = 0; j < spec.axes.size(); ++j) os << (j ? " x " : "") << axis_text(spec.axes[j]);
    os << "\n              metrics: ";
    for (std::size_t j = 0; j < spec.metrics.size(); ++j) os << (j ? ", " : "") << spec.metrics[j].name;
    os << '\n';
  }
  print_optimizations(reader, t, os);
  return 0;
}

}  // namespace

int info_command(const InfoArgs& args) {
  try {
    return run_info(args);
  } catch (const store::StoreError& e) {
    std::cerr << "kinesweep info: error: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "kinesweep info: error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace ks::cli
