// A study's results-file metadata (runner/study_meta.hpp).
#include "runner/study_meta.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "common/shell_word.hpp"
#include "schema/params.hpp"

namespace ks {

std::vector<store::KindMeta> kind_meta(const Study& study) {
  std::vector<store::KindMeta> out;
  auto strings = [](auto&& range) {
    std::vector<std::string> v;
    for (const auto& x : range) v.emplace_back(x);
    return v;
  };
  for (const BlockKind kind : block_kinds()) {
    const Block* block = nullptr;
    for (const Block& b : study.blocks)
      if (!block && b.kind() == kind) block = &b;
    for (const OptimizeBlock& o : study.optimizations)
      if (!block && o.block().kind() == kind) block = &o.block();
    if (!block) continue;
    store::KindMeta k;
    k.name = std::string(to_string(kind));
    const auto st = statuses(kind);
    const Ranking rank = ranking(kind);
    std::vector<std::string> ranked{std::string(rank.objective)};
    if (!rank.tie.empty()) ranked.emplace_back(rank.tie);
    const auto arrays = kind == BlockKind::trajectory ? trajectory_history_arrays(study.robot_shape())
                        : kind == BlockKind::motion   ? motion_history_arrays(study.robot_shape())
                                                      : ik_history_arrays(IkProblem::scara, study.robot_shape());
    std::vector<std::string> names, units;
    for (const auto& a : arrays) names.push_back(a.name), units.push_back(a.unit);
    k.lists = {{"statuses", strings(st)},
               {"good_statuses", {std::string(st.front())}},
               {"ranking", ranked},
               {"key_metrics", strings(key_metrics(kind))},
               {"objectives", objective_names(block->metrics())},
               {"history_arrays", names},
               {"resume_context", strings(context_parts(kind))}};
    if (kind != BlockKind::ik) k.lists.emplace_back("history_units", units);
    out.push_back(std::move(k));
  }
  return out;
}

/// The study's blocks whose design dimension is a Saltelli design (its axes written { saltelli = ... }).
std::vector<store::DesignMeta> design_meta(const Study& study) {
  std::vector<store::DesignMeta> out;
  for (std::size_t b = 0; b < study.blocks.size(); ++b) {
    const Block& block = study.blocks[b];
    store::DesignMeta d;
    for (std::size_t k = 0; k < block.dims().size(); ++k) {
      const Dim& dim = block.dims()[k];
      std::string name;
      for (std::size_t a : dim.axes) name += (name.empty() ? "" : "+") + block.axes()[a].name;
      d.dims.push_back(name);
      d.sizes.push_back(static_cast<std::int64_t>(dim.size));
      if (block.axes()[dim.axes.front()].form != "saltelli") continue;
      d.dim = static_cast<std::int64_t>(k);
      for (std::size_t a : dim.axes) d.factors.push_back(block.axes()[a].name);
    }
    if (d.factors.empty()) continue;
    d.block = block.name();
    d.kind = std::string(to_string(block.kind()));
    d.design = "saltelli";
    d.base_samples = d.sizes[static_cast<std::size_t>(d.dim)] / static_cast<std::int64_t>(d.factors.size() + 2);
    d.first_run = static_cast<std::int64_t>(study.first_run(b));
    out.push_back(std::move(d));
  }
  return out;
}

store::StoreMeta store_meta(const Study& study, const HistoryPolicy& histories) {
  store::StoreMeta meta;
  meta.histories = histories.str();
  meta.kinds = kind_meta(study);
  meta.designs = design_meta(study);
  meta.command_line = process_command_line();
  meta.study_name = study.name;
  meta.study_path = study.file;
  meta.study_text = study.text;
  meta.study_sha256 = study.sha256;
  meta.robot_path = study.robot_file;
  meta.robot_text = study.robot_text;
  return meta;
}

namespace {
/// The smallest dt of a trajectory block's runs [s] (its dt axis, else its dt).
double smallest_dt(const Block& b) {
  double dt = std::numeric_limits<double>::infinity();
  bool swept = false;
  for (const Axis& a : b.axes())
    if (a.name == "dt")
      for (const Cell& c : a.values) swept = true, dt = std::min(dt, std::get<double>(c));
  return swept ? dt : std::get<double>(b.value(0, "dt"));
}

std::string number(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%g", v);
  return s;
}

std::string megabytes(double bytes) {
  char s[32];
  std::snprintf(s, sizeof s, "%.0f MB", bytes / 1e6);
  return s;
}
}  // namespace

std::string history_memory_problem(const Study& study, const HistoryPolicy& histories) {
  if (histories.mode == HistoryPolicy::Mode::none) return "";
  double duration = 0;
  for (double d : study.task.durations) duration += d;
  const std::size_t values = values_per_row(trajectory_history_arrays(study.robot_shape()));
  for (const Block& b : study.blocks) {
    if (b.kind() != BlockKind::trajectory || b.run_count() == 0) continue;
    const double dt = smallest_dt(b);
    if (!(dt > 0)) continue;  // refused by the parser
    const double rows = history_rows(duration, dt, histories.stride);
    const double bytes = history_bytes_in_memory(rows, values);
    if (bytes <= kMaxHistoryBytesPerRun) continue;
    int stride = std::max(1, histories.stride);
    while (history_bytes_in_memory(history_rows(duration, dt, stride), values) > kMaxHistoryBytesPerRun) stride *= 2;
    int lo = stride / 2 + 1;  // the smallest stride that fits, between the last two powers of 2
    while (lo < stride) {
      const int mid = lo + (stride - lo) / 2;
      if (history_bytes_in_memory(history_rows(duration, dt, mid), values) > kMaxHistoryBytesPerRun) lo = mid + 1;
      else stride = mid;
    }
    return "block '" + b.name() + "': with histories = " + histories.str() + " a run on the " +
           number(duration) + " s path at dt = " + number(dt) + " s keeps " + std::to_string(static_cast<std::uint64_t>(rows)) + " history rows of " +
           std::to_string(values) + " values, " + megabytes(bytes) + " in memory while it runs; expected at most " +
           megabytes(kMaxHistoryBytesPerRun) + " per run: use histories = \"every=" + std::to_string(stride) +
           "\" or coarser, or \"none\" ([study] histories or --histories)";
  }
  return "";
}

}  // namespace ks
