// Reading /runs in pieces: ranges and lists of run ids from a reader, rows read back by a writer
// (pending rows included). The oracle is the deterministic generator that wrote the rows.
#include <gtest/gtest.h>

#include <cstring>

#include "store/store.hpp"
#include "store_testgen.hpp"

namespace {
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;

/// Equal rows; doubles compared bit for bit (NaN == NaN).
void expect_same_row(const Record& got, const Record& want, std::int64_t id) {
  ASSERT_EQ(got.cells.size(), want.cells.size()) << "run " << id;
  for (std::size_t c = 0; c < want.cells.size(); ++c) {
    ASSERT_EQ(got.cells[c].index(), want.cells[c].index()) << "run " << id << " column " << c;
    if (const double* w = std::get_if<double>(&want.cells[c])) {
      const double g = std::get<double>(got.cells[c]);
      EXPECT_EQ(0, std::memcmp(&g, w, sizeof g)) << "run " << id << " column " << c;
    } else {
      EXPECT_EQ(got.cells[c], want.cells[c]) << "run " << id << " column " << c;
    }
  }
}

/// The row of a run never written: NaN, -1, "".
Record blank_row() {
  Record r;
  for (const ColumnSpec& c : test_columns()) {
    if (c.type == CellType::f64) r.cells.emplace_back(std::numeric_limits<double>::quiet_NaN());
    if (c.type == CellType::i64) r.cells.emplace_back(std::int64_t{-1});
    if (c.type == CellType::str) r.cells.emplace_back(std::string());
  }
  return r;
}

std::string write_file(const TempDir& td, std::int64_t n, const std::vector<std::int64_t>& ids) {
  const std::string path = td.file("rows.h5");
  auto w = ResultsWriter::create(path, test_meta(), test_columns(), n);
  for (std::int64_t id : ids) w->write_run(id, test_record(id));
  w->close();
  return path;
}

TEST(StoreRows, ReaderRangesEqualTheWrittenRowsAndClampAtTheEnd) {
  TempDir td;
  std::vector<std::int64_t> ids;
  for (std::int64_t id = 0; id < 1000; ++id)
    if (id % 3 != 1) ids.push_back(id);
  const std::string path = write_file(td, 1000, ids);
  ResultsReader r(path);
  for (const auto& [first, count] : std::vector<std::pair<std::int64_t, std::int64_t>>{
           {0, 1000}, {0, 1}, {997, 50}, {300, 257}, {1000, 5}, {0, ResultsReader::kAll}}) {
    const auto rows = r.read_rows(first, count);
    ASSERT_EQ(static_cast<std::int64_t>(rows.size()), std::min<std::int64_t>(count, 1000 - first)) << first;
    const auto done = r.done_mask(first, count);
    const auto alpha = r.read_f64("alpha", first, count);
    const auto iters = r.read_i64("iters", first, count);
    const auto status = r.read_str("status", first, count);
    ASSERT_EQ(done.size(), rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const std::int64_t id = first + static_cast<std::int64_t>(i);
      const Record want = id % 3 != 1 ? test_record(id) : blank_row();
      expect_same_row(rows[i], want, id);
      EXPECT_EQ(done[i], id % 3 != 1 ? 1 : 0);
      const double a = std::get<double>(want.cells[0]);
      EXPECT_EQ(0, std::memcmp(&alpha[i], &a, sizeof a));
      EXPECT_EQ(iters[i], std::get<std::int64_t>(want.cells[2]));
      EXPECT_EQ(status[i], std::get<std::string>(want.cells[3]));
    }
  }
  EXPECT_THROW(r.read_rows(-1, 3), StoreError);
  EXPECT_THROW(r.read_f64("iters", 0, 3), StoreError);  // not an f64 column
}

TEST(StoreRows, ReaderReadsAListOfRunIdsAndRefusesAnUnorderedOne) {
  TempDir td;
  std::vector<std::int64_t> all(200);
  for (std::int64_t id = 0; id < 200; ++id) all[id] = id;
  ResultsReader r(write_file(td, 200, all));
  const std::vector<std::int64_t> ids = {0, 3, 4, 77, 150, 199};
  const auto rows = r.read_rows(ids);
  ASSERT_EQ(rows.size(), ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) expect_same_row(rows[i], test_record(ids[i]), ids[i]);
  EXPECT_TRUE(r.read_rows(std::vector<std::int64_t>{}).empty());
  EXPECT_THROW(r.read_rows(std::vector<std::int64_t>{5, 4}), StoreError);
  EXPECT_THROW(r.read_rows(std::vector<std::int64_t>{3, 3}), StoreError);
  EXPECT_THROW(r.read_rows(std::vector<std::int64_t>{200}), StoreError);
}

TEST(StoreRows, AWriterReadsBackCommittedAndPendingRowsWithoutCommitting) {
  TempDir td;
  const std::string path = td.file("w.h5");
  StoreOptions opt;
  opt.flush_every_runs = 0;
  opt.flush_every_seconds = 0;
  auto w = ResultsWriter::create(path, test_meta(), test_columns(), 40, opt);
  for (std::int64_t id : {2, 9, 31}) w->write_run(id, test_record(id));
  w->flush();
  for (std::int64_t id : {5, 39}) w->write_run(id, test_record(id));  // pending: not committed
  const auto rows = w->read_rows(0, 100);
  ASSERT_EQ(rows.size(), 40u);
  for (std::int64_t id = 0; id < 40; ++id) {
    const bool written = id == 2 || id == 9 || id == 31 || id == 5 || id == 39;
    expect_same_row(rows[id], written ? test_record(id) : blank_row(), id);
  }
  {
    ResultsReader r(path);  // the pending rows are not done until the next flush
    const auto d = r.done_mask();
    EXPECT_EQ(d[5], 0);
    EXPECT_EQ(d[9], 1);
  }
  w->close();
  ResultsReader r(path);
  EXPECT_EQ(r.done_mask()[39], 1);
  expect_same_row(r.read_record(39), test_record(39), 39);
}

}  // namespace
