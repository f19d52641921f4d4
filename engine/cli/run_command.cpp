#include "cli/run_command.hpp"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <thread>

#include "common/human_units.hpp"
#include "common/shell_word.hpp"
#include "runner/run_study.hpp"
#include "store/store.hpp"
#include "study/study.hpp"

namespace ks::cli {

namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_sigint(int) { g_stop.store(true); }

/// SIGINT and SIGTERM set g_stop from here to the end of the command: the command then ends at its
/// next stopping point (before the results file is created, between runs, between evaluations).
struct StopOnSignals {
  StopOnSignals() {
    std::signal(SIGINT, on_sigint);
    std::signal(SIGTERM, on_sigint);
  }
  ~StopOnSignals() {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
  }
};

/// For tests of signal handling: with KINESWEEP_TEST_PAUSE_BEFORE_SWEEP set, announce "paused" on
/// stderr and wait (up to 60 s) for g_stop once the study is validated, before anything is written.
void test_pause_before_sweep() {
  if (!std::getenv("KINESWEEP_TEST_PAUSE_BEFORE_SWEEP")) return;
  std::cerr << "paused before the sweep (KINESWEEP_TEST_PAUSE_BEFORE_SWEEP)" << std::endl;
  for (int i = 0; i < 6000 && !g_stop.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

/// Why `path` cannot name a file ("" when it can): a NUL would cut it short, control characters
/// are almost always a slip of a script.
std::string path_chars_problem(const std::string& path) {
  for (unsigned char c : path)
    if (c < 0x20 || c == 0x7f)
      return c == 0 ? "contains a NUL character; expected a path without control characters"
                    : "contains a control character; expected a path without control characters";
  return "";
}

/// Why `path` cannot name a results file ("" when it can): the file is HDF5, so its name ends in
/// .h5 or .hdf5 (a .csv or .json name would hide what it holds; `kinesweep query` exports those).
std::string output_name_problem(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string ext = p.extension().string();
  if (ext == ".h5" || ext == ".hdf5") return "";
  std::string m = "a results file is HDF5; expected a name ending in .h5 (or .hdf5)";
  if (ext == ".csv" || ext == ".json")
    m += "; for " + ext.substr(1) + ", run into FILE.h5, then: kinesweep query FILE.h5 --format " + ext.substr(1);
  return m;
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

int run_command(const RunArgs& a) {
  const StopOnSignals signals;  // before anything is read or created
  store::print_hdf5_error_stack(a.verbose);
  Study study;
  try {
    study = load_study(a.study, StudyOptions{.max_runs = a.max_runs, .robot_text = {}});
  } catch (const StudyError& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
  HistoryPolicy histories = study.histories;
  if (!a.histories.empty() && !HistoryPolicy::parse(a.histories, histories)) {
    std::cerr << "kinesweep run: --histories " << a.histories << ": expected full, none or every=N (N >= 1)\n";
    return 2;
  }
  if (a.resume && a.overwrite) {
    std::cerr << "kinesweep run: --resume and --overwrite exclude each other\n";
    return 2;
  }
  const std::string output = a.output.empty() ? study.output : a.output;
  std::string why = path_chars_problem(output);
  if (why.empty()) why = output_name_problem(output);
  if (!why.empty()) {
    std::cerr << "kinesweep run: " << (a.output.empty() ? "the study's output " : "-o ") << shell_word(output) << ": "
              << why << '\n';
    return 2;
  }
  RunRequest r;
  r.study_arg = a.study;
  r.program = a.program;
  r.output = output;
  r.resume = a.resume;
  r.overwrite = a.overwrite;
  r.quiet = a.quiet;
  r.verify_best = !a.no_verify_best;
  r.dry_run = a.dry_run;  // a few seconds at most; its temporary files are removed before it returns
  r.options.threads = a.threads;
  r.options.lanes = a.lanes;
  r.options.histories = histories;
  r.histories_given = !a.histories.empty();
  r.options.compression = a.compression;
  r.options.stop = &g_stop;
  ProgressDisplay progress(a.quiet);
  r.options.on_progress = [&](const SweepProgress& p) { progress(p); };
  test_pause_before_sweep();
  const int code = run_study(study, r, std::cout, std::cerr);
  if (code == 1) {
    // A results-file failure (e.g. a full disk) can leave HDF5 1.10 holding a file whose close
    // failed, and its at-exit shutdown then crashes closing it again. End here instead: the file is
    // left as a killed process leaves it, and its journal restores the last commit at --resume.
    std::cout.flush();
    std::cerr.flush();
    std::_Exit(1);
  }
  return code;
}

}  // namespace ks::cli
