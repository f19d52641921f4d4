// The HDF5 results store: round trips, resume, refusal/failure paths, and crash safety under SIGKILL.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include "store/store.hpp"
#include "store_testgen.hpp"

namespace {
namespace fs = std::filesystem;
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Equal cells; doubles compared bit for bit (NaN == NaN, -0 != +0).
bool same_cell(const Cell& a, const Cell& b) {
  if (a.index() != b.index()) return false;
  if (auto* x = std::get_if<double>(&a)) return same_bits(*x, std::get<double>(b));
  return a == b;
}

void expect_same_history(const RunHistory& got, const RunHistory& want, std::int64_t id) {
  ASSERT_EQ(got.arrays.size(), want.arrays.size()) << "run " << id;
  for (std::size_t k = 0; k < want.arrays.size(); ++k) {
    const auto &g = got.arrays[k], &w = want.arrays[k];
    EXPECT_EQ(g.name, w.name);
    EXPECT_EQ(g.unit, w.unit);
    EXPECT_EQ(g.rows, w.rows);
    EXPECT_EQ(g.cols, w.cols);
    ASSERT_EQ(g.data.size(), w.data.size());
    if (!w.data.empty())  // memcmp of an empty vector's null data is undefined
      EXPECT_EQ(0, std::memcmp(g.data.data(), w.data.data(), w.data.size() * sizeof(double)))
          << "run " << id << " array " << w.name << " not bit-identical";
  }
}

/// Checks every run marked done against the generator; returns the number of done runs.
std::int64_t verify_done_runs(const ResultsReader& r) {
  auto done = r.done_mask();
  std::vector<std::vector<Cell>> cols;
  for (auto& c : r.columns()) cols.push_back(r.read_column(c.name));
  std::int64_t n_done = 0;
  for (std::int64_t id = 0; id < r.n_runs(); ++id) {
    const auto want = test_record(id);
    if (!done[static_cast<std::size_t>(id)]) {
      // An undone row holds the missing values, or (when the writer died between committing the rows
      // and committing their done flags) exactly the right values; never anything else.
      bool all_missing = true, all_right = true;
      for (std::size_t c = 0; c < cols.size(); ++c) {
        const Cell& g = cols[c][static_cast<std::size_t>(id)];
        if (auto* d = std::get_if<double>(&g)) {
          all_missing = all_missing && std::isnan(*d);
        } else if (auto* i = std::get_if<std::int64_t>(&g)) {
          all_missing = all_missing && *i == -1;
        } else {
          all_missing = all_missing && std::get<std::string>(g).empty();
        }
        all_right = all_right && same_cell(g, want.cells[c]);
      }
      EXPECT_TRUE(all_missing || all_right) << "undone run " << id << " holds a torn row";
      if (r.has_history(id)) expect_same_history(r.read_history(id), test_history(id), id);
      continue;
    }
    ++n_done;
    for (std::size_t c = 0; c < cols.size(); ++c)
      EXPECT_TRUE(same_cell(cols[c][static_cast<std::size_t>(id)], want.cells[c]))
          << "run " << id << " column " << r.columns()[c].name;
    expect_same_history(r.read_history(id), test_history(id), id);
  }
  return n_done;
}

/// Non-asserting variant for possibly mixed snapshots: "" when every done run is right.
std::string check_snapshot(const ResultsReader& r, std::int64_t* n_done, int history_stride = 1) {
  auto done = r.done_mask();
  std::vector<std::vector<Cell>> cols;
  for (auto& c : r.columns()) cols.push_back(r.read_column(c.name));
  *n_done = 0;
  for (std::int64_t id = 0; id < r.n_runs(); ++id) {
    if (!done[static_cast<std::size_t>(id)]) continue;
    ++*n_done;
    const auto want = test_record(id);
    for (std::size_t c = 0; c < cols.size(); ++c)
      if (!same_cell(cols[c][static_cast<std::size_t>(id)], want.cells[c]))
        return "run " + std::to_string(id) + " column " + r.columns()[c].name;
    if (id % history_stride != 0 && id + 8 < r.n_runs() && done[static_cast<std::size_t>(id + 8)]) continue;
    const auto got = r.read_history(id), w = test_history(id);
    if (got.arrays.size() != w.arrays.size()) return "run " + std::to_string(id) + " history arrays";
    for (std::size_t k = 0; k < w.arrays.size(); ++k)
      if (got.arrays[k].data.size() != w.arrays[k].data.size() ||
          (!w.arrays[k].data.empty() &&
           std::memcmp(got.arrays[k].data.data(), w.arrays[k].data.data(), w.arrays[k].data.size() * 8) != 0))
        return "run " + std::to_string(id) + " history " + w.arrays[k].name;
  }
  return "";
}

std::unique_ptr<ResultsWriter> make_writer(const std::string& path, std::int64_t n, StoreOptions opt = {}) {
  return ResultsWriter::create(path, test_meta(), test_columns(), n, opt);
}

// ------------------------------------------------------------------------------------------------
// The bytes are what HDF5's filter pipeline stores: zlib(shuffle(data)); inflating and unshuffling
// (byte j of element i at j * n + i) gives the array back.
TEST(StoreEncode, DeflateStreamDecodesToTheRawArray) {
  auto h = test_history(3);
  auto e = encode_history(h, 6);
  ASSERT_EQ(e.arrays.size(), h.arrays.size());
  for (std::size_t k = 0; k < h.arrays.size(); ++k) {
    const auto& a = h.arrays[k];
    EXPECT_EQ(e.arrays[k].rows, a.rows);
    if (a.data.empty()) { EXPECT_TRUE(e.arrays[k].bytes.empty()); continue; }
    std::vector<unsigned char> shuffled(a.data.size() * sizeof(double));
    uLongf n = static_cast<uLongf>(shuffled.size());
    ASSERT_EQ(uncompress(shuffled.data(), &n, e.arrays[k].bytes.data(), e.arrays[k].bytes.size()), Z_OK);
    EXPECT_EQ(n, a.data.size() * sizeof(double));
    std::vector<double> back(a.data.size());
    auto* b = reinterpret_cast<unsigned char*>(back.data());
    for (std::size_t i = 0; i < back.size(); ++i)
      for (std::size_t j = 0; j < 8; ++j) b[i * 8 + j] = shuffled[j * back.size() + i];
    EXPECT_EQ(0, std::memcmp(back.data(), a.data.data(), n));
    auto raw = encode_history(RunHistory{{a}}, 0);  // level 0: the raw array, no filter
    ASSERT_EQ(raw.arrays[0].bytes.size(), n);
    EXPECT_EQ(0, std::memcmp(raw.arrays[0].bytes.data(), a.data.data(), n));
  }
  HistoryArray bad{"x", "", 3, 2, {1.0, 2.0}};
  EXPECT_THROW(encode_history(RunHistory{{bad}}), StoreError);
}

// The same oracle (zlib's own inflate) on sizes around the 65535-byte stored-block limit of the
// stream's low byte planes (6 n bytes: one, two and several stored blocks), smooth and random data.
TEST(StoreEncode, StoredAndDeflatedPartsDecodeAtEverySize) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  for (std::size_t rows : {1u, 7u, 3640u, 3641u, 10922u, 10923u, 40000u})
    for (int level : {1, 9}) {
      HistoryArray a{"x", "m", rows, 3, std::vector<double>(rows * 3)};
      for (std::size_t i = 0; i < a.data.size(); ++i) a.data[i] = i % 2 ? u(rng) : std::sin(0.001 * i);
      const auto e = encode_history(RunHistory{{a}}, level);
      std::vector<unsigned char> shuffled(a.data.size() * 8 + 16);
      uLongf n = static_cast<uLongf>(shuffled.size());
      ASSERT_EQ(uncompress(shuffled.data(), &n, e.arrays[0].bytes.data(), e.arrays[0].bytes.size()), Z_OK) << rows;
      ASSERT_EQ(n, a.data.size() * 8);
      std::vector<double> back(a.data.size());
      auto* b = reinterpret_cast<unsigned char*>(back.data());
      for (std::size_t i = 0; i < back.size(); ++i)
        for (std::size_t j = 0; j < 8; ++j) b[i * 8 + j] = shuffled[j * back.size() + i];
      EXPECT_EQ(0, std::memcmp(back.data(), a.data.data(), n)) << rows << " rows, level " << level;
    }
}

