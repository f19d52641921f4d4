// ResultsWriter::write_optimization: /optimizations/<name>/ (see store.hpp, FORMAT.md).
#include <algorithm>
#include <set>

#include "store/store.hpp"
#include "store/table_group.hpp"

namespace ks::store {
using namespace detail;


void ResultsWriter::write_optimization(const OptimizationRecord& r) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  m.touched = true;
  m.content = true;
  if (r.name.empty() || r.name == "." || r.name == ".." || r.name.find('/') != std::string::npos)
    throw StoreError(m.path, "invalid optimization name '" + r.name + "' (empty, '.', '..' or contains '/')");
  const std::size_t d = r.dims(), n = r.size();
  if (r.units.size() != d || r.lower.size() != d || r.upper.size() != d || r.x.size() != n * d ||
      r.constraint.size() != n || r.stage.size() != n || r.status.size() != n || r.start.size() != n ||
      r.best_x.size() != d || r.local_from.size() != r.local_value.size() * d ||
      r.local_to.size() != r.local_value.size() * d)
    throw StoreError(m.path, "optimization " + r.name + ": inconsistent sizes (variables " + std::to_string(d) +
                                 ", evaluations " + std::to_string(n) + ")");
  for (const auto& s : r.stages)
    if (s.best_x.size() != d) throw StoreError(m.path, "optimization " + r.name + ": stage " + s.name + " best_x size");
  if (!link_exists(m.file, "optimizations")) {
    Hid g(H5Gcreate2(m.file, "optimizations", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    if (!g.ok()) m.fail("cannot create /optimizations");
  }
  Hid root(H5Gopen2(m.file, "optimizations", H5P_DEFAULT));
  if (!root.ok()) m.fail("cannot open /optimizations");
  if (link_exists(root, r.name)) {
    if (H5Ldelete(root, r.name.c_str(), H5P_DEFAULT) < 0) m.fail("cannot replace /optimizations/" + r.name);
    m.freed_space = true;
  }
  TableOut o{m, "/optimizations/" + r.name};
  Hid g = o.group(root, r.name);
  write_str_attr(g, "kind", r.kind);
  write_str_attr(g, "preset", r.preset);
  write_str_attr(g, "objective", r.objective);
  write_str_attr(g, "settings", r.settings);
  write_str_list_attr(g, "variables", r.variables);
  write_str_list_attr(g, "units", r.units);
  o.f64_attr(g, "lower", r.lower);
  o.f64_attr(g, "upper", r.upper);
  o.f64_attr(g, "best_objective", r.best_objective);
  o.f64_attr(g, "best_x", r.best_x);
  write_str_attr(g, "best_status", r.best_status);
  write_str_attr(g, "best_stage", r.best_stage);
  o.f64_attr(g, "wall_time", r.wall_time_s);
  write_i64_attr(g, "seed", r.seed);
  write_i64_attr(g, "n_evaluations", static_cast<std::int64_t>(n));
  {
    std::vector<std::string> rn;
    for (const auto& [k, v] : r.reference) {
      rn.push_back(k);
      o.f64_attr(g, ("reference_" + k).c_str(), v);
    }
    write_str_list_attr(g, "references", rn);
  }
  // Every evaluation.
  {
    Hid e = o.group(g, "evaluations");
    o.where = "/optimizations/" + r.name + "/evaluations";
    o.f64(e, "x", r.x, d, "", "the point, one column per variable (units: the group's attribute units)");
    o.f64(e, "objective", r.value, 0, "", "objective value (deterministic penalty when the run failed)");
    o.f64(e, "constraint", r.constraint, 0, "", "reach margin |cos theta2| - 1 (<= 0: reachable); NaN when none");
    o.str(e, "stage", r.stage, "sweep | global | local");
    o.str(e, "status", r.status, "the run's status (an evaluation set: the first failure and the count)");
    o.i64(e, "start", r.start, "local: index of the start (row of local/from); sweep: the cell's run id; global: -1");
    o.dimensions(e, "evaluation", "variable");
  }
  // Stages.
  {
    o.where = "/optimizations/" + r.name + "/stages";
    Hid s = o.group(g, "stages");
    std::vector<std::string> name, alg, res, st;
    std::vector<double> wall, best, bx;
    std::vector<std::int64_t> ev;
    for (const auto& x : r.stages) {
      name.push_back(x.name); alg.push_back(x.algorithm); res.push_back(x.result); st.push_back(x.best_status);
      wall.push_back(x.wall_time_s); best.push_back(x.best_objective); ev.push_back(x.evaluations);
      bx.insert(bx.end(), x.best_x.begin(), x.best_x.end());
    }
    o.str(s, "name", name, "stage name");
    o.str(s, "algorithm", alg, "NLopt algorithm");
    o.str(s, "result", res, "NLopt result code");
    o.str(s, "best_status", st, "status of the stage's best point");
    o.f64(s, "wall_time", wall, 0, "s", "wall time of the stage");
    o.f64(s, "best_objective", best, 0, "", "best objective of the stage");
    o.f64(s, "best_x", bx, d, "", "best point of the stage, one column per variable");
    o.i64(s, "evaluations", ev, "objective evaluations of the stage");
    o.dimensions(s, "stage", "variable");
  }
  // Local starts.
  {
    o.where = "/optimizations/" + r.name + "/local";
    Hid l = o.group(g, "local");
    o.f64(l, "from", r.local_from, d, "", "start of each local polish");
    o.f64(l, "to", r.local_to, d, "", "best point each local polish reached");
    o.f64(l, "objective", r.local_value, 0, "", "best objective each local polish reached");
    o.dimensions(l, "start", "variable");
  }
  // The best point's run: metrics and history.
  {
    o.where = "/optimizations/" + r.name + "/best";
    Hid b = o.group(g, "best");
    std::vector<std::string> names;
    for (const auto& [k, v] : r.best_metrics) {
      names.push_back(k);
      o.f64_attr(b, k.c_str(), v);
    }
    write_str_list_attr(b, "metrics", names);
    Hid h = o.group(b, "history");
    std::vector<std::string> arrays;
    for (const auto& a : r.history.arrays) {
      if (a.data.size() != a.rows * a.cols) throw StoreError(m.path, "history array " + a.name + ": rows*cols mismatch");
      arrays.push_back(a.name);
      o.f64(h, a.name, a.data, a.cols, a.unit, "the best point's run");
    }
    write_str_list_attr(h, "arrays", arrays);
    o.dimensions(h, "row");
  }
  m.do_flush();
}

}  // namespace ks::store
