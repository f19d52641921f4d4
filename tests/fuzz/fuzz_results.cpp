// Fuzz target for the results-file readers: any bytes as a results file (and, when the bytes hold the
// journal magic "KSJRNL", everything from its first occurrence on as the file's journal), opened through
// every C++ reader of results files: ResultsReader's whole read API (metadata, every /runs column,
// histories, landscapes, designs, optimisations), the commands behind `kinesweep info`, `query` (rows,
// --group-by, --pareto, --run/--history, --optimization) and `sensitivity`, and ResultsWriter::open_for_resume
// (resume's open). Any exception is an answer (a damaged file refused); a crash, a hang, unbounded
// memory or undefined behaviour is a defect. Built with libFuzzer under clang (-DKINESWEEP_FUZZ=ON);
// results_corpus_check drives the same entry point with any compiler.
#include <dirent.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "cli/info_command.hpp"
#include "cli/query_command.hpp"
#include "cli/query_util.hpp"
#include "cli/sensitivity_command.hpp"
#include "store/store.hpp"

namespace {

// Reads of histories stop after this many runs (a file of many runs would otherwise make one input
// take seconds).
constexpr std::int64_t kHistoryRuns = 8;

/// A directory of its own under $TMPDIR (or /tmp), made once per process; the input is written there
/// as results.h5 (and results.h5.journal).
const std::string& work_dir() {
  static const std::string dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string t = std::string(tmp && *tmp ? tmp : "/tmp") + "/ks_fuzz_results.XXXXXX";
    if (!::mkdtemp(t.data())) {
      std::perror("fuzz_results: mkdtemp");
      std::abort();
    }
    return t;
  }();
  return dir;
}

void write_file(const std::string& path, std::string_view bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f || std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fclose(f) != 0) {
    std::perror(path.c_str());
    std::abort();
  }
}

/// Remove the input's files and whatever a reader or resume left beside them (lock files, staged
/// copies), so that the next input starts from an empty directory.
void clear_dir(const std::string& dir) {
  if (DIR* d = ::opendir(dir.c_str())) {
    std::vector<std::string> names;
    while (const dirent* e = ::readdir(d))
      if (std::string_view(e->d_name) != "." && std::string_view(e->d_name) != "..") names.emplace_back(e->d_name);
    ::closedir(d);
    for (const std::string& n : names) ::unlink((dir + "/" + n).c_str());
  }
}

/// std::cout and std::cerr discarded while alive (the commands print tables and errors).
class Silence {
 public:
  Silence() : out_(std::cout.rdbuf(&null_)), err_(std::cerr.rdbuf(&null_)) {}
  ~Silence() {
    std::cout.rdbuf(out_);
    std::cerr.rdbuf(err_);
  }

 private:
  struct NullBuf : std::streambuf {
    int overflow(int c) override { return c == EOF ? 0 : c; }
    std::streamsize xsputn(const char*, std::streamsize n) override { return n; }
  } null_;
  std::streambuf* out_;
  std::streambuf* err_;
};