TEST(StoreEncode, ThreadSafeInWorkers) {
  std::vector<std::thread> th;
  std::vector<int> ok(4, 0);
  for (int t = 0; t < 4; ++t)
    th.emplace_back([t, &ok] {
      for (int i = 0; i < 50; ++i) {
        auto e = encode_history(test_history(t * 50 + i), 4);
        auto again = encode_history(test_history(t * 50 + i), 4);
        for (std::size_t k = 0; k < e.arrays.size(); ++k) ok[t] += e.arrays[k].bytes == again.arrays[k].bytes ? 0 : 1;
      }
    });
  for (auto& x : th) x.join();
  for (int v : ok) EXPECT_EQ(v, 0);
}

TEST(Store, RoundTripRowsHistoriesLandscapeAndMetadata) {
  TempDir td;
  const std::string path = td.file("r.h5");
  const std::int64_t n = 40;
  {
    auto w = make_writer(path, n);
    for (std::int64_t id = n - 1; id >= 0; --id)  // reverse order: any order is accepted
      w->write_run(id, test_record(id), encode_history(test_history(id), 5));
    w->write_landscape(test_landscape());
    w->close();
  }
  EXPECT_FALSE(fs::exists(path + ".journal"));
  ResultsReader r(path);
  const auto m = test_meta();
  EXPECT_EQ(r.meta().format, "kinesweep-results");
  EXPECT_EQ(r.meta().format_version, kFormatVersion);
  EXPECT_EQ(r.meta().study_name, m.study_name);
  EXPECT_EQ(r.meta().study_path, m.study_path);
  EXPECT_EQ(r.meta().study_text, m.study_text);
  EXPECT_EQ(r.meta().study_sha256, m.study_sha256);
  EXPECT_EQ(r.meta().engine_version, std::string(KINESWEEP_VERSION));
  ASSERT_EQ(r.meta().created.size(), 20u);  // YYYY-MM-DDTHH:MM:SSZ
  EXPECT_EQ(r.meta().created[10], 'T');
  EXPECT_EQ(r.meta().created.back(), 'Z');
  ASSERT_EQ(r.columns().size(), test_columns().size());
  for (std::size_t c = 0; c < r.columns().size(); ++c) {
    EXPECT_EQ(r.columns()[c].name, test_columns()[c].name);
    EXPECT_EQ(r.columns()[c].type, test_columns()[c].type);
    EXPECT_EQ(r.columns()[c].unit, test_columns()[c].unit);
    EXPECT_EQ(r.columns()[c].description, test_columns()[c].description);
    EXPECT_EQ(r.columns()[c].role, test_columns()[c].role);
    EXPECT_EQ(r.columns()[c].kinds, test_columns()[c].kinds);
  }
  EXPECT_EQ(r.n_runs(), n);
  EXPECT_EQ(verify_done_runs(r), n);
  // typed access and single records agree with the generator
  auto alpha = r.read_f64("alpha");
  EXPECT_TRUE(std::isnan(alpha[3]));
  EXPECT_EQ(r.read_i64("iters")[0], -1);
  EXPECT_EQ(r.read_str("status")[3], "ok-\xc3\xb1");
  auto rec = r.read_record(22);
  for (std::size_t c = 0; c < rec.cells.size(); ++c) EXPECT_TRUE(same_cell(rec.cells[c], test_record(22).cells[c]));
  EXPECT_FALSE(r.has_history(4));
  EXPECT_THROW(r.read_f64("status"), StoreError);
  EXPECT_THROW(r.read_column("nope"), StoreError);
  // landscape
  ASSERT_EQ(r.landscapes(), std::vector<std::string>{"A"});
  auto want = test_landscape();
  auto got = r.read_landscape("A");
  ASSERT_EQ(got.axes.size(), want.axes.size());
  for (std::size_t i = 0; i < want.axes.size(); ++i) {
    EXPECT_EQ(got.axes[i].name, want.axes[i].name);
    EXPECT_EQ(got.axes[i].unit, want.axes[i].unit);
    EXPECT_EQ(got.axes[i].values, want.axes[i].values);
  }
  ASSERT_EQ(got.metrics.size(), 1u);
  EXPECT_EQ(got.metrics[0].unit, "Nm");
  ASSERT_EQ(got.metrics[0].grid.size(), want.metrics[0].grid.size());
  for (std::size_t i = 0; i < want.metrics[0].grid.size(); ++i)
    EXPECT_TRUE(same_bits(got.metrics[0].grid[i], want.metrics[0].grid[i]));
}

