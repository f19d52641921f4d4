#include "runner/schema.hpp"

#include <limits>

namespace ks {

namespace {
Cell missing(CellType t) {
  switch (t) {
    case CellType::f64: return std::numeric_limits<double>::quiet_NaN();
    case CellType::i64: return std::int64_t{-1};
    default: return std::string();
  }
}
std::size_t add(std::vector<ColumnSpec>& cols, const ColumnSpec& c) {
  for (std::size_t i = 0; i < cols.size(); ++i)
    if (cols[i].name == c.name) return i;
  cols.push_back(c);
  return cols.size() - 1;
}
}  // namespace

StudySchema make_schema(const Study& study) {
  StudySchema s;
  auto& c = s.columns;
  s.run_id = add(c, {"run_id", CellType::i64, "", "global run id (row index)"});
  s.block = add(c, {"block", CellType::str, "", "name of the study block the run belongs to"});
  for (const Block& b : study.blocks) {
    std::vector<std::size_t> pc;
    for (const ColumnSpec& p : b.columns()) pc.push_back(add(c, p));
    s.param_column.push_back(std::move(pc));
  }
  for (const Block& b : study.blocks) {
    std::vector<std::size_t> mc;
    for (const ColumnSpec& m : metric_columns(b.kind())) mc.push_back(add(c, m));
    s.metric_column.push_back(std::move(mc));
  }
  for (std::size_t b = 0; b < study.blocks.size(); ++b) {  // role and kinds (run_id, block, status, wall_time: defaults)
    const std::string kind(to_string(study.blocks[b].kind()));
    auto mark = [&](std::size_t i, Role role) {
      c[i].role = role;
      if (("," + c[i].kinds + ",").find("," + kind + ",") == std::string::npos)
        c[i].kinds += (c[i].kinds.empty() ? "" : ",") + kind;
    };
    for (std::size_t i : s.param_column[b]) mark(i, Role::parameter);
    for (std::size_t i : s.metric_column[b]) mark(i, Role::metric);
  }
  s.status = add(c, {"status", CellType::str, "",
                     "trajectory: ok, unreachable_start, singular, diverged; ik: converged, stalled, singular, "
                     "max_iter, cycle, diverged, unsupported, no_solution"});
  s.wall_time = add(c, {"wall_time", CellType::f64, "s", "wall-clock time of the run (the only column that "
                                                            "varies between identical sweeps)"});
  for (const ColumnSpec& col : c) s.blank.cells.push_back(missing(col.type));
  return s;
}

Record StudySchema::row(std::uint64_t id, std::size_t b, const std::string& block_name, std::span<const Cell> params,
                        const RunOutcome& o, double wall) const {
  Record r = blank;
  r.cells[run_id] = static_cast<std::int64_t>(id);
  r.cells[block] = block_name;
  for (std::size_t i = 0; i < params.size(); ++i) r.cells[param_column[b][i]] = params[i];
  for (std::size_t j = 0; j < o.metrics.size(); ++j) r.cells[metric_column[b][j]] = o.metrics[j];
  r.cells[status] = o.status;
  r.cells[wall_time] = wall;
  return r;
}

}  // namespace ks