/// Every read ResultsReader offers, on the file at `path`; exceptions propagate. Returns the file's
/// study hash (for resume's open).
std::string read_everything(const std::string& path) {
  ks::store::ResultsReader r(path, ks::cli::v1_column_roles);
  const std::string sha = r.meta().study_sha256;
  const std::int64_t n = r.n_runs();
  (void)r.done_mask();
  for (const ks::ColumnSpec& c : r.columns()) {
    try {
      switch (c.type) {
        case ks::CellType::f64: (void)r.read_f64(c.name, 0, 64); break;
        case ks::CellType::i64: (void)r.read_i64(c.name, 0, 64); break;
        case ks::CellType::str: (void)r.read_str(c.name, 0, 64); break;
      }
      (void)r.read_column(c.name);
    } catch (const std::exception&) {
    }
  }
  try {
    (void)r.read_rows(0, 16);
    (void)r.read_rows(std::vector<std::int64_t>{0, n / 2, n - 1});
  } catch (const std::exception&) {
  }
  if (r.has_histories())
    for (std::int64_t id = 0, seen = 0; id < n && seen < kHistoryRuns; ++id) {
      try {
        if (!r.has_history(id)) continue;
        ++seen;
        (void)r.read_history(id);
        (void)r.read_history_chunks(id);
      } catch (const std::exception&) {
      }
    }
  for (const std::string& block : r.landscapes()) {
    try {
      (void)r.read_landscape(block, false);
      (void)r.read_landscape(block, true);
    } catch (const std::exception&) {
    }
  }
  try {
    (void)r.designs();
  } catch (const std::exception&) {
  }
  for (const std::string& name : r.optimizations()) {
    try {
      (void)r.read_optimization(name);
    } catch (const std::exception&) {
    }
  }
  r.refresh();
  (void)r.unchanged_since_open();
  return sha;
}

/// The commands that read results files, as `kinesweep info|query|sensitivity` run them (they catch
/// their errors and return an exit code).
void run_commands(const std::string& path) {
  {
    ks::cli::InfoArgs a;
    a.file = path;
    (void)ks::cli::info_command(a);
  }
  {
    ks::cli::QueryArgs a;
    a.file = path;
    a.columns = "all";
    a.format = "csv";
    a.include_pending = true;
    a.limit = 64;
    (void)ks::cli::query_command(a);
  }
  {
    ks::cli::QueryArgs a;
    a.file = path;
    a.group_by = "block";
    a.agg = "count,min:E,argmin:E";
    (void)ks::cli::query_command(a);
  }
  {
    ks::cli::QueryArgs a;
    a.file = path;
    a.where = {"status == ok"};
    a.sort = {"E"};
    a.format = "json";
    a.limit = 8;
    (void)ks::cli::query_command(a);
  }
  for (const char* reference : {"", "100,0"}) {
    ks::cli::QueryArgs a;
    a.file = path;
    a.pareto = "E,min_manipulability:max";
    a.hypervolume = reference;
    a.limit = 16;
    (void)ks::cli::query_command(a);
  }
  {
    ks::cli::QueryArgs a;
    a.file = path;
    a.run = 0;
    a.history = "all";
    a.limit = 16;
    (void)ks::cli::query_command(a);
  }
  try {
    ks::store::ResultsReader r(path, ks::cli::v1_column_roles);
    for (const std::string& name : r.optimizations()) {
      ks::cli::QueryArgs a;
      a.file = path;
      a.optimization = name;
      a.limit = 16;
      (void)ks::cli::query_command(a);
    }
  } catch (const std::exception&) {
  }
  {
    ks::cli::SensitivityArgs a;
    a.file = path;
    a.bootstrap = 20;
    (void)ks::cli::sensitivity_command(a);
    a.format = "json";
    (void)ks::cli::sensitivity_command(a);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = (ks::store::print_hdf5_error_stack(false), true);
  (void)quiet;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::size_t j = bytes.find("KSJRNL");
  const std::string& dir = work_dir();
  const std::string path = dir + "/results.h5";
  clear_dir(dir);
  write_file(path, bytes.substr(0, j));
  if (j != std::string_view::npos) write_file(path + ".journal", bytes.substr(j));  // FORMAT.md: the journal beside the file
  Silence silence;
  std::string sha;
  try {
    sha = read_everything(path);
  } catch (const std::exception&) {
  }
  run_commands(path);
  try {
    ks::store::StoreOptions o;
    o.flush_every_seconds = 0;
    ks::store::ResultsWriter::Resumed resumed = ks::store::ResultsWriter::open_for_resume(path, sha, o);
    if (resumed.writer) {
      (void)resumed.writer->n_runs();
      resumed.writer->close();
    }
  } catch (const std::exception&) {
  }
  clear_dir(dir);
  return 0;
}
