#include "cli/run_command.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <thread>

#include "runner/run_study.hpp"
#include "store/store.hpp"
#include "study/study.hpp"

namespace ks::cli {

namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_sigint(int) { g_stop.store(true); }

/// "full", "none", "every=N" -> policy; false when malformed.
bool parse_histories(const std::string& s, HistoryPolicy& p) {
  if (s == "full") {
    p = {HistoryPolicy::Mode::full, 1};
    return true;
  }
  if (s == "none") {
    p = {HistoryPolicy::Mode::none, 0};
    return true;
  }
  if (s.rfind("every=", 0) == 0) {
    try {
      std::size_t used = 0;
      const int n = std::stoi(s.substr(6), &used);
      if (n >= 1 && used == s.size() - 6) {
        p = {HistoryPolicy::Mode::every, n};
        return true;
      }
    } catch (...) {
    }
  }
  return false;
}

std::string human_bytes(double b) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  int u = 0;
  while (b >= 1024 && u < 4) b /= 1024, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %s", b, units[u]);
  return buf;
}
std::string human_time(double s) {
  char buf[32];
  if (s < 120) std::snprintf(buf, sizeof buf, "%.1f s", s);
  else if (s < 7200) std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  else std::snprintf(buf, sizeof buf, "%.1f h", s / 3600);
  return buf;
}

int dry_run(const Study& study, const StudySchema& schema, const HistoryPolicy& h, int threads, int level) {
  std::cout << "study " << study.name << " (" << study.file << "), sha256 " << study.sha256 << '\n';
  for (const Block& b : study.blocks) {
    std::cout << "  block " << b.name() << " (" << to_string(b.kind()) << "): " << b.run_count() << " runs =";
    const auto shape = b.shape();
    if (shape.empty()) std::cout << " 1";
    for (std::size_t d = 0; d < shape.size(); ++d) std::cout << (d ? " x " : " ") << shape[d];
    std::cout << '\n';
  }
  // Estimate from a few runs spread over the study, executed here on one thread.
  const std::uint64_t total = study.run_count();
  const int stride = h.mode == HistoryPolicy::Mode::none ? 0 : h.stride;
  const std::uint64_t samples = std::min<std::uint64_t>(total, 24);
  RunWorkspace ws;
  double seconds = 0, bytes = 0;
  for (std::uint64_t i = 0; i < samples; ++i) {
    const std::uint64_t id = samples > 1 ? i * (total - 1) / (samples - 1) : 0;
    const RunRef ref = study.locate(id);
    const RunSpec run = study.blocks[ref.block].run(ref.local);
    const auto t0 = std::chrono::steady_clock::now();
    const RunOutcome o = execute(Scenario::of(study), run, stride, ws);
    const store::EncodedHistory encoded = store::encode_history(o.history, level);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (const auto& a : encoded.arrays) bytes += static_cast<double>(a.bytes.size()) + 600;
  }
  const double per_run_s = samples ? seconds / samples : 0, per_run_b = samples ? bytes / samples : 0;
  const int n = threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency());
  std::cout << "  total: " << total << " runs; histories " << h.str() << "\n  estimated size: "
            << human_bytes(total * (per_run_b + 9.0 * schema.columns.size())) << "; estimated time: "
            << human_time(total * per_run_s / std::max(1, n)) << " on " << n << " threads (from " << samples
            << " sample runs)\n";
  for (const OptimizeBlock& ob : study.optimizations) {  // run after the sweep
    std::cout << "  optimization " << ob.name << ": minimise " << ob.objective_text << " over";
    for (const auto& v : ob.variables) std::cout << ' ' << v.name;
    if (!ob.polish_block.empty()) std::cout << "; sweep " << ob.polish_block << " (best " << ob.polish_best << ")";
    if (ob.global) std::cout << "; global " << opt::to_string(ob.global->algorithm) << " (max_evals " << ob.global->max_evals << ")";
    if (ob.local) std::cout << "; local " << opt::to_string(ob.local->algorithm) << " (max_evals " << ob.local->max_evals << ")";
    std::cout << '\n';
  }
  return 0;
}

