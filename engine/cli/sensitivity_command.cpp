#include "cli/sensitivity_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>

#include "cli/kind_meaning.hpp"
#include "cli/query_util.hpp"
#include "schema/params.hpp"
#include "sensitivity/design_indices.hpp"
#include "store/store.hpp"

namespace ks::cli {

namespace {

const store::DesignMeta& design_of(const std::vector<store::DesignMeta>& designs, const std::string& block) {
  for (const auto& d : designs)
    if (d.block == block) return d;
  throw std::logic_error("no design of block " + block);
}

/// The meaning of a design's run kind, as the file declares it (cli/kind_meaning.hpp).
KindMeaning meaning_of(const store::ResultsReader& reader, const std::string& name) {
  KindMeaning km = kind_meaning(reader.meta(), name);
  if (!km.known || km.good().empty() || km.objective().empty())
    throw std::runtime_error("unknown run kind '" + name + "' in /designs");
  return km;
}

void print_table(const std::vector<DesignIndices>& results, const std::vector<store::DesignMeta>& designs, double confidence, std::ostream& os) {
  char line[256];
  for (const DesignIndices& r : results) {
    const store::DesignMeta& d = design_of(designs, r.block);
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

void print_json(const std::string& file, const std::vector<DesignIndices>& results, const std::vector<store::DesignMeta>& designs, const SobolOptions& opt, std::ostream& os) {
  auto num = [](double v) {  // round-trip precision: the stored /sensitivity values, digit for digit
    if (!std::isfinite(v)) return std::string("null");
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  os << "{\"file\": " << json_string(file) << ", \"confidence\": " << num(opt.confidence)
     << ", \"bootstrap\": " << opt.bootstrap << ", \"results\": [";
  for (std::size_t k = 0; k < results.size(); ++k) {
    const DesignIndices& r = results[k];
    const store::DesignMeta& d = design_of(designs, r.block);
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
  std::vector<DesignIndices> results;
  for (const auto& d : designs) {
    if (!args.block.empty() && d.block != args.block) continue;
    std::vector<std::string> metrics = args.metrics;
    if (metrics.empty()) metrics.emplace_back(meaning_of(reader, d.kind).objective());
    const std::vector<std::string> numeric = design_metrics(reader, d.kind);
    for (const std::string& m : metrics)
      if (std::find(numeric.begin(), numeric.end(), m) == numeric.end()) {
        std::cerr << "kinesweep sensitivity: error: --metric " << m << ": not a numeric metric of " << d.kind
                  << " runs; expected one of " << join(numeric, ", ") << suggest(m, numeric) << '\n';
        return 2;
      }
    for (DesignIndices& r : design_indices(reader, d, metrics, meaning_of(reader, d.kind).good(), opt))
      results.push_back(std::move(r));
  }
  if (args.format == "json") print_json(args.file, results, designs, opt, std::cout);
  else print_table(results, designs, opt.confidence, std::cout);
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
