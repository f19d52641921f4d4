// The HDF5 results store: encoding, round trips, resume, refusal and failure paths (crash safety:
// test_store_crash.cpp, test_store_recovery.cpp).
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
#include "store_checks.hpp"
#include "store_testgen.hpp"

namespace {
namespace fs = std::filesystem;
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;


// ------------------------------------------------------------------------------------------------
// The bytes are what HDF5's filter pipeline stores: zlib(shuffle(chunk)) per chunk of chunk_rows
// rows, the last padded with NaN rows; inflating (zlib's own inflate: an independent decoder) and
// unshuffling (byte j of element i at j * n + i) gives the rows back.
std::vector<double> inflate_chunk(const EncodedChunk& c, std::size_t n) {
  std::vector<double> back(n);
  if (c.filter_mask == kRawChunk) {
    EXPECT_EQ(c.bytes.size(), n * 8);
    std::memcpy(back.data(), c.bytes.data(), std::min(c.bytes.size(), n * 8));
    return back;
  }
  EXPECT_EQ(c.filter_mask, 0u);
  std::vector<unsigned char> shuffled(n * 8 + 16);
  uLongf got = static_cast<uLongf>(shuffled.size());
  EXPECT_EQ(uncompress(shuffled.data(), &got, c.bytes.data(), c.bytes.size()), Z_OK);
  EXPECT_EQ(got, n * 8);
  auto* b = reinterpret_cast<unsigned char*>(back.data());
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < 8; ++j) b[i * 8 + j] = shuffled[j * n + i];
  return back;
}

/// Checks every chunk of `e` against the array `a` it encodes: the rows, then NaN padding.
void expect_chunks_hold(const EncodedArray& e, const HistoryArray& a, std::size_t chunk_rows) {
  ASSERT_EQ(e.rows, a.rows);
  if (a.rows == 0 || a.cols == 0) { EXPECT_TRUE(e.chunks.empty()); return; }
  ASSERT_EQ(e.chunk_rows, chunk_rows);
  ASSERT_EQ(e.chunks.size(), (a.rows + chunk_rows - 1) / chunk_rows);
  for (std::size_t k = 0; k < e.chunks.size(); ++k) {
    const auto back = inflate_chunk(e.chunks[k], chunk_rows * a.cols);
    for (std::size_t i = 0; i < back.size(); ++i) {
      const std::size_t at = k * chunk_rows * a.cols + i;
      if (at < a.data.size()) {
        EXPECT_EQ(0, std::memcmp(&back[i], &a.data[at], 8)) << a.name << " chunk " << k << " value " << i;
      } else {
        EXPECT_TRUE(std::isnan(back[i])) << a.name << " padding " << i;
      }
    }
  }
}

