#include "runner/schema.hpp"

#include <algorithm>
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
/// Index of column c.name, adding it (or the kind of c, with its description, to it) as needed.
std::size_t add(std::vector<ColumnSpec>& cols, const ColumnSpec& c) {
  for (std::size_t i = 0; i < cols.size(); ++i)
    if (cols[i].name == c.name) {
      ColumnSpec& have = cols[i];
      if (have.labels.empty() || c.labels.empty()) have.labels.clear();  // free text for one kind: for all
      else  // a text column of several kinds holds the values of each
        for (const std::string& l : c.labels)
          if (std::find(have.labels.begin(), have.labels.end(), l) == have.labels.end()) have.labels.push_back(l);
      if (!c.kinds.empty() && !have.kinds.empty() && ("," + have.kinds + ",").find("," + c.kinds + ",") == std::string::npos) {
        if (have.description != c.description) {  // one description per kind: "trajectory: ...; ik: ..."
          if (have.kinds.find(',') == std::string::npos) have.description = have.kinds + ": " + have.description;
          have.description += "; " + c.kinds + ": " + c.description;
        }
        have.kinds += "," + c.kinds;
      }
      return i;
    }
  cols.push_back(c);
  return cols.size() - 1;
}
}  // namespace

StudySchema make_schema(const Study& study) {
  StudySchema s;
  auto& c = s.columns;
  s.run_id = add(c, run_id_column());
  s.block = add(c, block_column());
  for (const Block& b : study.blocks) c[s.block].labels.push_back(b.name());
  for (const Block& b : study.blocks) {
    std::vector<std::size_t> pc;
    for (const ColumnSpec& p : b.columns()) pc.push_back(add(c, p));
    s.param_column.push_back(std::move(pc));
  }
  for (const Block& b : study.blocks) {
    std::vector<std::size_t> mc;
    for (const MetricDef& m : b.metrics()) mc.push_back(add(c, m.column(b.kind())));
    s.metric_column.push_back(std::move(mc));
  }
  s.status = add(c, status_column());
  s.wall_time = add(c, wall_time_column());
  for (const ColumnSpec& col : c) s.blank.cells.push_back(missing(col.type));
  return s;
}

Record StudySchema::row(std::uint64_t id, std::size_t bi, const Block& b, const RunSpec& run, const RunOutcome& o,
                        double wall) const {
  Record r = blank;
  r.cells[run_id] = static_cast<std::int64_t>(id);
  r.cells[block] = b.name();
  const auto& table = b.table();
  for (std::size_t i = 0; i < table.size(); ++i) r.cells[param_column[bi][i]] = table[i].get(run);
  const auto& ms = b.metrics();
  for (std::size_t j = 0; j < ms.size(); ++j) r.cells[metric_column[bi][j]] = ms[j].get(o);
  r.cells[status] = std::string(o.status());
  r.cells[wall_time] = wall;
  return r;
}

}  // namespace ks
