// Landscapes streamed cell by cell (begin_landscape, write_landscape_cell): what a reader sees
// before and after each commit, cells in any order and rewritten, grids of one to four dimensions
// whose sizes do not divide the chunk. The oracle is a plain array filled with the same writes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>

#include "store/store.hpp"
#include "store_testgen.hpp"

namespace {
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;

LandscapeSpec spec_of(const std::vector<std::size_t>& shape) {
  LandscapeSpec s;
  s.block = "B";
  for (std::size_t d = 0; d < shape.size(); ++d) {
    LandscapeAxis a{"x" + std::to_string(d), "m", {}};
    for (std::size_t i = 0; i < shape[d]; ++i) a.values.push_back(0.5 * static_cast<double>(i) - 1.0);
    s.axes.push_back(a);
  }
  s.metrics = {{"E", "Nm", "energy", {}}, {"ok", "", "1 where ok", {}}};
  return s;
}

/// Bitwise equal grids (NaN == NaN).
void expect_grid(const LandscapeSpec& got, const std::vector<std::vector<double>>& want, const std::string& what) {
  ASSERT_EQ(got.metrics.size(), want.size()) << what;
  for (std::size_t m = 0; m < want.size(); ++m) {
    ASSERT_EQ(got.metrics[m].grid.size(), want[m].size()) << what;
    for (std::size_t c = 0; c < want[m].size(); ++c)
      ASSERT_EQ(0, std::memcmp(&got.metrics[m].grid[c], &want[m][c], sizeof(double)))
          << what << ": metric " << m << " cell " << c << " = " << got.metrics[m].grid[c] << ", want " << want[m][c];
  }
}

TEST(StoreLandscapes, CellsInAnyOrderReadBackAtTheirPlacesAndUnwrittenCellsAreNaN) {
  std::mt19937_64 rng(11);
  for (const std::vector<std::size_t>& shape : std::vector<std::vector<std::size_t>>{
           {}, {1}, {37}, {3, 5}, {241, 21}, {2, 7, 13}, {3, 4, 5, 6}, {1, 1, 9000}}) {
    TempDir td;
    const std::string path = td.file("l.h5");
    const LandscapeSpec spec = spec_of(shape);
    const std::size_t cells = std::accumulate(shape.begin(), shape.end(), std::size_t{1}, std::multiplies<>());
    std::vector<std::vector<double>> want(2, std::vector<double>(cells, std::nan("")));
    auto w = ResultsWriter::create(path, test_meta(), test_columns(), 4);
    const std::size_t h = w->begin_landscape(spec);
    // runs of consecutive cells, single cells, cells twice (the last values stay), in a shuffled order
    std::vector<std::uint64_t> order(cells);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    order.resize(cells * 2 / 3);
    std::sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(order.size() / 2));
    for (std::size_t i = 0; i < order.size(); ++i) {
      const std::uint64_t c = order[i];
      const double v[2] = {static_cast<double>(c) + 0.25 * static_cast<double>(i % 3), static_cast<double>(i % 2)};
      w->write_landscape_cell(h, c, v);
      want[0][c] = v[0], want[1][c] = v[1];
      if (i % 5 == 0) {  // again, later values
        const double again[2] = {-v[0], 7.0};
        w->write_landscape_cell(h, c, again);
        want[0][c] = again[0], want[1][c] = again[1];
      }
      if (i == order.size() / 3) w->flush();
    }
    w->close();
    ResultsReader r(path);
    const LandscapeSpec got = r.read_landscape("B");
    ASSERT_EQ(got.axes.size(), shape.size());
    for (std::size_t d = 0; d < shape.size(); ++d) EXPECT_EQ(got.axes[d].values, spec.axes[d].values);
    expect_grid(got, want, "shape of " + std::to_string(shape.size()) + " dimensions, " + std::to_string(cells) + " cells");
  }
}

TEST(StoreLandscapes, AGridOfMillionsOfCellsStreamsInBatchesWithCommits) {
  // 3e6 cells in batches of 512 with a commit every 64 batches: a chunked layout of this file's
  // two-entry chunk B-tree nodes failed here ("unable to encode node level": over 255 levels)
  TempDir td;
  const std::string path = td.file("l.h5");
  LandscapeSpec spec = spec_of({3000, 1000});
  spec.metrics.resize(1);
  auto w = ResultsWriter::create(path, test_meta(), test_columns(), 4);
  const std::size_t h = w->begin_landscape(spec);
  for (std::uint64_t c = 0; c < 3000000; ++c) {
    const double v = static_cast<double>(c % 7919);
    w->write_landscape_cell(h, c, &v);
    if (c % (512 * 64) == 0) w->flush();
  }
  w->close();
  ResultsReader r(path);
  const LandscapeSpec got = r.read_landscape("B");
  ASSERT_EQ(got.metrics.at(0).grid.size(), 3000000u);
  for (std::uint64_t c = 0; c < 3000000; c += 997) ASSERT_EQ(got.metrics[0].grid[c], static_cast<double>(c % 7919)) << c;
}

