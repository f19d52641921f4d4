// Column scans of /runs decode the stored chunks themselves (store/runs_read.cpp: libdeflate, not
// HDF5's filter pipeline): every value equals HDF5's own read of the same dataset (the oracle), for
// chunks compressed whole, chunks committed incomplete (stored deflate blocks) and chunks never
// written (the fill value). Dense landscapes (every cell written before the next commit) are
// copied from their owners by file offset and equal the owners' cells; a commit with cells of a
// dense landscape unwritten fails and leaves the last commit as it was.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "store/store.hpp"
#include "store_testgen.hpp"

namespace {
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;

/// /runs/<name> read whole by HDF5 (its filter pipeline), as `mtype`, elements of `size` bytes.
std::vector<unsigned char> hdf5_read(const std::string& path, const std::string& name, hid_t mtype, std::size_t size,
                                     hsize_t n) {
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t d = H5Dopen2(f, ("runs/" + name).c_str(), H5P_DEFAULT);
  std::vector<unsigned char> out(n * size);
  EXPECT_GE(H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0);
  H5Dclose(d);
  H5Fclose(f);
  return out;
}

TEST(StoreScan, ColumnReadsEqualHdf5sOwnReadOfEveryKindOfChunk) {
  TempDir td;
  const std::int64_t C = static_cast<std::int64_t>(kRunsChunkRows), n = 5 * C + 123;
  const std::string path = td.file("scan.h5");
  {
    auto w = ResultsWriter::create(path, test_meta(), copy_columns(), n);
    // chunks 0 and 1 whole (compressed), chunk 2 half (committed stored), chunk 4 a few rows, the
    // rest never written
    for (std::int64_t id = 0; id < 2 * C + C / 2; ++id) w->write_run(id, copy_record(id));
    w->flush();
    for (std::int64_t id = 4 * C + 5; id < 4 * C + 40; ++id) w->write_run(id, copy_record(id));
    w->close();
  }
  const ResultsReader r(path);
  for (const auto& [first, count] : std::vector<std::pair<std::int64_t, std::int64_t>>{{0, n}, {C - 7, 2 * C + 20}, {4 * C + 1, 50}, {n - 3, 3}}) {
    const std::vector<Record> rows = r.read_rows(first, count);
    const auto x = hdf5_read(path, "x", H5T_NATIVE_DOUBLE, 8, static_cast<hsize_t>(n));
    const auto k = hdf5_read(path, "n", H5T_NATIVE_INT64, 8, static_cast<hsize_t>(n));
    ASSERT_EQ(rows.size(), static_cast<std::size_t>(count));
    for (std::int64_t i = 0; i < count; ++i) {
      const std::size_t at = static_cast<std::size_t>(first + i) * 8;
      double want_x;
      std::int64_t want_n;
      std::memcpy(&want_x, x.data() + at, 8);
      std::memcpy(&want_n, k.data() + at, 8);
      const double got_x = std::get<double>(rows[i].cells[0]);
      ASSERT_TRUE(got_x == want_x || (std::isnan(got_x) && std::isnan(want_x))) << "row " << first + i;
      ASSERT_EQ(std::get<std::int64_t>(rows[i].cells[1]), want_n) << "row " << first + i;
    }
  }
  // and the values are the runs' own where they were written
  const std::vector<Record> rows = r.read_rows(0, n);
  for (std::int64_t id : {std::int64_t{0}, C + 17, 2 * C + C / 2 - 1, 4 * C + 39})
    EXPECT_EQ(rows[static_cast<std::size_t>(id)].cells, copy_record(id).cells) << id;
}

/// A 40 x 3000 grid with metrics "u" and "v".
LandscapeSpec dense_grid(bool dense) {
  LandscapeSpec spec;
  spec.block = "b";
  for (int a = 0; a < 2; ++a) {
    LandscapeAxis ax{a ? "q" : "p", "1", {}};
    for (int i = 0; i < (a ? 3000 : 40); ++i) ax.values.push_back(i);
    spec.axes.push_back(ax);
  }
  spec.metrics = {{"u", "m", "first", {}}, {"v", "s", "second", {}}};
  spec.dense = dense;
  return spec;
}

TEST(StoreScan, DenseLandscapeCopiedFromItsOwnersByOffset) {
  TempDir td;
  const std::size_t cells = 40 * 3000;
  std::vector<std::int32_t> owner(cells);
  for (std::size_t c = 0; c < cells; ++c) owner[c] = static_cast<std::int32_t>((c / 70001 + c / 999) % 2);
  auto value = [](std::size_t c, std::size_t m, int s) { return 10.0 * s + m + 1e-4 * static_cast<double>(c); };
  for (int s = 0; s < 2; ++s) {
    auto w = ResultsWriter::create(td.file("src" + std::to_string(s) + ".h5"), test_meta(), copy_columns(), 4);
    const std::size_t h = w->begin_landscape(dense_grid(false));
    for (std::size_t c = 0; c < cells; ++c)
      if (owner[c] == s) {
        const double v[2] = {value(c, 0, s), value(c, 1, s)};
        w->write_landscape_cell(h, c, v);
      }
    w->close();
  }
  auto w = ResultsWriter::create(td.file("dst.h5"), test_meta(), copy_columns(), 4);
  const std::size_t h = w->begin_landscape(dense_grid(true));
  ResultsReader r0(td.file("src0.h5")), r1(td.file("src1.h5"));
  ASSERT_TRUE(w->copy_landscape(h, {&r0, &r1}, owner.data()));
  w->close();
  const LandscapeSpec got = ResultsReader(td.file("dst.h5")).read_landscape("b");
  for (std::size_t m = 0; m < 2; ++m)
    for (std::size_t c = 0; c < cells; ++c)
      ASSERT_EQ(got.metrics[m].grid[c], value(c, m, owner[c])) << "metric " << m << " cell " << c;
}

TEST(StoreScan, ACommitWithCellsOfADenseLandscapeUnwrittenFails) {
  TempDir td;
  const std::string path = td.file("dense.h5");
  auto w = ResultsWriter::create(path, test_meta(), copy_columns(), 4);
  w->write_run(0, copy_record(0));
  w->flush();
  const std::size_t h = w->begin_landscape(dense_grid(true));
  const double v[2] = {1.0, 2.0};
  w->write_landscape_cell(h, 5, v);
  EXPECT_THROW(w->flush(), StoreError);
  w.reset();
  // the last commit holds the run and no landscape
  const ResultsReader r(path);
  EXPECT_EQ(r.done_mask(0, 1), std::vector<std::uint8_t>{1});
  EXPECT_TRUE(r.landscapes().empty());
}

}  // namespace