TEST(StoreEncode, DeflateStreamDecodesToTheRawArray) {
  for (std::int64_t id : {0, 3, 6, 13}) {
    auto h = test_history(id);
    for (int level : {0, 1, 6})
      for (std::size_t chunk_rows : {std::size_t{0}, std::size_t{7}, std::size_t{64}, std::size_t{1000}}) {
        auto e = encode_history(h, level, chunk_rows);
        ASSERT_EQ(e.arrays.size(), h.arrays.size());
        for (std::size_t k = 0; k < h.arrays.size(); ++k)
          expect_chunks_hold(e.arrays[k], h.arrays[k], chunk_rows ? chunk_rows : h.arrays[k].rows);
        const RunHistory back = decode_history(e);  // the store's own decoder agrees with zlib's
        ASSERT_EQ(back.arrays.size(), h.arrays.size());
        for (std::size_t k = 0; k < h.arrays.size(); ++k) {
          ASSERT_EQ(back.arrays[k].data.size(), h.arrays[k].data.size());
          if (!h.arrays[k].data.empty()) {  // memcmp of an empty vector's null data is undefined
            EXPECT_EQ(0, std::memcmp(back.arrays[k].data.data(), h.arrays[k].data.data(), 8 * h.arrays[k].data.size()));
          }
        }
      }
  }
  HistoryArray bad{"x", "", 3, 2, {1.0, 2.0}};
  EXPECT_THROW(encode_history(RunHistory{{bad}}), StoreError);
  HistoryArray a{"a", "", 3, 1, {1.0, 2.0, 3.0}}, b{"b", "", 2, 1, {1.0, 2.0}};
  EXPECT_THROW(encode_history(RunHistory{{a, b}}), StoreError);  // a run's arrays share their rows
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
      expect_chunks_hold(encode_history(RunHistory{{a}}, level).arrays[0], a, rows);
      expect_chunks_hold(encode_history(RunHistory{{a}}, level, 3641).arrays[0], a, 3641);
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
        for (std::size_t k = 0; k < e.arrays.size(); ++k)
          for (std::size_t c = 0; c < e.arrays[k].chunks.size(); ++c)
            ok[t] += e.arrays[k].chunks[c].bytes == again.arrays[k].chunks[c].bytes ? 0 : 1;
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
    for (std::int64_t id = 0; id < n; ++id) EXPECT_EQ(res.writer->is_done(id), id % 3 == 0) << id;
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

/// A landscape of `n` cells over one axis with 64 metrics: 512 bytes of cells per run.
LandscapeSpec wide_landscape(std::int64_t n) {
  LandscapeSpec spec;
  spec.block = "b";
  spec.axes.push_back({"i", "", {}});
  for (std::int64_t i = 0; i < n; ++i) spec.axes[0].values.push_back(static_cast<double>(i));
  for (int m = 0; m < 64; ++m) spec.metrics.push_back({"m" + std::to_string(m), "", "", {}});
  return spec;
}

StoreOptions no_automatic_flush() {
  StoreOptions opt;
  opt.flush_every_runs = 0;
  opt.flush_every_seconds = 0;
  return opt;
}

// Rows and landscape cells written since the last commit are held in memory (the journal's pages)
// until the commit, so the writer commits once they reach a few MiB even when neither
// flush_every_runs nor flush_every_seconds asks for a commit.
TEST(Store, CommitsOnceTheUncommittedRowsReachAFewMiB) {
  TempDir td;
  const std::string path = td.file("bound.h5");
  const std::int64_t n = 20000;
  const LandscapeSpec spec = wide_landscape(n);
  std::vector<double> cell(64);
  auto w = make_writer(path, n, no_automatic_flush());
  const std::size_t grid = w->begin_landscape(spec);
  for (std::int64_t id = 0; id < n; ++id) {
    w->write_run(id, test_record(id));
    for (int m = 0; m < 64; ++m) cell[static_cast<std::size_t>(m)] = static_cast<double>(id * 64 + m);
    w->write_landscape_cell(grid, static_cast<std::uint64_t>(id), cell.data());
    if (id == 0) {
      // Until a commit, the new grid lies past the committed size, where writes go straight to the
      // file: its cells hold no journal memory and do not count. Committed, it counts.
      EXPECT_EQ(w->pending(), 1u);
      w->flush();
    }
  }
  EXPECT_LT(w->pending(), static_cast<std::size_t>(n) / 2);  // 4 MiB: about 7400 runs of 569 bytes
  {
    ResultsReader r(path);  // the writer is still open: what the automatic commits committed
    const auto d = r.done_mask();
    EXPECT_EQ(std::count(d.begin(), d.end(), 1), n - static_cast<std::int64_t>(w->pending()));
  }
  w->close();
  ResultsReader r(path);
  const auto d = r.done_mask();
  EXPECT_EQ(std::count(d.begin(), d.end(), 1), n);
  const LandscapeSpec got = r.read_landscape("b");
  ASSERT_EQ(got.metrics.size(), 64u);
  for (int m : {0, 63})
    for (std::int64_t id : {std::int64_t{0}, std::int64_t{7777}, n - 1})
      EXPECT_EQ(got.metrics[static_cast<std::size_t>(m)].grid[static_cast<std::size_t>(id)],
                static_cast<double>(id * 64 + m));
}

// A grid created since the last commit lies past the committed size (written straight to the file,
// not held by the journal): filling it, 10 MB here, forces no commit; after close it reads back.
TEST(Store, ANewGridIsFilledWithoutCommits) {
  TempDir td;
  const std::string path = td.file("fresh.h5");
  const std::int64_t n = 20000;
  const LandscapeSpec spec = wide_landscape(n);
  auto w = make_writer(path, n, no_automatic_flush());
  const std::size_t grid = w->begin_landscape(spec);
  w->write_run(0, test_record(0));
  std::vector<double> cell(64);
  for (std::int64_t id = 0; id < n; ++id) {
    for (int m = 0; m < 64; ++m) cell[static_cast<std::size_t>(m)] = static_cast<double>(id * 64 + m);
    w->write_landscape_cell(grid, static_cast<std::uint64_t>(id), cell.data());
  }
  EXPECT_EQ(w->pending(), 1u);  // no commit: the run is still pending
  w->close();
  ResultsReader r(path);
  const LandscapeSpec got = r.read_landscape("b");
  for (std::int64_t id : {std::int64_t{0}, std::int64_t{12345}, n - 1})
    EXPECT_EQ(got.metrics[63].grid[static_cast<std::size_t>(id)], static_cast<double>(id * 64 + 63));
}

// The writer's done flags (one bit per run) against the runs written, at the edges of 64-run words
// and of the 65536-run pieces in which a resume reads /runs/done, before and after a resume.
TEST(Store, IsDoneMatchesTheWrittenRunsAtWordAndPieceEdges) {
  TempDir td;
  const std::string path = td.file("bits.h5");
  const std::int64_t n = 65536 + 130;  // two resume pieces, the last word partly used
  std::vector<bool> want(static_cast<std::size_t>(n), false);
  std::vector<std::int64_t> ids = {0, 62, 63, 64, 127, 128, 65535, 65536, 65537, n - 1};
  for (std::int64_t id = 5; id < n; id += 97) ids.push_back(id);
  auto expect_flags = [&](const ResultsWriter& w, const char* when) {
    EXPECT_FALSE(w.is_done(-1)) << when;
    EXPECT_FALSE(w.is_done(n)) << when;
    std::int64_t wrong = 0, first_wrong = -1;
    for (std::int64_t id = 0; id < n; ++id)
      if (w.is_done(id) != want[static_cast<std::size_t>(id)] && wrong++ == 0) first_wrong = id;
    EXPECT_EQ(wrong, 0) << when << ": first wrong run " << first_wrong;
  };
  StoreOptions opt;
  opt.flush_every_runs = 500;  // commits while writing, as a sweep does
  {
    auto w = ResultsWriter::create(path, test_meta(), test_columns(), n, opt);
    expect_flags(*w, "new file");
    for (std::int64_t id : ids) {
      w->write_run(id, test_record(id));
      want[static_cast<std::size_t>(id)] = true;
    }
    w->write_run(64, test_record(64));  // written again: still done, its neighbours untouched
    expect_flags(*w, "after write_run");
    w->close();
  }
  {
    auto res = ResultsWriter::open_for_resume(path, test_meta().study_sha256, opt);
    ASSERT_EQ(res.writer->n_runs(), n);
    expect_flags(*res.writer, "after resume");
    for (std::int64_t id : {std::int64_t{1}, std::int64_t{65}, std::int64_t{65534}, n - 2}) {
      res.writer->write_run(id, test_record(id));
      want[static_cast<std::size_t>(id)] = true;
    }
    expect_flags(*res.writer, "after resume and write_run");
    res.writer->close();
  }
  ResultsReader r(path);
  const auto mask = r.done_mask();
  ASSERT_EQ(static_cast<std::int64_t>(mask.size()), n);
  for (std::int64_t id = 0; id < n; ++id)
    ASSERT_EQ(mask[static_cast<std::size_t>(id)] != 0, want[static_cast<std::size_t>(id)]) << "run " << id;
  // a file of no runs
  const std::string empty = td.file("empty.h5");
  ResultsWriter::create(empty, test_meta(), test_columns(), 0)->close();
  auto res = ResultsWriter::open_for_resume(empty, test_meta().study_sha256);
  EXPECT_EQ(res.writer->n_runs(), 0);
  EXPECT_FALSE(res.writer->is_done(0));
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

}  // namespace