TEST(StoreLandscapes, AReaderSeesTheCellsOfCommittedRunsOnly) {
  TempDir td;
  const std::string path = td.file("l.h5");
  const LandscapeSpec spec = spec_of({4, 3});
  auto w = ResultsWriter::create(path, test_meta(), test_columns(), 12);
  const std::size_t h = w->begin_landscape(spec);
  w->flush();
  std::vector<std::vector<double>> want(2, std::vector<double>(12, std::nan("")));
  {
    ResultsReader r(path);  // the landscape exists before any cell
    expect_grid(r.read_landscape("B"), want, "begun");
  }
  for (std::uint64_t c = 0; c < 5; ++c) {
    const double v[2] = {c * 1.5, 1.0};
    w->write_landscape_cell(h, c, v);
    if (c < 3) want[0][c] = v[0], want[1][c] = v[1];
    if (c == 2) w->flush();
  }
  {
    ResultsReader r(path);  // cells 3 and 4 are not committed
    expect_grid(r.read_landscape("B"), want, "after the first commit");
  }
  w->flush();
  want[0][3] = 4.5, want[0][4] = 6.0, want[1][3] = want[1][4] = 1.0;
  ResultsReader r(path);
  expect_grid(r.read_landscape("B"), want, "after the second commit");
}

TEST(StoreLandscapes, BeginningALandscapeAgainStartsItAfresh) {
  TempDir td;
  const std::string path = td.file("l.h5");
  auto w = ResultsWriter::create(path, test_meta(), test_columns(), 4);
  const double v[2] = {1.0, 1.0};
  const std::size_t first = w->begin_landscape(spec_of({3}));
  w->write_landscape_cell(first, 0, v);
  const std::size_t again = w->begin_landscape(spec_of({3}));
  EXPECT_THROW(w->write_landscape_cell(first, 1, v), StoreError);  // the old handle is gone
  EXPECT_THROW(w->write_landscape_cell(again, 3, v), StoreError);  // past the grid
  w->write_landscape_cell(again, 2, v);
  w->close();
  ResultsReader r(path);
  const double nan = std::nan("");
  expect_grid(r.read_landscape("B"), {{nan, nan, 1.0}, {nan, nan, 1.0}}, "begun twice");
}

// A resumed writer keeps a landscape already in the file when it is begun with the same grid (its
// cells are those of committed rows), and starts afresh one begun with another grid.
TEST(StoreLandscapes, AResumedWriterKeepsTheSameGridAndReplacesAnother) {
  TempDir td;
  const std::string path = td.file("l.h5");
  const double nan = std::nan("");
  {
    auto w = ResultsWriter::create(path, test_meta(), test_columns(), 4);
    const double v[2] = {1.5, 1.0};
    w->write_landscape_cell(w->begin_landscape(spec_of({2, 3})), 1, v);
    w->close();
  }
  {
    auto w = std::move(ResultsWriter::open_for_resume(path, test_meta().study_sha256).writer);
    const std::size_t h = w->begin_landscape(spec_of({2, 3}));
    const double v[2] = {2.5, 0.0};
    w->write_landscape_cell(h, 4, v);
    w->close();
  }
  expect_grid(ResultsReader(path).read_landscape("B"), {{nan, 1.5, nan, nan, 2.5, nan}, {nan, 1.0, nan, nan, 0.0, nan}},
              "kept");
  for (int other = 0; other < 4; ++other) {
    LandscapeSpec spec = spec_of({2, 3});
    if (other == 0) spec.axes[1].values[2] = 9.0;  // another axis value
    if (other == 1) spec.axes[0].unit = "rad";
    if (other == 2) spec.metrics[1].description = "1 where converged";
    if (other == 3) spec = spec_of({3, 2});
    auto w = std::move(ResultsWriter::open_for_resume(path, test_meta().study_sha256).writer);
    const std::size_t h = w->begin_landscape(spec);
    const double v[2] = {-1.0, -2.0};
    w->write_landscape_cell(h, 0, v);
    w->close();
    const LandscapeSpec got = ResultsReader(path).read_landscape("B");
    expect_grid(got, {{-1.0, nan, nan, nan, nan, nan}, {-2.0, nan, nan, nan, nan, nan}}, "replaced " + std::to_string(other));
    EXPECT_EQ(got.axes[0].values, spec.axes[0].values);
    EXPECT_EQ(got.metrics[1].description, spec.metrics[1].description);
  }
}