TEST(Store, UnwrittenRowsHoldMissingValuesAndCommitIsAtFlush) {
  TempDir td;
  const std::string path = td.file("p.h5");
  StoreOptions opt;
  opt.flush_every_runs = 0;
  opt.flush_every_seconds = 0;
  auto w = make_writer(path, 30, opt);
  for (std::int64_t id : {5, 1, 17, 29}) w->write_run(id, test_record(id), test_history(id));
  EXPECT_EQ(w->pending(), 4u);
  EXPECT_TRUE(w->is_done(17));
  {
    ResultsReader r(path);  // reads while the writer is open: nothing committed yet
    auto d = r.done_mask();
    EXPECT_EQ(std::count(d.begin(), d.end(), 1), 0);
  }
  w->flush();
  {
    ResultsReader r(path);
    EXPECT_EQ(verify_done_runs(r), 4);
  }
  w->write_run(2, test_record(2), test_history(2));
  w->close();
  ResultsReader r(path);
  EXPECT_EQ(verify_done_runs(r), 5);
}

TEST(Store, AutomaticFlushEveryKRuns) {
  TempDir td;
  const std::string path = td.file("k.h5");
  StoreOptions opt;
  opt.flush_every_runs = 3;
  opt.flush_every_seconds = 0;
  auto w = make_writer(path, 10, opt);
  for (std::int64_t id = 0; id < 7; ++id) w->write_run(id, test_record(id), test_history(id));
  EXPECT_EQ(w->pending(), 1u);
  ResultsReader r(path);
  EXPECT_EQ(verify_done_runs(r), 6);
}

