// Sweep throughput: runs per second at 1 and 2 threads, with histories none and full (targets:
// 2 threads >= 1.9x one thread; full compressed histories cost <= 15 % of wall time).
// Each iteration runs a 2 x 81 x 21 trajectory sweep (3402 runs of 2001 steps) into a fresh file.
// histories: 0 none, 1 full (shuffle + deflate level 1), 2 full raw (no filter), 3 every=10 (level 1).
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
alpha1A = { from = -20, to = 30, count = 81 }
k = { from = 0, to = 1, count = 21 }
)";

void sweep(benchmark::State& st) {
  const int threads = static_cast<int>(st.range(0));
  const int mode = static_cast<int>(st.range(1));
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
    o.histories = mode == 0   ? HistoryPolicy{HistoryPolicy::Mode::none, 0}
                  : mode == 3 ? HistoryPolicy{HistoryPolicy::Mode::every, 10}
                              : HistoryPolicy{HistoryPolicy::Mode::full, 1};
    o.compression = mode == 2 ? 0 : 1;
    const SweepReport r = run_sweep(study, schema, *writer, o);
    writer->close();
    runs += r.written;
  }
  st.counters["runs/s"] = benchmark::Counter(static_cast<double>(runs), benchmark::Counter::kIsRate);
  std::filesystem::remove(path);
}
}  // namespace

BENCHMARK(sweep)
    ->ArgNames({"threads", "histories"})
    ->ArgsProduct({{1, 2}, {0, 1, 2, 3}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK_MAIN();
