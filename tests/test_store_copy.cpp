// ResultsWriter::copy_runs (the merge of a distributed sweep's shards): rows and histories copied
// from several source files equal the same runs written directly; a chunk one source holds whole is
// copied byte for byte (HDF5's own chunk reads as the oracle); layouts that do not match are
// refused with nothing copied. Landscape cells copied from their owner's grid (kept where no source
// owns them; a source without the landscape refused). And the typed column reads (read_numbers, read_codes) against the
// rows' own values.
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

bool has_run_history(std::int64_t id) { return id % 5000 == 7; }

/// The stored bytes of the chunk holding row `row` of /runs/<name> (HDF5's direct chunk read).
std::vector<unsigned char> stored_chunk(const std::string& path, const std::string& name, hsize_t row) {
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t d = H5Dopen2(f, ("runs/" + name).c_str(), H5P_DEFAULT);
  hsize_t offset = row - row % kRunsChunkRows, bytes = 0;
  std::uint32_t mask = 0;
  std::vector<unsigned char> out;
  if (H5Dget_chunk_storage_size(d, &offset, &bytes) >= 0) {
    out.resize(bytes);
    EXPECT_GE(H5Dread_chunk(d, H5P_DEFAULT, &offset, &mask, out.data()), 0);
  }
  H5Dclose(d);
  H5Fclose(f);
  return out;
}

TEST(StoreCopy, RunsCopiedFromSourcesEqualTheRunsWrittenDirectly) {
  TempDir td;
  const auto C = static_cast<std::int64_t>(kRunsChunkRows);
  const std::int64_t n = 3 * C + 500;  // chunks 0, 1, 2 whole, chunk 3 partial
  // Source 0: chunk 0 whole and the odd rows of chunk 1; source 1: the even rows of chunk 1, chunk
  // 2 but for its first 10 rows (which the destination holds already) and chunk 3.
  std::vector<std::int32_t> owner(static_cast<std::size_t>(n), -1);
  for (std::int64_t id = 0; id < n; ++id) {
    if (id < C) owner[id] = 0;
    else if (id < 2 * C) owner[id] = id % 2 ? 0 : 1;
    else if (id >= 2 * C + 10) owner[id] = 1;
  }
  const std::string src0 = td.file("src0.h5"), src1 = td.file("src1.h5"), dst = td.file("dst.h5"),
                    direct = td.file("direct.h5");
  for (int s = 0; s < 2; ++s) {
    auto w = ResultsWriter::create(s ? src1 : src0, test_meta(), copy_columns(), n);
    for (std::int64_t id = 0; id < n; ++id)
      if (owner[id] == s)
        w->write_run(id, copy_record(id), has_run_history(id) ? encode_history(test_history(id), 1) : EncodedHistory{});
    w->close();
  }
  {
    auto w = ResultsWriter::create(direct, test_meta(), copy_columns(), n);
    for (std::int64_t id = 0; id < n; ++id)
      w->write_run(id, copy_record(id), has_run_history(id) ? encode_history(test_history(id), 1) : EncodedHistory{});
    w->close();
  }
  {
    auto w = ResultsWriter::create(dst, test_meta(), copy_columns(), n);
    for (std::int64_t id = 2 * C; id < 2 * C + 10; ++id) w->write_run(id, copy_record(id));
    w->flush();
    ResultsReader r0(src0), r1(src1);
    ASSERT_TRUE(w->copy_runs({&r0, &r1}, owner));
    for (std::int64_t id = 0; id < n; ++id) EXPECT_TRUE(w->is_done(id)) << id;
    // the typed reads see the copied rows before any commit
    const std::vector<double> x = w->read_numbers("x", C - 3, 6);
    const std::vector<double> nn = w->read_numbers("n", C - 3, 6);
    const std::vector<std::uint16_t> codes = w->read_codes("word", C - 3, 6);
    ASSERT_EQ(x.size(), 6u);
    for (std::int64_t i = 0; i < 6; ++i) {
      const Record want = copy_record(C - 3 + i);
      EXPECT_EQ(x[i], std::get<double>(want.cells[0]));
      EXPECT_EQ(nn[i], static_cast<double>(std::get<std::int64_t>(want.cells[1])));
      const std::string& word = std::get<std::string>(want.cells[2]);
      EXPECT_EQ(codes[i] < 3 ? copy_columns()[2].labels[codes[i]] : std::string(), word);
    }
    EXPECT_THROW(w->read_codes("x", 0, 1), StoreError);
    w->close();
  }
  ResultsReader got(dst), want(direct);
  const auto done = got.done_mask();
  for (std::int64_t id = 0; id < n; ++id) ASSERT_EQ(done[id], 1) << id;
  const auto a = got.read_rows(0, n), b = want.read_rows(0, n);
  for (std::int64_t id = 0; id < n; ++id) ASSERT_EQ(a[id].cells, b[id].cells) << "run " << id;
  for (std::int64_t id = 0; id < n; ++id) {
    ASSERT_EQ(got.has_history(id), owner[id] >= 0 && has_run_history(id)) << id;
    if (!got.has_history(id)) continue;
    const RunHistory h = got.read_history(id), w = want.read_history(id);
    ASSERT_EQ(h.arrays.size(), w.arrays.size());
    for (std::size_t k = 0; k < h.arrays.size(); ++k) {  // bitwise (the test histories hold NaN)
      ASSERT_EQ(h.arrays[k].data.size(), w.arrays[k].data.size());
      EXPECT_EQ(std::memcmp(h.arrays[k].data.data(), w.arrays[k].data.data(), 8 * h.arrays[k].data.size()), 0) << id;
    }
  }
  // chunk 0, held whole by source 0, is its stored bytes; every chunk is what a direct write stores
  for (const char* col : {"x", "n", "word"}) {
    EXPECT_EQ(stored_chunk(dst, col, 0), stored_chunk(src0, col, 0)) << col;
    for (hsize_t row = 0; row < static_cast<hsize_t>(n); row += kRunsChunkRows)
      EXPECT_EQ(stored_chunk(dst, col, row), stored_chunk(direct, col, row)) << col << " chunk at " << row;
  }
}