TEST(Store, ResumeFillsGapsAndEqualsUninterruptedRun) {
  TempDir td;
  const std::string ref = td.file("ref.h5"), part = td.file("part.h5");
  const std::int64_t n = 25;
  {
    auto w = make_writer(ref, n);
    for (std::int64_t id = 0; id < n; ++id) w->write_run(id, test_record(id), test_history(id));
  }
  {
    auto w = make_writer(part, n);
    for (std::int64_t id = 0; id < n; id += 3) w->write_run(id, test_record(id), test_history(id));
  }
  EXPECT_THROW(ResultsWriter::open_for_resume(part, std::string(64, '0')), StoreError);
  try {
    ResultsWriter::open_for_resume(part, std::string(64, '0'));
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("sha256"), std::string::npos) << e.what();
  }
  {
    auto res = ResultsWriter::open_for_resume(part, test_meta().study_sha256);
    std::vector<std::int64_t> want;
    for (std::int64_t id = 0; id < n; id += 3) want.push_back(id);
    EXPECT_EQ(res.done, want);
    EXPECT_EQ(res.writer->columns().size(), test_columns().size());
    for (std::int64_t id = n - 1; id >= 0; --id)
      if (!res.writer->is_done(id)) res.writer->write_run(id, test_record(id), test_history(id));
    res.writer->close();
  }
  ResultsReader a(ref), b(part);
  EXPECT_EQ(a.done_mask(), b.done_mask());
  for (auto& c : a.columns()) {
    auto x = a.read_column(c.name), y = b.read_column(c.name);
    ASSERT_EQ(x.size(), y.size());
    for (std::size_t i = 0; i < x.size(); ++i) EXPECT_TRUE(same_cell(x[i], y[i])) << c.name << " row " << i;
  }
  for (std::int64_t id = 0; id < n; ++id) expect_same_history(b.read_history(id), a.read_history(id), id);
}

TEST(Store, SecondWriterIsRefusedWhileOneIsOpen) {
  TempDir td;
  const std::string path = td.file("busy.h5");
  auto w = make_writer(path, 5);
  EXPECT_THROW(ResultsWriter::open_for_resume(path, test_meta().study_sha256), StoreError);
  EXPECT_THROW(make_writer(path, 5, StoreOptions{.overwrite = true}), StoreError);
  w->write_run(0, test_record(0), test_history(0));
  w->close();
  ResultsReader r(path);
  EXPECT_EQ(verify_done_runs(r), 1);
}

