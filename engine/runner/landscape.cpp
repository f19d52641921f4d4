#include "runner/landscape.hpp"

#include <limits>

namespace ks {

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// Gridded metrics per kind: metric columns by name, plus status-derived grids.
const std::vector<std::string>& grid_metrics(BlockKind k) {
  static const std::vector<std::string> traj{"E", "E_M", "tau_inf", "tau1_inf", "tau2_inf", "tau3_inf",
                                             "min_manipulability", "max_tracking_error", "ok", "status_code"};
  static const std::vector<std::string> ik{"converged", "iterations", "solution", "error", "status_code"};
  return k == BlockKind::trajectory ? traj : ik;
}
const std::vector<std::string>& status_names(BlockKind k) {
  static const std::vector<std::string> traj{"ok", "unreachable_start", "singular", "diverged"};
  static const std::vector<std::string> ik{"converged", "stalled", "singular", "max_iter",
                                           "cycle",     "diverged", "unsupported", "no_solution"};
  return k == BlockKind::trajectory ? traj : ik;
}
double number(const Cell& c) {
  if (const double* d = std::get_if<double>(&c)) return *d;
  if (const std::int64_t* i = std::get_if<std::int64_t>(&c)) return static_cast<double>(*i);
  return kNaN;
}
}  // namespace

LandscapeGrid::LandscapeGrid(const Block& block) : block_(block) {
  names_ = grid_metrics(block.kind());
  const auto& cols = metric_columns(block.kind());
  for (const std::string& n : names_) {
    sources_.push_back(n == "ok" || n == "converged" ? Source::is_ok
                       : n == "status_code"          ? Source::status_code
                                                     : Source::column);
    std::size_t j = 0;
    while (j < cols.size() && cols[j].name != n) ++j;
    metric_index_.push_back(j);
  }
  enabled_ = block.run_count() <= kMaxLandscapeCells && !block.overflowed();
  if (enabled_) grids_.assign(names_.size(), std::vector<double>(block.run_count(), kNaN));
}

void LandscapeGrid::add(std::uint64_t local, const Record& row, const StudySchema& schema, std::size_t b) {
  if (!enabled_) return;
  const std::string& status = std::get<std::string>(row.cells[schema.status]);
  const auto& statuses = status_names(block_.kind());
  double code = kNaN;
  for (std::size_t s = 0; s < statuses.size(); ++s)
    if (statuses[s] == status) code = static_cast<double>(s);
  for (std::size_t m = 0; m < names_.size(); ++m) {
    double v = kNaN;
    switch (sources_[m]) {
      case Source::is_ok: v = code == 0.0 ? 1.0 : 0.0; break;  // ok / converged are code 0
      case Source::status_code: v = code; break;
      case Source::column:
        v = number(row.cells[schema.metric_column[b][metric_index_[m]]]);
        if (names_[m] == "solution" && v < 0) v = kNaN;
        break;
    }
    grids_[m][local] = v;
  }
}

store::LandscapeSpec LandscapeGrid::spec() const {
  store::LandscapeSpec s;
  s.block = block_.name();
  for (const Dim& d : block_.dims()) {
    store::LandscapeAxis a;
    const Axis& first = block_.axes()[d.axes.front()];
    for (std::size_t i = 0; i < d.axes.size(); ++i) a.name += (i ? "+" : "") + block_.axes()[d.axes[i]].name;
    a.unit = first.unit;
    std::string labels;
    for (std::size_t i = 0; i < first.values.size(); ++i) {
      if (const std::string* str = std::get_if<std::string>(&first.values[i])) {
        a.values.push_back(static_cast<double>(i));
        labels += (i ? "," : "") + *str;
      } else {
        a.values.push_back(number(first.values[i]));
      }
    }
    if (!labels.empty()) a.unit = "labels:" + labels;
    s.axes.push_back(std::move(a));
  }
  const auto& cols = metric_columns(block_.kind());
  const auto& statuses = status_names(block_.kind());
  for (std::size_t m = 0; m < names_.size(); ++m) {
    store::LandscapeMetric lm;
    lm.name = names_[m];
    lm.grid = grids_[m];
    for (const ColumnSpec& c : cols)
      if (c.name == lm.name) lm.unit = c.unit, lm.description = c.description;
    if (lm.name == "ok" || lm.name == "converged") lm.description = "1 where the run's status is " + lm.name + ", else 0";
    if (lm.name == "status_code") {
      lm.description = "index of the run's status in:";
      for (const auto& st : statuses) lm.description += " " + st;
    }
    s.metrics.push_back(std::move(lm));
  }
  return s;
}

}  // namespace ks
