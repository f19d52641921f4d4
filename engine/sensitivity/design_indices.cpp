// The Sobol' indices of a results file's Saltelli designs (sensitivity/design_indices.hpp).
#include "sensitivity/design_indices.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "common/format_double.hpp"

namespace ks {

namespace {
/// A cell as the tables print it: numbers with 6 significant digits.
std::string cell_text(const Cell& c) {
  if (const double* d = std::get_if<double>(&c)) return format_double(*d);
  if (const std::int64_t* i = std::get_if<std::int64_t>(&c)) return std::to_string(*i);
  if (const std::string* s = std::get_if<std::string>(&c)) return *s;
  return "";
}

std::uint64_t failed_runs(const DesignIndices& r) {
  std::uint64_t n = 0;
  for (const auto& [status, k] : r.failed) n += k;
  return n;
}

/// `count` values of the numeric /runs column `c` from row `first`, as doubles.
std::vector<double> read_numbers(const store::ResultsReader& file, const ColumnSpec& c, std::int64_t first,
                                 std::int64_t count) {
  if (c.type == CellType::f64) return file.read_f64(c.name, first, count);
  const std::vector<std::int64_t> v = file.read_i64(c.name, first, count);
  return std::vector<double>(v.begin(), v.end());
}
}  // namespace

std::vector<std::string> design_metrics(const store::ResultsReader& file, const std::string& kind) {
  std::vector<std::string> out;
  for (const ColumnSpec& c : file.columns())
    if (c.role == Role::metric && c.type != CellType::str && ("," + c.kinds + ",").find("," + kind + ",") != std::string::npos)
      out.push_back(c.name);
  return out;
}

std::vector<DesignIndices> design_indices(const store::ResultsReader& file, const store::DesignMeta& d,
                                          const std::vector<std::string>& metrics, const std::string& good,
                                          const SobolOptions& options) {
  const auto& cols = file.columns();
  std::int64_t runs = 1;
  for (std::int64_t s : d.sizes) runs *= s;
  const auto done = file.done_mask(d.first_run, runs);
  const auto status = file.read_str("status", d.first_run, runs);
  // strides of the mixed-radix local index (last dimension fastest)
  const std::size_t nd = d.sizes.size(), dim = static_cast<std::size_t>(d.dim);
  std::vector<std::int64_t> stride(nd, 1);
  for (std::size_t k = nd - 1; k-- > 0;) stride[k] = stride[k + 1] * d.sizes[k + 1];
  const std::int64_t combos = runs / d.sizes[dim];
  const std::int64_t n = d.base_samples, f = static_cast<std::int64_t>(d.factors.size());
  // the combinations: point 0's local index and the other dimensions' values (read once)
  std::vector<std::int64_t> bases(static_cast<std::size_t>(combos));
  std::vector<std::string> ats(bases.size());
  for (std::int64_t c = 0; c < combos; ++c) {
    std::int64_t base = 0, rest = c;
    for (std::size_t k = nd; k-- > 0;) {
      if (k == dim) continue;
      base += (rest % d.sizes[k]) * stride[k];
      rest /= d.sizes[k];
    }
    bases[static_cast<std::size_t>(c)] = base;
    if (nd == 1) continue;
    const Record row = file.read_record(d.first_run + base);
    std::string& at = ats[static_cast<std::size_t>(c)];
    for (std::size_t k = 0; k < nd; ++k) {
      if (k == dim) continue;
      std::istringstream names(d.dims[k]);
      for (std::string a; std::getline(names, a, '+');) {
        const auto col = std::find_if(cols.begin(), cols.end(), [&](const ColumnSpec& s) { return s.name == a; });
        if (col != cols.end()) at += (at.empty() ? "" : ", ") + a + "=" + cell_text(row.cells[col - cols.begin()]);
      }
    }
  }
  // the metrics' values (read in turn: the file is read by one thread)
  std::vector<std::vector<double>> ys;
  std::vector<const ColumnSpec*> specs;
  for (const std::string& metric : metrics) {
    const auto it = std::find_if(cols.begin(), cols.end(), [&](const ColumnSpec& c) { return c.name == metric; });
    if (it == cols.end() || it->type == CellType::str)
      throw std::invalid_argument("design_indices: '" + metric + "' is not a numeric /runs column");
    ys.push_back(read_numbers(file, *it, d.first_run, runs));
    specs.push_back(&*it);
  }
  // the estimates, one task per metric and combination (each its own resampling, from the same seed)
  std::vector<DesignIndices> out(metrics.size() * bases.size());
  tbb::parallel_for(std::size_t(0), out.size(), [&](std::size_t t) {
    const std::size_t m_index = t / bases.size(), c = t % bases.size();
    const std::vector<double>& y = ys[m_index];
    const std::int64_t base = bases[c];
    DesignIndices& r = out[t];
    r.block = d.block, r.kind = d.kind, r.factors = d.factors, r.good = good, r.metric = metrics[m_index];
    r.unit = specs[m_index]->unit, r.combination = static_cast<std::int64_t>(c), r.at = ats[c];
    auto value = [&](std::int64_t point) {
      const std::int64_t local = base + point * stride[dim];
      if (!done[local]) return ++r.not_done, std::numeric_limits<double>::quiet_NaN();
      if (status[local] != good) return ++r.failed[status[local]], std::numeric_limits<double>::quiet_NaN();
      return y[local];
    };
    std::vector<double> a(n), b(n);
    std::vector<std::vector<double>> ab(f, std::vector<double>(n));
    for (std::int64_t j = 0; j < n; ++j) {
      const std::uint64_t not_done = r.not_done, failed = failed_runs(r);
      a[j] = value(j);
      b[j] = value(n + j);
      for (std::int64_t m = 0; m < f; ++m) ab[m][j] = value((2 + m) * n + j);
      if (r.not_done != not_done) ++r.not_done_samples;
      else if (failed_runs(r) != failed) ++r.failed_samples;
    }
    std::vector<std::span<const double>> spans(ab.begin(), ab.end());
    r.s = sobol_indices(a, b, spans, options);
  });
  return out;
}

store::SensitivityTable sensitivity_table(const std::vector<DesignIndices>& results, const SobolOptions& options) {
  store::SensitivityTable t;
  t.bootstrap = options.bootstrap, t.confidence = options.confidence, t.seed = options.seed;
  for (const DesignIndices& r : results)
    for (std::size_t i = 0; i < r.s.first.size(); ++i) {
      store::SensitivityRow row;
      row.block = r.block, row.metric = r.metric, row.factor = r.factors[i], row.combination = r.combination, row.factor_index = static_cast<std::int64_t>(i);
      row.first = r.s.first[i], row.first_lo = r.s.first_lo[i], row.first_hi = r.s.first_hi[i];
      row.total = r.s.total[i], row.total_lo = r.s.total_lo[i], row.total_hi = r.s.total_hi[i];
      row.variance = r.s.variance;
      row.samples = static_cast<std::int64_t>(r.s.samples), row.dropped = static_cast<std::int64_t>(r.s.dropped);
      t.rows.push_back(std::move(row));
    }
  return t;
}

}  // namespace ks
