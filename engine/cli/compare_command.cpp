#include "cli/compare_command.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <tuple>

#include "cli/query_util.hpp"
#include "cli/query_where.hpp"
#include "schema/params.hpp"
#include "store/store.hpp"
#include "verify/gci.hpp"
#include "cli/kind_meaning.hpp"

namespace ks::cli {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The text of row `r` of column `c` (numbers as format_double, missing as "").
std::string text(const RunsColumn* c, std::int64_t r) {
  if (!c) return "";
  const auto i = static_cast<std::size_t>(r);
  if (c->missing(r)) return "";
  switch (c->type) {
    case CellType::str: return c->s[i];
    case CellType::i64: return std::to_string(c->i[i]);
    case CellType::f64: return format_double(c->f[i]);
  }
  return "";
}

double number(const RunsColumn* c, std::int64_t r) {
  if (!c) return kNaN;
  const auto i = static_cast<std::size_t>(r);
  if (c->type == CellType::f64) return c->f[i];
  if (c->type == CellType::i64) return c->missing(r) ? kNaN : static_cast<double>(c->i[i]);
  return kNaN;
}

struct Best {
  double value = kNaN;
  std::int64_t run = -1;
};

/// What /verification says of a run's metric: the GCI of the run as stored (the largest over its
/// refinements, relative) and its grid behaviour.
struct Grid {
  std::string state = "none";  ///< converged | diverges | oscillates | not_enough | none
  double gci = kNaN;           ///< relative (converged only)
};

Grid grid_of(const store::VerificationTable& t, std::int64_t run, const std::string& metric) {
  Grid g;
  bool any = false;
  double gci = 0.0;
  std::string worst;  // the first non-converged behaviour found, in row order
  for (const store::VerificationRow& r : t.rows) {
    if (r.run != run || r.quantity != metric) continue;
    any = true;
    Convergence c = Convergence::not_enough;
    parse(r.convergence, c);
    if (c == Convergence::monotone || c == Convergence::unchanged) gci = std::max(gci, r.gci_coarse);
    else if (worst.empty())
      worst = c == Convergence::divergent ? "diverges" : c == Convergence::oscillatory ? "oscillates" : "not_enough";
  }
  if (!any) return g;
  if (!worst.empty()) g.state = worst;
  else g.state = "converged", g.gci = gci;
  return g;
}

int run_compare(const CompareArgs& args) {
  store::ResultsReader reader(args.file, v1_column_roles);
  RunsTable t = runs_header(reader);
  const RunsColumn* by = t.find(args.by);
  if (!by) {
    const std::vector<std::string> names = t.names();
    const std::string dym = did_you_mean(args.by, names);
    std::cerr << "kinesweep compare: error: --by " << args.by << ": no such /runs column in " << args.file
              << "; expected one of " << join(names, ", ") << (dym.empty() ? "" : " (did you mean '" + dym + "'?)") << '\n';
    return 2;
  }
  // the metrics per kind: --metric, or the kind's ranking objective; each must be a numeric metric
  std::map<std::string, std::vector<std::string>> metrics;
  for (const std::string& kind : t.kinds) {
    std::vector<std::string> numeric;
    for (const RunsColumn& c : t.cols)
      if (c.role == Role::metric && c.type != CellType::str && c.applies_to(kind)) numeric.push_back(c.name);
    std::vector<std::string> wanted = args.metrics;
    if (wanted.empty()) {
      const std::string objective = kind_meaning(t.meta, kind).objective();
      if (!objective.empty()) wanted.push_back(objective);
    }
    for (const std::string& m : wanted) {
      if (std::find(numeric.begin(), numeric.end(), m) != numeric.end()) metrics[kind].push_back(m);
      else if (t.kinds.size() == 1 || args.metrics.empty()) {
        const std::string dym = did_you_mean(m, numeric);
        std::cerr << "kinesweep compare: error: --metric " << m << ": not a numeric metric of " << kind
                  << " runs; expected one of " << join(numeric, ", ") << (dym.empty() ? "" : " (did you mean '" + dym + "'?)")
                  << '\n';
        return 2;
      }
    }
  }
  std::vector<Disjunction> filters;
  try {
    for (const std::string& expr : args.where) filters.push_back(parse_where(expr, t));
  } catch (const ArgError& e) {
    std::cerr << "kinesweep compare: error: --where: " << e.what() << '\n';
    return 2;
  }
  const store::VerificationTable verification = reader.read_verification();
  // best[(kind, end, metric)][group]: the lowest value among the good runs (then the lower run id)
  std::map<std::tuple<std::string, std::string, std::string>, std::map<std::string, Best>> best;
  std::map<std::string, std::string> units;
  t.load_all(true);
  for_each_piece(reader, t, [&](const RunsTable& p) {
    const RunsColumn* status = p.find("status");
    const RunsColumn* method = p.find("method");
    const RunsColumn* spline = p.find("spline");
    const RunsColumn* end_state = p.find("end_state");
    const RunsColumn* local_end = p.find("end");
    const RunsColumn* group = p.find(args.by);
    const Selector select{p, false};
    for (std::int64_t r = 0; r < static_cast<std::int64_t>(p.done.size()); ++r) {
      if (!p.done[static_cast<std::size_t>(r)]) continue;
      if (!std::all_of(filters.begin(), filters.end(), [&](const Disjunction& d) { return select.test(d, r); })) continue;
      const std::string kind = p.kind(r);
      const auto m = metrics.find(kind);
      if (m == metrics.end()) continue;
      if (!kind_meaning(p.meta, kind).is_good(text(status, r))) continue;
      std::string end;
      if (kind == to_string(BlockKind::trajectory))
        end = end_condition(text(method, r), text(spline, r), text(end_state, r), text(local_end, r));
      if (!args.end.empty() && args.end != "any" && end != args.end) continue;
      if (args.end == "any") end = "any";
      const std::int64_t id = p.row_id(r);
      for (const std::string& metric : m->second) {
        const RunsColumn* c = p.find(metric);
        const double v = number(c, r);
        if (!std::isfinite(v)) continue;
        units[metric] = c->unit;
        Best& b = best[{kind, end, metric}][text(group, r)];
        if (b.run < 0 || v < b.value || (v == b.value && id < b.run)) b = {v, id};
      }
    }
  });
  OutTable out;
  out.names = {"kind", "end", "metric", "unit", "rank", args.by, "run", "value", "grid", "gci", "uncertainty",
               "next", "margin", "margin_uncertainty", "verdict"};
  out.units = {"", "", "", "", "", by->unit, "", "", "", "%", "", "", "", "", ""};
  for (const auto& [key, groups] : best) {
    const auto& [kind, end, metric] = key;
    std::vector<std::pair<std::string, Best>> ranked(groups.begin(), groups.end());
    std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) {
      return a.second.value < b.second.value || (a.second.value == b.second.value && a.second.run < b.second.run);
    });
    std::vector<Grid> grids;
    for (const auto& [g, b] : ranked) grids.push_back(grid_of(verification, b.run, metric));
    for (std::size_t i = 0; i < ranked.size(); ++i) {
      const Best& b = ranked[i].second;
      const double u = grids[i].gci * std::abs(b.value);
      std::vector<OutCell> row{kind, end, metric, units[metric], static_cast<std::int64_t>(i + 1), ranked[i].first, b.run,
                               b.value, grids[i].state, 100.0 * grids[i].gci, u};
      if (i + 1 < ranked.size()) {
        const Best& n = ranked[i + 1].second;
        const double margin = n.value - b.value;
        const double mu = u + grids[i + 1].gci * std::abs(n.value);
        const std::string verdict = !std::isfinite(mu) ? "unverified" : margin > mu ? "ahead" : "within uncertainty";
        row.insert(row.end(), {ranked[i + 1].first, margin, mu, verdict});
      } else {
        row.insert(row.end(), {std::monostate{}, std::monostate{}, std::monostate{}, std::string("last")});
      }
      out.rows.push_back(std::move(row));
    }
  }
  const Format f = *parse_format(args.format);
  if (f == Format::table) {
    std::cout << "best good run per " << args.by << ", per end condition and metric; its grid convergence index (GCI) "
              << "from /verification; the margin to the next " << args.by << " +/- both uncertainties (GCI x value); "
              << "value, uncertainty and margin in the row's unit\n";
  }
  print_out(out, f, std::cout);
  return 0;
}

}  // namespace

std::string end_condition(const std::string& method, const std::string& spline, const std::string& end_state,
                          const std::string& local_end) {
  static const EffectRule rule = [] {
    KindContext global;
    global.path_global = true;  // global_spline's parameters are in the table
    for (const ParamDef& p : params(BlockKind::trajectory, global))
      if (p.name == "end_state") return p.effect;
    return EffectRule{"method", {}};
  }();
  if (method == "vertex_alpha") return "rest";
  if (!end_state.empty() && rule.applies(method)) return spline == "vertex_quintic" ? "rest" : end_state;
  return local_end == "rest" ? "rest" : "free";
}

int compare_command(const CompareArgs& args) {
  try {
    return run_compare(args);
  } catch (const std::exception& e) {
    std::cerr << "kinesweep compare: error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace ks::cli