TEST(StoreCopy, SourcesOfAnotherLayoutAreRefusedWithNothingCopied) {
  TempDir td;
  const std::int64_t n = 100;
  std::vector<ColumnSpec> other = copy_columns();
  other[2].labels = {"alpha", "beta"};  // other labels: other codes
  {
    auto w = ResultsWriter::create(td.file("other.h5"), test_meta(), other, n);
    for (std::int64_t id = 0; id < n; ++id) w->write_run(id, copy_record(id % 2 ? 1 : 0));
    w->close();
  }
  auto w = ResultsWriter::create(td.file("dst.h5"), test_meta(), copy_columns(), n);
  ResultsReader r(td.file("other.h5"));
  EXPECT_FALSE(w->copy_runs({&r}, std::vector<std::int32_t>(n, 0)));
  for (std::int64_t id = 0; id < n; ++id) EXPECT_FALSE(w->is_done(id));
  w->close();
}

/// A landscape of block "b" over a 3 x 7 x 2500 grid (more cells than one piece of copy_landscape)
/// with metrics "u" and "v": cell c of metric m holds value(c, m, source).
LandscapeSpec copy_grid() {
  LandscapeSpec spec;
  spec.block = "b";
  const std::size_t dims[3] = {3, 7, 2500};
  for (int a = 0; a < 3; ++a) {
    LandscapeAxis ax{std::string(1, static_cast<char>('p' + a)), "1", {}};
    for (std::size_t i = 0; i < dims[a]; ++i) ax.values.push_back(static_cast<double>(i));
    spec.axes.push_back(ax);
  }
  spec.metrics = {{"u", "m", "first", {}}, {"v", "s", "second", {}}, {"w", "", "codes", {}, "w", {"p", "q", "r"}}};
  return spec;
}
/// Metric 2 is a grid of codes 0..2, NaN (none) in every fourth cell.
double grid_value(std::size_t c, std::size_t m, int source) {
  if (m == 2) return (c + static_cast<std::size_t>(source)) % 4 == 3 ? std::nan("") : static_cast<double>((c + static_cast<std::size_t>(source)) % 4);
  return 1000.0 * source + 0.5 * m + 1e-3 * static_cast<double>(c);
}

TEST(StoreCopy, LandscapeCellsCopiedFromTheirOwnersGrid) {
  TempDir td;
  const std::int64_t n = 10;
  const LandscapeSpec spec = copy_grid();
  const std::size_t cells = 3 * 7 * 2500;
  // owners: runs of several lengths (some longer than a piece), unowned cells among them
  std::vector<std::int32_t> owner(cells);
  for (std::size_t c = 0; c < cells; ++c) owner[c] = c < 70000 ? static_cast<std::int32_t>((c / 9973) % 3) - 1 : 1;
  for (int s = 0; s < 2; ++s) {
    auto w = ResultsWriter::create(td.file("src" + std::to_string(s) + ".h5"), test_meta(), copy_columns(), n);
    const std::size_t h = w->begin_landscape(spec);
    for (std::size_t c = 0; c < cells; ++c)
      if (owner[c] == s) {
        const double v[3] = {grid_value(c, 0, s), grid_value(c, 1, s), grid_value(c, 2, s)};
        w->write_landscape_cell(h, c, v);
      }
    w->close();
  }
  auto w = ResultsWriter::create(td.file("dst.h5"), test_meta(), copy_columns(), n);
  const std::size_t h = w->begin_landscape(spec);
  const double mine[3] = {-1.0, -2.0, 2.0};
  for (std::size_t c = 0; c < cells; ++c)
    if (owner[c] < 0) w->write_landscape_cell(h, c, mine);
  ResultsReader r0(td.file("src0.h5")), r1(td.file("src1.h5"));
  ASSERT_TRUE(w->copy_landscape(h, {&r0, &r1}, owner.data()));
  w->close();
  const LandscapeSpec got = ResultsReader(td.file("dst.h5")).read_landscape("b");
  ASSERT_EQ(got.metrics.size(), 3u);
  for (std::size_t m = 0; m < 3; ++m) {
    ASSERT_EQ(got.metrics[m].grid.size(), cells);
    for (std::size_t c = 0; c < cells; ++c) {
      const double want = owner[c] < 0 ? mine[m] : grid_value(c, m, owner[c]);
      ASSERT_TRUE(got.metrics[m].grid[c] == want || (std::isnan(want) && std::isnan(got.metrics[m].grid[c])))
          << "metric " << m << " cell " << c << ": " << got.metrics[m].grid[c] << ", want " << want;
    }
  }
  // a source without this landscape: refused, nothing written
  auto w2 = ResultsWriter::create(td.file("dst2.h5"), test_meta(), copy_columns(), n);
  const std::size_t h2 = w2->begin_landscape(spec);
  auto w3 = ResultsWriter::create(td.file("bare.h5"), test_meta(), copy_columns(), n);
  w3->close();
  ResultsReader bare(td.file("bare.h5"));
  EXPECT_FALSE(w2->copy_landscape(h2, {&r0, &bare}, owner.data()));
  w2->close();
  const LandscapeSpec untouched = ResultsReader(td.file("dst2.h5")).read_landscape("b");
  for (double x : untouched.metrics[0].grid) ASSERT_TRUE(std::isnan(x)) << x;
}

}  // namespace
