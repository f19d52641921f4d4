#include "runner/landscape.hpp"

#include <limits>

namespace ks {

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();

/// An axis as a landscape axis: its values (a string axis: the codes 0..n-1, its names in the unit
/// "labels:a,b,...").
store::LandscapeAxis landscape_axis(const Axis& axis) {
  store::LandscapeAxis a;
  a.name = axis.name;
  a.unit = axis.unit;
  std::string labels;
  for (std::size_t i = 0; i < axis.values.size(); ++i) {
    if (const std::string* str = std::get_if<std::string>(&axis.values[i])) {
      a.values.push_back(static_cast<double>(i));
      labels += (i ? "," : "") + *str;
    } else {
      a.values.push_back(cell_number(axis.values[i]));
    }
  }
  if (!labels.empty()) a.unit = "labels:" + labels;
  return a;
}

}  // namespace

bool LandscapeGrid::is_sampled(const Dim& d) const {
  if (d.axes.size() != 1) return true;  // a zip, LHS or Saltelli group
  const Axis& axis = block_.axes()[d.axes.front()];
  if (axis.form == "random" || axis.form == "lhs" || axis.form == "saltelli") return true;
  const store::LandscapeAxis a = landscape_axis(axis);
  bool up = true, down = true;  // a coordinate is strictly monotonic (CF)
  for (std::size_t i = 1; i < a.values.size(); ++i) {
    up = up && a.values[i] > a.values[i - 1];
    down = down && a.values[i] < a.values[i - 1];
  }
  return !up && !down;
}

LandscapeGrid::LandscapeGrid(const Block& block, bool enabled) : block_(block) {
  // The good-status grid (ok / converged), the metrics marked gridded, the status code.
  const auto& ms = block.metrics();
  names_.emplace_back(statuses(block.kind()).front());
  sources_.push_back(Source::is_ok);
  metric_index_.push_back(ms.size());
  for (std::size_t j = 0; j < ms.size(); ++j)
    if (ms[j].gridded) {
      names_.push_back(ms[j].name);
      sources_.push_back(Source::column);
      metric_index_.push_back(j);
    }
  names_.emplace_back("status_code");
  sources_.push_back(Source::status_code);
  metric_index_.push_back(ms.size());
  enabled_ = enabled && block.run_count() <= kMaxLandscapeCells && !block.overflowed();
  cell_.assign(names_.size(), kNaN);
}

void LandscapeGrid::begin(store::ResultsWriter& writer, bool dense) {
  if (!enabled_) return;
  store::LandscapeSpec s = spec();
  s.dense = dense;
  handle_ = writer.begin_landscape(s);
}

void LandscapeGrid::add(std::uint64_t local, const Record& row, const StudySchema& schema, std::size_t b,
                        store::ResultsWriter& writer) {
  if (!enabled_) return;
  const std::string& status = std::get<std::string>(row.cells[schema.status]);
  const auto names = statuses(block_.kind());
  double code = kNaN;
  for (std::size_t s = 0; s < names.size(); ++s)
    if (names[s] == status) code = static_cast<double>(s);
  values_.clear();
  for (std::size_t column : columns(schema, b)) values_.push_back(cell_number(row.cells[column]));
  add_cell(local, code, values_.data(), schema, b, writer);
}

std::vector<std::size_t> LandscapeGrid::columns(const StudySchema& schema, std::size_t b) const {
  std::vector<std::size_t> out;
  for (std::size_t m = 0; m < names_.size(); ++m)
    if (sources_[m] == Source::column) out.push_back(schema.metric_column[b][metric_index_[m]]);
  return out;
}

void LandscapeGrid::add_cell(std::uint64_t local, double code, const double* values, const StudySchema& schema,
                             std::size_t b, store::ResultsWriter& writer) {
  if (!enabled_) return;
  std::size_t j = 0;  // index into values (the Source::column metrics, in order)
  for (std::size_t m = 0; m < names_.size(); ++m) {
    double v = kNaN;
    switch (sources_[m]) {
      case Source::is_ok: v = code == 0.0 ? 1.0 : 0.0; break;  // ok / converged are code 0
      case Source::status_code: v = code; break;
      case Source::column:
        v = values[j++];
        if (schema.columns[schema.metric_column[b][metric_index_[m]]].type == CellType::i64 && v == -1.0)
          v = kNaN;  // the missing integer (solution -1: none reached)
        break;
    }
    cell_[m] = v;
  }
  writer.write_landscape_cell(handle_, local, cell_.data());
}

void LandscapeGrid::add_range(std::uint64_t first, std::uint64_t count, const double* codes,
                              const std::vector<const double*>& columns, const StudySchema& schema, std::size_t b,
                              store::ResultsWriter& writer) {
  if (!enabled_ || count == 0) return;
  // The same values add_cell computes, a metric at a time.
  std::vector<std::vector<double>> own;  // metrics whose values are not a column as it is
  std::vector<const double*> values;
  std::size_t j = 0;
  for (std::size_t m = 0; m < names_.size(); ++m) {
    if (sources_[m] == Source::column) {
      const double* v = columns[j++];
      if (schema.columns[schema.metric_column[b][metric_index_[m]]].type == CellType::i64) {
        own.emplace_back(v, v + count);
        for (double& x : own.back())
          if (x == -1.0) x = kNaN;  // the missing integer (solution -1: none reached)
        v = own.back().data();
      }
      values.push_back(v);
    } else if (sources_[m] == Source::status_code) {
      values.push_back(codes);
    } else {  // is_ok: ok / converged are code 0
      own.emplace_back(count);
      for (std::uint64_t i = 0; i < count; ++i) own.back()[i] = codes[i] == 0.0 ? 1.0 : 0.0;
      values.push_back(own.back().data());
    }
  }
  writer.write_landscape_range(handle_, first, count, values);
}

store::LandscapeSpec LandscapeGrid::spec() const {
  store::LandscapeSpec s;
  s.block = block_.name();
  std::size_t sampled = 0;  // sampled dimensions so far
  for (const Dim& d : block_.dims()) {
    std::vector<store::LandscapeAxis> along;  // the dimension's axes, as coordinates
    for (std::size_t a : d.axes) along.push_back(landscape_axis(block_.axes()[a]));
    if (!is_sampled(d)) {
      s.axes.push_back(std::move(along.front()));
      continue;
    }
    store::LandscapeAxis a;
    a.name = ++sampled == 1 ? "sample" : "sample_" + std::to_string(sampled);
    for (std::size_t i = 0; i < d.size; ++i) a.values.push_back(static_cast<double>(i));
    a.coordinates = std::move(along);
    s.axes.push_back(std::move(a));
  }
  const auto& ms = block_.metrics();
  for (std::size_t m = 0; m < names_.size(); ++m) {
    store::LandscapeMetric lm;
    lm.name = names_[m];
    lm.display_name = lm.name;
    if (sources_[m] == Source::column) {
      const MetricDef& md = ms[metric_index_[m]];
      lm.unit = md.unit, lm.description = md.description;
      if (!md.label.empty()) lm.display_name = md.label;
    }
    if (sources_[m] == Source::is_ok) lm.description = "1 where the run's status is " + lm.name + ", else 0";
    if (sources_[m] == Source::status_code) {
      lm.description = "index of the run's status in:";
      for (const auto& st : statuses(block_.kind())) {
        lm.description += " " + std::string(st);
        lm.flags.emplace_back(st);
      }
    }
    s.metrics.push_back(std::move(lm));
  }
  return s;
}

}  // namespace ks