// Cells written again into a kept landscape lie in the committed part of the file, where the journal
// holds their pages in memory until the commit: the writer commits once a few MiB of them wait, even
// without any run written.
TEST(StoreLandscapes, CellsWrittenAgainIntoAKeptLandscapeAreCommittedEveryFewMiB) {
  TempDir td;
  const std::string path = td.file("l.h5");
  LandscapeSpec spec = spec_of({2000, 1000});  // 2 metrics: 32 MB of cells
  StoreOptions opt;
  opt.flush_every_runs = 0;
  opt.flush_every_seconds = 0;
  {
    auto w = ResultsWriter::create(path, test_meta(), test_columns(), 4, opt);
    const std::size_t h = w->begin_landscape(spec);
    const double v[2] = {1.0, 1.0};
    for (std::uint64_t c = 0; c < 2000000; ++c) w->write_landscape_cell(h, c, v);
    w->close();
  }
  auto w = std::move(ResultsWriter::open_for_resume(path, test_meta().study_sha256, opt).writer);
  const std::size_t h = w->begin_landscape(spec);
  const double v[2] = {2.0, 2.0};
  for (std::uint64_t c = 0; c < 2000000; ++c) w->write_landscape_cell(h, c, v);
  {
    ResultsReader r(path);  // the writer is still open: what its automatic commits committed
    const LandscapeSpec got = r.read_landscape("B");
    EXPECT_EQ(got.metrics[0].grid[0], 2.0);
    EXPECT_EQ(got.metrics[1].grid[1000000], 2.0);
  }
  w->close();
  const LandscapeSpec got = ResultsReader(path).read_landscape("B");
  EXPECT_EQ(std::count(got.metrics[0].grid.begin(), got.metrics[0].grid.end(), 2.0), 2000000);
}

}  // namespace

namespace {
/// A block of 5 sampled points (parameters a, drawn out of order, and b, a string parameter) by 2
/// values of k, with the metric E and a grid of status codes.
LandscapeSpec sampled_spec() {
  LandscapeSpec s;
  s.block = "S";
  LandscapeAxis sample{"sample", "", {0, 1, 2, 3, 4}};
  sample.coordinates = {{"a", "rad", {0.3, -0.1, 0.3, 0.2, -0.5}}, {"b", "labels:x,y", {0, 1, 0, 1, 1}}};
  s.axes = {sample, {"k", "", {0.0, 1.0}}};
  s.metrics = {{"E", "Nm", "energy", {}}, {"status_code", "", "index of the status", {}, "status_code", {"ok", "bad"}}};
  return s;
}
}  // namespace

// Format 5: a sampled dimension keeps every parameter's values along it, and a grid of codes reads
// back as written, NaN (stored as -1) where no cell was written; a resumed writer keeps that grid.
TEST(StoreLandscapes, ASampledDimensionKeepsItsParametersAndCodesReadBackWithNaN) {
  TempDir td;
  const std::string path = td.file("s.h5");
  const double nan = std::nan("");
  const LandscapeSpec spec = sampled_spec();
  {
    auto w = ResultsWriter::create(path, test_meta(), test_columns(), 4);
    const std::size_t h = w->begin_landscape(spec);
    const double a[2] = {1.5, 1.0}, b[2] = {2.5, 0.0}, c[2] = {nan, nan};
    w->write_landscape_cell(h, 1, a);
    w->write_landscape_cell(h, 2, b);
    w->write_landscape_cell(h, 3, c);
    w->close();
  }
  LandscapeSpec got = ResultsReader(path).read_landscape("S");
  ASSERT_EQ(got.axes.size(), 2u);
  EXPECT_EQ(got.axes[0].name, "sample");
  ASSERT_EQ(got.axes[0].coordinates.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(got.axes[0].coordinates[i].name, spec.axes[0].coordinates[i].name);
    EXPECT_EQ(got.axes[0].coordinates[i].unit, spec.axes[0].coordinates[i].unit);
    EXPECT_EQ(got.axes[0].coordinates[i].values, spec.axes[0].coordinates[i].values);
  }
  EXPECT_TRUE(got.axes[1].coordinates.empty());
  const std::vector<double> E(10, nan), code(10, nan);
  std::vector<double> wantE = E, wantCode = code;
  wantE[1] = 1.5, wantE[2] = 2.5, wantCode[1] = 1.0, wantCode[2] = 0.0;
  expect_grid(got, {wantE, wantCode}, "written");
  {
    auto w = std::move(ResultsWriter::open_for_resume(path, test_meta().study_sha256).writer);
    const double d[2] = {4.0, 1.0};
    w->write_landscape_cell(w->begin_landscape(spec), 9, d);
    w->close();
  }
  wantE[9] = 4.0, wantCode[9] = 1.0;
  expect_grid(ResultsReader(path).read_landscape("S"), {wantE, wantCode}, "kept by a resumed writer");
}