class ProgressDisplay {
 public:
  explicit ProgressDisplay(bool quiet) : tty_(isatty(STDERR_FILENO)), quiet_(quiet) {}
  void operator()(const SweepProgress& p) {
    if (quiet_) return;
    const double rate = p.elapsed_s > 0 ? p.done / p.elapsed_s : 0;
    const double eta = rate > 0 ? (p.todo - p.done) / rate : 0;
    const double frac = p.todo ? static_cast<double>(p.done) / p.todo : 1.0;
    char buf[256];
    if (tty_) {
      const int width = 30, fill = static_cast<int>(frac * width);
      std::string bar(fill, '#');
      bar += std::string(width - fill, '.');
      std::snprintf(buf, sizeof buf, "\r[%s] %llu/%llu runs  %.0f runs/s  ETA %s   ", bar.c_str(),
                    static_cast<unsigned long long>(p.done), static_cast<unsigned long long>(p.todo), rate,
                    human_time(eta).c_str());
      std::cerr << buf << (p.done == p.todo ? "\n" : "") << std::flush;
    } else if (p.elapsed_s - last_ >= 5.0 || p.done == p.todo) {
      last_ = p.elapsed_s;
      std::snprintf(buf, sizeof buf, "progress: %llu/%llu runs (%.1f%%), %.0f runs/s, ETA %s\n",
                    static_cast<unsigned long long>(p.done), static_cast<unsigned long long>(p.todo), 100 * frac, rate,
                    human_time(eta).c_str());
      std::cerr << buf << std::flush;
    }
  }

 private:
  bool tty_, quiet_;
  double last_ = -1e9;
};
}  // namespace

RunArgs& add_run_command(CLI::App& app) {
  static RunArgs a;
  auto* c = app.add_subcommand("run", "Run a study file into an HDF5 results file");
  c->add_option("study", a.study, "study file (TOML)")->required();
  c->add_option("-o,--output", a.output, "results file (default: the study's output, results/<name>.h5)");
  c->add_option("--threads", a.threads, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  c->add_flag("--resume", a.resume, "complete only the runs missing from an existing results file");
  c->add_flag("--overwrite", a.overwrite, "replace an existing results file");
  c->add_flag("--dry-run", a.dry_run, "print runs per block and estimated size and time; write nothing");
  c->add_option("--histories", a.histories, "full | every=N | none (default: the study's)");
  c->add_option("--compression", a.compression, "deflate level of the histories, after HDF5's shuffle (default 1; 0: raw chunks, no filter)")
      ->check(CLI::Range(0, 9));
  c->add_flag("-q,--quiet", a.quiet, "no progress display");
  return a;
}

int run_command(const RunArgs& a) {
  Study study;
  try {
    study = load_study(a.study);
  } catch (const StudyError& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
  HistoryPolicy histories = study.histories;
  if (!a.histories.empty() && !parse_histories(a.histories, histories)) {
    std::cerr << "kinesweep run: --histories " << a.histories << ": expected full, none or every=N (N >= 1)\n";
    return 2;
  }
  if (a.resume && a.overwrite) {
    std::cerr << "kinesweep run: --resume and --overwrite exclude each other\n";
    return 2;
  }
  if (a.dry_run) return dry_run(study, make_schema(study), histories, a.threads, a.compression);

  RunRequest r;
  r.study_arg = a.study;
  r.output = a.output.empty() ? study.output : a.output;
  r.resume = a.resume;
  r.overwrite = a.overwrite;
  r.quiet = a.quiet;
  r.options.threads = a.threads;
  r.options.histories = histories;
  r.options.compression = a.compression;
  r.options.stop = &g_stop;
  ProgressDisplay progress(a.quiet);
  r.options.on_progress = [&](const SweepProgress& p) { progress(p); };
  std::signal(SIGINT, on_sigint);
  std::signal(SIGTERM, on_sigint);
  const int code = run_study(study, r, std::cout, std::cerr);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  return code;
}

}  // namespace ks::cli