TEST(Store, NeverOverwritesUnlessAskedAndFailuresKeepTheOldFile) {
  TempDir td;
  const std::string path = td.file("keep.h5");
  {
    auto w = make_writer(path, 3);
    w->write_run(1, test_record(1), test_history(1));
  }
  const std::string before = slurp(path);
  EXPECT_THROW(make_writer(path, 3), StoreError);
  EXPECT_EQ(slurp(path), before);
  // a failing creation (bad schema) with overwrite leaves the old file alone
  auto cols = test_columns();
  cols.push_back(cols[0]);  // duplicate column
  EXPECT_THROW(ResultsWriter::create(path, test_meta(), cols, 3, StoreOptions{.overwrite = true}), StoreError);
  EXPECT_EQ(slurp(path), before);
  cols = test_columns();
  cols.push_back({"done", CellType::f64, "", "", Role::bookkeeping, ""});
  EXPECT_THROW(ResultsWriter::create(path, test_meta(), cols, 3, StoreOptions{.overwrite = true}), StoreError);
  EXPECT_EQ(slurp(path), before);
  // no temporary files left behind
  for (auto& e : fs::directory_iterator(td.dir)) EXPECT_EQ(e.path().filename(), "keep.h5");
  {
    auto w = make_writer(path, 4, StoreOptions{.overwrite = true});
    w->close();
  }
  ResultsReader r(path);
  EXPECT_EQ(r.n_runs(), 4);
  EXPECT_EQ(verify_done_runs(r), 0);
}

TEST(Store, UnwritableLocationsGiveStoreErrorWithPathAndCause) {
  TempDir td;
  const std::string regular = td.file("plainfile");
  std::ofstream(regular) << "x";
  for (const std::string& path : {regular + "/results.h5", std::string("/proc/ks_results.h5"),
                                 td.file("no/such/dir/results.h5")}) {
    try {
      make_writer(path, 3);
      ADD_FAILURE() << "no error for " << path;
    } catch (const StoreError& e) {
      EXPECT_EQ(e.path(), path);
      EXPECT_FALSE(e.cause().empty());
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    }
  }
  EXPECT_THROW(ResultsReader(td.file("absent.h5")), StoreError);
  EXPECT_THROW(ResultsWriter::open_for_resume(td.file("absent.h5"), "x"), StoreError);
}

TEST(Store, BadInputIsRejected) {
  TempDir td;
  auto w = make_writer(td.file("bad.h5"), 3);
  EXPECT_THROW(w->write_run(3, test_record(0)), StoreError);
  EXPECT_THROW(w->write_run(-1, test_record(0)), StoreError);
  Record r = test_record(0);
  r.cells[0] = std::int64_t{1};
  EXPECT_THROW(w->write_run(0, r), StoreError);
  r.cells.pop_back();
  EXPECT_THROW(w->write_run(0, r), StoreError);
  auto l = test_landscape();
  l.metrics[0].grid.pop_back();
  EXPECT_THROW(w->write_landscape(l), StoreError);
  w->write_run(0, test_record(0), test_history(0));  // the writer is still usable
  w->close();
  EXPECT_THROW(w->flush(), StoreError);
}

// ------------------------------------------------------------------------------------------------
// Crash safety.

/// Opens the file with the plain HDF5 C API (default sec2 driver, read-only, no recovery).
bool opens_with_plain_hdf5(const std::string& path) {
  H5E_auto2_t f;
  void* d;
  H5Eget_auto2(H5E_DEFAULT, &f, &d);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  bool ok = id >= 0;
  if (ok) {
    hid_t ds = H5Dopen2(id, "runs/done", H5P_DEFAULT);
    ok = ds >= 0;
    if (ok) H5Dclose(ds);
    H5Fclose(id);
  }
  H5Eset_auto2(H5E_DEFAULT, f, d);
  return ok;
}

bool journal_has_commit(const std::string& results) {
  // same check as store::detail::journal_has_pending_commit, read from the file format (FORMAT.md)
  std::string j = slurp(results + ".journal");
  if (j.size() < 64) return false;
  return j.compare(j.size() - 32, 8, "KSJCMT01") == 0;
}

