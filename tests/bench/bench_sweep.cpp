// Sweep throughput: runs per second at 1 and 2 threads, with histories none and full (issue 4
// targets: 2 threads >= 1.9x one thread; full compressed histories cost <= 15 % of wall time).
// Each iteration runs a 2 x 11 x 11 trajectory sweep (242 runs of 2001 steps) into a fresh file.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "runner/sweep.hpp"

using namespace ks;

namespace {
const char* kStudy = R"(
[study]
name = "bench"
[[block]]
name = "landscape"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { from = -20, to = 30, count = 11 }
k = { from = 0, to = 1, count = 11 }
)";

void sweep(benchmark::State& st) {
  const int threads = static_cast<int>(st.range(0));
  const bool full = st.range(1) != 0;
  const Study study = parse_study(kStudy, "bench.toml");
  const StudySchema schema = make_schema(study);
  const std::string path = (std::filesystem::temp_directory_path() / "kinesweep_bench_sweep.h5").string();
  std::uint64_t runs = 0;
  for (auto _ : st) {
    store::StoreMeta meta;
    meta.study_name = study.name;
    meta.study_text = study.text;
    meta.study_sha256 = study.sha256;
    store::StoreOptions so;
    so.overwrite = true;
    auto writer = store::ResultsWriter::create(path, meta, schema.columns, static_cast<std::int64_t>(study.run_count()), so);
    SweepOptions o;
    o.threads = threads;
    o.histories = full ? HistoryPolicy{HistoryPolicy::Mode::full, 1} : HistoryPolicy{HistoryPolicy::Mode::none, 0};
    const SweepReport r = run_sweep(study, schema, *writer, o);
    writer->close();
    runs += r.written;
  }
  st.counters["runs/s"] = benchmark::Counter(static_cast<double>(runs), benchmark::Counter::kIsRate);
  std::filesystem::remove(path);
}
}  // namespace

BENCHMARK(sweep)
    ->ArgNames({"threads", "full_histories"})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK_MAIN();
