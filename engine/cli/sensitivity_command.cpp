#include "cli/sensitivity_command.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <sstream>

#include "cli/kind_meaning.hpp"
#include "cli/query_util.hpp"
#include "schema/params.hpp"
#include "sensitivity/sobol_indices.hpp"
#include "store/store.hpp"

namespace ks::cli {

namespace {

/// One table: a block's design, one metric, one combination of the block's other axes.
struct Result {
  const store::DesignMeta* design = nullptr;
  std::string metric, unit, at;  ///< at: "method=local_weighted" (the other axes' values), "" when none
  std::map<std::string, std::uint64_t> failed;  ///< status -> runs of the design (not the good status)
  std::uint64_t not_done = 0;
  std::string good;                   ///< the kind's good status: the indices are conditional on it
  std::uint64_t failed_samples = 0;   ///< sample rows left out because a run of theirs failed (all done)
  std::uint64_t not_done_samples = 0; ///< sample rows left out because a run of theirs is not done
  SobolIndices s;
};

std::string cell_text(const Cell& c) {
  if (const double* d = std::get_if<double>(&c)) return format_double(*d);
  if (const std::int64_t* i = std::get_if<std::int64_t>(&c)) return std::to_string(*i);
  return std::get<std::string>(c);
}

/// The meaning of a design's run kind, as the file declares it (cli/kind_meaning.hpp).
KindMeaning meaning_of(const store::ResultsReader& reader, const std::string& name) {
  KindMeaning km = kind_meaning(reader.meta(), name);
  if (!km.known || km.good().empty() || km.objective().empty())
    throw std::runtime_error("unknown run kind '" + name + "' in /designs");
  return km;
}

/// Runs of the design with a status other than the good one.
std::uint64_t failed_runs(const Result& r) {
  std::uint64_t n = 0;
  for (const auto& [status, k] : r.failed) n += k;
  return n;
}

/// `count` values of the numeric /runs column `c` from row `first`, as doubles (an i64 column converted).
std::vector<double> read_numbers(store::ResultsReader& reader, const ColumnSpec& c, std::int64_t first,
                                 std::int64_t count) {
  if (c.type == CellType::f64) return reader.read_f64(c.name, first, count);
  const std::vector<std::int64_t> v = reader.read_i64(c.name, first, count);
  return std::vector<double>(v.begin(), v.end());
}

/// The indices of every metric for every combination of the design block's other dimensions.
void analyse(store::ResultsReader& reader, const store::DesignMeta& d, const std::vector<std::string>& metrics,
             const SobolOptions& opt, std::vector<Result>& out) {
  const auto& cols = reader.columns();
  std::int64_t runs = 1;
  for (std::int64_t s : d.sizes) runs *= s;
  const auto done = reader.done_mask(d.first_run, runs);
  const auto status = reader.read_str("status", d.first_run, runs);
  const std::string good = meaning_of(reader, d.kind).good();
  // strides of the mixed-radix local index (last dimension fastest)
  const std::size_t nd = d.sizes.size(), dim = static_cast<std::size_t>(d.dim);
  std::vector<std::int64_t> stride(nd, 1);
  for (std::size_t k = nd - 1; k-- > 0;) stride[k] = stride[k + 1] * d.sizes[k + 1];
  std::int64_t combos = runs / d.sizes[dim];
  const std::int64_t n = d.base_samples, f = static_cast<std::int64_t>(d.factors.size());
  for (const std::string& metric : metrics) {
    const auto it = std::find_if(cols.begin(), cols.end(), [&](const ColumnSpec& c) { return c.name == metric; });
    const std::vector<double> y = read_numbers(reader, *it, d.first_run, runs);
    for (std::int64_t c = 0; c < combos; ++c) {
      // the local index of point 0 of the design at combination c of the other dimensions
      std::int64_t base = 0, rest = c;
      for (std::size_t k = nd; k-- > 0;) {
        if (k == dim) continue;
        base += (rest % d.sizes[k]) * stride[k];
        rest /= d.sizes[k];
      }
      Result r;
      r.design = &d;
      r.good = good;
      r.metric = metric;
      r.unit = it->unit;
      const Record row = nd > 1 ? reader.read_record(d.first_run + base) : Record{};  // the other axes' values
      for (std::size_t k = 0; k < nd; ++k) {
        if (k == dim) continue;
        std::istringstream names(d.dims[k]);
        for (std::string a; std::getline(names, a, '+');) {
          const auto col = std::find_if(cols.begin(), cols.end(), [&](const ColumnSpec& s) { return s.name == a; });
          if (col != cols.end()) r.at += (r.at.empty() ? "" : ", ") + a + "=" + cell_text(row.cells[col - cols.begin()]);
        }
      }
      auto value = [&](std::int64_t point) {
        const std::int64_t local = base + point * stride[dim];
        if (!done[local]) return ++r.not_done, std::nan("");
        if (status[local] != good) return ++r.failed[status[local]], std::nan("");
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
      r.s = sobol_indices(a, b, spans, opt);
      out.push_back(std::move(r));
    }
  }
}

void print_table(const std::vector<Result>& results, double confidence, std::ostream& os) {
  char line[256];
  for (const Result& r : results) {
    const store::DesignMeta& d = *r.design;
    os << "block " << d.block << " (" << d.kind << "), Saltelli design: " << d.base_samples << " samples x ("
       << d.factors.size() << " factors + 2) = " << d.base_samples * static_cast<std::int64_t>(d.factors.size() + 2)
       << " runs" << (r.at.empty() ? "" : " at " + r.at) << "\n";
    os << "  metric " << r.metric << (r.unit.empty() ? "" : " [" + r.unit + "]") << ": variance "
       << format_double(r.s.variance) << "; samples used " << r.s.samples << " of " << d.base_samples;
    if (r.s.dropped) {
      os << " (" << r.s.dropped << " left out: a run of the sample failed or is not done;";
      for (const auto& [st, k] : r.failed) os << " " << st << " " << k;
      if (r.not_done) os << " not done " << r.not_done;
      os << " runs)";
    }
    os << "\n";
    if (r.failed_samples)
      os << "  failed samples " << r.failed_samples << " of " << d.base_samples
         << ": the indices are conditional on success (computed over the samples whose runs all ended " << r.good
         << ")\n";
    if (r.not_done_samples) os << "  samples not done " << r.not_done_samples << " of " << d.base_samples << "\n";
    const int pct = static_cast<int>(std::lround(confidence * 100));
    std::snprintf(line, sizeof line, "  %-22s %9s  %-21s %9s  %-21s\n", "factor", "S1", (std::to_string(pct) + "% interval").c_str(),
                  "ST", (std::to_string(pct) + "% interval").c_str());
    os << line;
    for (std::size_t i = 0; i < d.factors.size(); ++i) {
      const std::string i1 = "[" + format_double(r.s.first_lo[i]) + ", " + format_double(r.s.first_hi[i]) + "]";
      const std::string i2 = "[" + format_double(r.s.total_lo[i]) + ", " + format_double(r.s.total_hi[i]) + "]";
      std::snprintf(line, sizeof line, "  %-22s %9.4f  %-21s %9.4f  %-21s\n", d.factors[i].c_str(), r.s.first[i],
                    i1.c_str(), r.s.total[i], i2.c_str());
      os << line;
    }
  }
}

void print_json(const std::string& file, const std::vector<Result>& results, const SobolOptions& opt, std::ostream& os) {
  auto num = [](double v) { return std::isfinite(v) ? format_double(v) : std::string("null"); };
  os << "{\"file\": " << json_string(file) << ", \"confidence\": " << num(opt.confidence)
     << ", \"bootstrap\": " << opt.bootstrap << ", \"results\": [";
  for (std::size_t k = 0; k < results.size(); ++k) {
    const Result& r = results[k];
    const store::DesignMeta& d = *r.design;
    os << (k ? "," : "") << "\n {\"block\": " << json_string(d.block) << ", \"kind\": " << json_string(d.kind)
       << ", \"metric\": " << json_string(r.metric) << ", \"unit\": " << json_string(r.unit)
       << ", \"at\": " << json_string(r.at) << ", \"base_samples\": " << d.base_samples
       << ", \"samples\": " << r.s.samples << ", \"dropped\": " << r.s.dropped << ", \"failed_samples\": "
       << r.failed_samples << ", \"not_done_samples\": " << r.not_done_samples
       << ", \"conditional_on_success\": " << (r.failed_samples ? "true" : "false")
       << ", \"good_status\": " << json_string(r.good) << ", \"not_done\": " << r.not_done
       << ", \"failed_runs\": {";
    bool first = true;
    for (const auto& [st, c] : r.failed) os << (first ? "" : ", ") << json_string(st) << ": " << c, first = false;
    os << "}, \"variance\": " << num(r.s.variance) << ", \"factors\": [";
    for (std::size_t i = 0; i < d.factors.size(); ++i)
      os << (i ? ", " : "") << "{\"name\": " << json_string(d.factors[i]) << ", \"first\": " << num(r.s.first[i])
         << ", \"first_lo\": " << num(r.s.first_lo[i]) << ", \"first_hi\": " << num(r.s.first_hi[i])
         << ", \"total\": " << num(r.s.total[i]) << ", \"total_lo\": " << num(r.s.total_lo[i])
         << ", \"total_hi\": " << num(r.s.total_hi[i]) << "}";
    os << "]}";
  }
  os << "\n]}\n";
}

int run_sensitivity(const SensitivityArgs& args) {
  SobolOptions opt;
  opt.bootstrap = args.bootstrap;
  opt.confidence = args.confidence;
  opt.seed = args.seed;
  if (std::string why; !opt.IsValid(&why)) {
    std::cerr << "kinesweep sensitivity: error: " << why << '\n';
    return 2;
  }
  store::ResultsReader reader(args.file, v1_column_roles);
  const std::vector<store::DesignMeta> designs = reader.designs();
  if (designs.empty()) {
    std::cerr << "kinesweep sensitivity: error: " << args.file
              << " holds no Saltelli design; expected a study block with saltelli = { count = N, seed = S } and "
                 "axes written { saltelli = { from, to } }\n";
    return 1;
  }
  const auto suggest = [](const std::string& w, const std::vector<std::string>& names) {
    const std::string dym = did_you_mean(w, names);
    return dym.empty() ? std::string() : " (did you mean '" + dym + "'?)";
  };
  std::vector<std::string> names;
  for (const auto& d : designs) names.push_back(d.block);
  if (!args.block.empty() && std::find(names.begin(), names.end(), args.block) == names.end()) {
    std::cerr << "kinesweep sensitivity: error: --block " << args.block << ": no such block with a design; expected "
              << join(names, ", ") << suggest(args.block, names) << '\n';
    return 2;
  }
  std::vector<Result> results;
  for (const auto& d : designs) {
    if (!args.block.empty() && d.block != args.block) continue;
    std::vector<std::string> metrics = args.metrics;
    if (metrics.empty()) metrics.emplace_back(meaning_of(reader, d.kind).objective());
    std::vector<std::string> numeric;
    for (const ColumnSpec& c : reader.columns())
      if (c.role == Role::metric && c.type != CellType::str && ("," + c.kinds + ",").find("," + d.kind + ",") != std::string::npos)
        numeric.push_back(c.name);
    for (const std::string& m : metrics)
      if (std::find(numeric.begin(), numeric.end(), m) == numeric.end()) {
        std::cerr << "kinesweep sensitivity: error: --metric " << m << ": not a numeric metric of " << d.kind
                  << " runs; expected one of " << join(numeric, ", ") << suggest(m, numeric) << '\n';
        return 2;
      }
    analyse(reader, d, metrics, opt, results);
  }
  if (args.format == "json") print_json(args.file, results, opt, std::cout);
  else print_table(results, opt.confidence, std::cout);
  return 0;
}

}  // namespace

int sensitivity_command(const SensitivityArgs& args) {
  try {
    return run_sensitivity(args);
  } catch (const std::exception& e) {
    std::cerr << "kinesweep sensitivity: error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace ks::cli