pid_t spawn_helper(const std::vector<std::string>& args, const std::string& crash_env = "") {
  pid_t pid = fork();
  if (pid == 0) {
    if (!crash_env.empty()) setenv("KS_STORE_TEST_CRASH", crash_env.c_str(), 1);
    int devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    std::vector<char*> argv;
    std::string exe = STORE_WRITER_HELPER;
    argv.push_back(exe.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

TEST(StoreCrash, ExitWithoutCloseKeepsExactlyTheFlushedRuns) {
  TempDir td;
  const std::string path = td.file("exit.h5");
  pid_t pid = fork();
  if (pid == 0) {
    StoreOptions opt;
    opt.flush_every_runs = 0;
    opt.flush_every_seconds = 0;
    auto w = make_writer(path, 50, opt);
    for (std::int64_t id = 0; id < 20; ++id) w->write_run(id, test_record(id), test_history(id));
    w->flush();
    for (std::int64_t id = 20; id < 50; ++id) w->write_run(id, test_record(id), test_history(id));
    _exit(0);  // dies with 30 unflushed runs (and HDF5's caches) in memory
  }
  int st = 0;
  waitpid(pid, &st, 0);
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  EXPECT_TRUE(opens_with_plain_hdf5(path));  // before any recovery
  ResultsReader r(path);
  auto d = r.done_mask();
  for (std::int64_t id = 0; id < 50; ++id) EXPECT_EQ(d[static_cast<std::size_t>(id)], id < 20 ? 1 : 0) << id;
  EXPECT_EQ(verify_done_runs(r), 20);
}

TEST(StoreCrash, SigkillAtRandomMomentsThenResume) {
  TempDir td;
  const std::string ref = td.file("ref.h5"), path = td.file("killed.h5");
  const std::int64_t n = 2000;
  {
    pid_t pid = spawn_helper({ref, std::to_string(n), "--no-shuffle", "--landscape"});
    int st = 0;
    waitpid(pid, &st, 0);
    ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  }
  std::mt19937 rng(20261123);
  const int iterations = 30;
  int kills_before_file = 0, kills_pending_commit = 0, kills_mid_epoch = 0, finished_early = 0;
  std::int64_t last_done = 0;
  std::vector<std::int64_t> done_counts;
  for (int it = 0; it < iterations; ++it) {
    if (it % 6 == 0) {  // start over now and then, so that some kills land during creation
      fs::remove(path);
      fs::remove(path + ".journal");
      last_done = 0;
    }
    const int flush_every = std::vector<int>{1, 2, 5, 16}[static_cast<std::size_t>(it % 4)];
    const int delay_us = std::vector<int>{0, 100, 300}[static_cast<std::size_t>(it % 3)];
    pid_t pid = spawn_helper({path, std::to_string(n), "--delay-us", std::to_string(delay_us), "--flush-every",
                              std::to_string(flush_every), "--landscape"});
    const int max_us = it % 6 == 0 ? 6000 : 150000;  // right after a fresh start: aim at the creation
    if (it % 6 != 0)  // otherwise aim at a writer that has its file (wait on its progress, however slow)
      while (!fs::exists(path)) {
        siginfo_t si{};  // (WNOWAIT: an exited writer stays to be reaped below)
        if (waitid(P_PID, static_cast<id_t>(pid), &si, WEXITED | WNOHANG | WNOWAIT) != 0 || si.si_pid != 0) break;
        std::this_thread::yield();
      }
    std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(500, max_us)(rng)));
    kill(pid, SIGKILL);
    int st = 0;
    waitpid(pid, &st, 0);
    if (!WIFSIGNALED(st)) ++finished_early;
    if (!fs::exists(path)) {  // killed while creating: no file, and no garbage at the final name
      ++kills_before_file;
      for (auto& e : fs::directory_iterator(td.dir))
        if (e.path().filename() != "ref.h5") fs::remove(e.path());  // stale temp files of the dead writer
      continue;
    }
    if (fs::exists(path + ".journal")) ++kills_mid_epoch;
    const bool pending = journal_has_commit(path);
    if (pending) {
      ++kills_pending_commit;
    } else {
      EXPECT_TRUE(opens_with_plain_hdf5(path)) << "iteration " << it << ": file does not open before recovery";
    }
    const std::string file_before = slurp(path), journal_before = slurp(path + ".journal");
    std::int64_t done = 0;
    {  // readers change nothing: a commit the writer did not apply is read from the journal
      ResultsReader r(path);
      done = verify_done_runs(r);
    }
    EXPECT_EQ(slurp(path), file_before) << "iteration " << it << ": a reader changed the file";
    EXPECT_EQ(slurp(path + ".journal"), journal_before) << "iteration " << it << ": a reader changed the journal";
    EXPECT_GE(done, last_done) << "iteration " << it << ": committed runs were lost";
    last_done = done;
    done_counts.push_back(done);
  }
  std::cout << "[ kill -9 ] " << iterations << " kills: " << kills_before_file << " before the file existed, "
            << kills_mid_epoch << " with a live journal, " << kills_pending_commit
            << " between journal commit and apply, " << finished_early
            << " finished before the kill; done runs after each kill:";
  for (auto d : done_counts) std::cout << ' ' << d;
  std::cout << std::endl;
  EXPECT_LT(finished_early, iterations / 2);  // the kills really hit running writers
  // finish: resume to the end, then the file equals the uninterrupted one
  pid_t pid = spawn_helper({path, std::to_string(n), "--landscape"});
  int st = 0;
  waitpid(pid, &st, 0);
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  ResultsReader a(ref), b(path);
  EXPECT_EQ(verify_done_runs(b), n);
  EXPECT_EQ(a.done_mask(), b.done_mask());
  for (auto& c : a.columns()) {
    auto x = a.read_column(c.name), y = b.read_column(c.name);
    for (std::size_t i = 0; i < x.size(); ++i) EXPECT_TRUE(same_cell(x[i], y[i])) << c.name << " row " << i;
  }
  for (std::int64_t id = 0; id < n; ++id) expect_same_history(b.read_history(id), a.read_history(id), id);
  EXPECT_EQ(b.landscapes(), a.landscapes());
}

TEST(StoreConcurrent, ReaderFollowsAWriterInAnotherProcess) {
  // The reader reads while the writer commits, as fast as it can; the writer also stops itself
  // after three flushes mid-sweep (--stop-after-runs), and the reader must then get a consistent
  // snapshot at once. The checks depend on the writer's progress only, never on timing.
  TempDir td;
  const std::string path = td.file("live.h5");
  const std::int64_t n = 1200;
  pid_t pid = spawn_helper({path, std::to_string(n), "--delay-us", "200", "--flush-every", "64",
                            "--stop-after-runs", "300,600,900"});
  std::unique_ptr<ResultsReader> r;
  int snapshots = 0, mid = 0, threw = 0, stale = 0, stale_wrong = 0, stops = 0;
  std::int64_t last = 0;
  int st = 0;
  for (;;) {
    const pid_t w = waitpid(pid, &st, WNOHANG | WUNTRACED);
    if (w == pid && !WIFSTOPPED(st)) break;
    const bool stopped = w == pid;  // the writer waits, at a committed state, until SIGCONT
    if (!stopped) std::this_thread::yield();
    std::string msg;
    std::int64_t done = 0;
    try {
      if (!r) {
        if (!fs::exists(path)) continue;
        r = std::make_unique<ResultsReader>(path);
      } else {
        r->refresh();
      }
      msg = check_snapshot(*r, &done, 9);  // histories: every 9th run and the newest ones
    } catch (const StoreError& e) {
      EXPECT_FALSE(stopped) << "a stopped writer's file must read: " << e.what();
      ++threw;  // metadata changed under this reader (HDF5 checksum/EOA checks): refresh and retry
      if (stopped) kill(pid, SIGCONT);
      continue;
    }
    const bool consistent = r->unchanged_since_open();
    if (stopped) {
      EXPECT_TRUE(consistent) << "nothing changes while the writer is stopped";
      ++stops;
      kill(pid, SIGCONT);
    }
    if (!consistent) {  // the writer committed during the reads: not one snapshot
      ++stale;
      if (!msg.empty()) ++stale_wrong;
      continue;
    }
    EXPECT_EQ(msg, "") << "a consistent snapshot with a wrong done run";
    EXPECT_GE(done, last);
    last = done;
    ++snapshots;
    if (done > 0 && done < n) ++mid;
  }
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  std::cout << "[ live reader ] " << snapshots << " consistent snapshots (" << mid << " mid-sweep, " << stops
            << " while the writer was stopped); discarded: " << threw << " threw, " << stale
            << " saw a commit during the reads (" << stale_wrong << " of them had missing/odd newest runs)"
            << std::endl;
  EXPECT_EQ(stops, 3);
  EXPECT_GE(mid, 3);
  ASSERT_TRUE(r);
  r->refresh();
  EXPECT_TRUE(r->unchanged_since_open());
  EXPECT_EQ(verify_done_runs(*r), n);
}

}  // namespace
