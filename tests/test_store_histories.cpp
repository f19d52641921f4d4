// The /histories layout (FORMAT.md): shared datasets with a per-run index, read back with the plain
// HDF5 C API (HDF5's own filter pipeline decodes the chunks the workers encoded), and run copies
// between files chunk by chunk. The oracle is the deterministic generator (store_testgen.hpp).
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "store/store.hpp"
#include "store_checks.hpp"
#include "store_testgen.hpp"

namespace {
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;

std::vector<std::int64_t> read_i64(hid_t f, const char* name) {
  hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
  hid_t s = H5Dget_space(d);
  std::vector<std::int64_t> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
  EXPECT_GE(H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << name;
  H5Sclose(s);
  H5Dclose(d);
  return v;
}

std::int64_t i64_attr(hid_t obj, const char* name) {
  std::int64_t v = -1;
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  EXPECT_GE(H5Aread(a, H5T_NATIVE_INT64, &v), 0) << name;
  H5Aclose(a);
  return v;
}

std::vector<std::string> str_list_attr(hid_t obj, const char* name) {
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  hid_t s = H5Aget_space(a);
  std::vector<char*> p(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
  hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, H5T_VARIABLE);
  H5Tset_cset(t, H5T_CSET_UTF8);
  EXPECT_GE(H5Aread(a, t, p.data()), 0);
  std::vector<std::string> out(p.begin(), p.end());
  H5Dvlen_reclaim(t, s, H5P_DEFAULT, p.data());
  H5Tclose(t);
  H5Sclose(s);
  H5Aclose(a);
  return out;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  for (std::size_t at = 0; at < s.size();) {
    const std::size_t c = std::min(s.find(',', at), s.size());
    out.push_back(s.substr(at, c - at));
    at = c + 1;
  }
  return out;
}

/// Every run's history as plain HDF5 reads it through the documented index, checked against the
/// generator; also the layout's promises: chunk-aligned starts, disjoint runs, no object per run.
void expect_layout_holds(const std::string& path, std::int64_t n) {
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_GE(i64_attr(f, "format_version"), 3);  // the layout of formats 3 and 4
  hid_t h = H5Gopen2(f, "histories", H5P_DEFAULT);
  const std::int64_t C = i64_attr(h, "chunk_rows"), used = i64_attr(h, "used_rows");
  const auto layouts = str_list_attr(h, "layouts");
  const auto start = read_i64(h, "start"), rows = read_i64(h, "rows"), layout = read_i64(h, "layout");
  ASSERT_EQ(static_cast<std::int64_t>(start.size()), n);
  ASSERT_GT(C, 0);
  std::map<std::int64_t, std::int64_t> spans;  // start -> end of each run's chunks
  for (std::int64_t id = 0; id < n; ++id) {
    const RunHistory want = test_history(id);
    const auto i = static_cast<std::size_t>(id);
    if (want.arrays.empty()) {
      EXPECT_EQ(start[i], -1) << id;
      EXPECT_EQ(layout[i], -1) << id;
      continue;
    }
    ASSERT_GE(layout[i], 0) << id;
    EXPECT_EQ(start[i] % C, 0) << "run " << id << " does not start on a chunk boundary";
    EXPECT_EQ(rows[i], static_cast<std::int64_t>(want.arrays.front().rows)) << id;
    const auto names = split(layouts[static_cast<std::size_t>(layout[i])]);
    ASSERT_EQ(names.size(), want.arrays.size()) << id;
    if (rows[i] > 0) spans[start[i]] = start[i] + (rows[i] + C - 1) / C * C;
    for (std::size_t k = 0; k < names.size(); ++k) {
      const HistoryArray& a = want.arrays[k];
      hid_t d = H5Dopen2(h, names[k].c_str(), H5P_DEFAULT);
      ASSERT_GE(d, 0) << names[k];
      hid_t fs = H5Dget_space(d);
      hsize_t dims[2] = {0, 0};
      H5Sget_simple_extent_dims(fs, dims, nullptr);
      EXPECT_EQ(dims[1], a.cols) << names[k];
      if (a.cols > 0) {
        EXPECT_EQ(static_cast<std::int64_t>(dims[0]), used) << "a finished file's extent is used_rows";
      }
      std::vector<double> got(a.rows * a.cols);
      if (!got.empty()) {
        const hsize_t first[2] = {static_cast<hsize_t>(start[i]), 0}, count[2] = {a.rows, a.cols};
        hid_t ms = H5Screate_simple(2, count, nullptr);
        H5Sselect_hyperslab(fs, H5S_SELECT_SET, first, nullptr, count, nullptr);
        EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, got.data()), 0);
        H5Sclose(ms);
        EXPECT_EQ(0, std::memcmp(got.data(), a.data.data(), 8 * got.size())) << "run " << id << " " << a.name;
      }
      H5Sclose(fs);
      H5Dclose(d);
    }
  }
  std::int64_t end = 0;
  for (auto& [s, e] : spans) {
    EXPECT_GE(s, end) << "two runs share rows";
    end = e;
  }
  EXPECT_LE(end, used);
  // one object per array and its netCDF dimension (<dataset>_column), the index and its dimensions;
  // none per run
  H5G_info_t info{};
  H5Gget_info(h, &info);
  std::size_t arrays = 0;
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    char name[128];
    H5Lget_name_by_idx(h, ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof name, H5P_DEFAULT);
    const std::string n = name;
    if (n != "start" && n != "rows" && n != "layout" && n != "run_id" && n != "history_row" &&
        !(n.size() > 7 && n.compare(n.size() - 7, 7, "_column") == 0))
      ++arrays;
  }
  EXPECT_LT(arrays, 10u) << "one object per run";
  EXPECT_EQ(info.nlinks, 5 + 2 * arrays);
  H5Gclose(h);
  H5Fclose(f);
}

TEST(StoreHistories, RaggedLayoutReadsBackWithPlainHdf5) {
  TempDir td;
  for (int level : {0, 1, 5}) {
    const std::string path = td.file("h" + std::to_string(level) + ".h5");
    const std::int64_t n = 60;
    {
      auto w = make_writer(path, n);
      for (std::int64_t id = n - 1; id >= 0; --id)  // any order; chunk sizes decided by the first
        w->write_run(id, test_record(id), encode_history(test_history(id), level, w->history_chunk_rows()));
      w->close();
    }
    expect_layout_holds(path, n);
    ResultsReader r(path);
    for (std::int64_t id = 0; id < n; ++id) {
      EXPECT_EQ(r.has_history(id), !test_history(id).arrays.empty()) << id;
      expect_same_history(r.read_history(id), test_history(id), id);
    }
  }
}

// A worker may encode before the chunk size is known (or with another one): the writer re-cuts.
TEST(StoreHistories, ChunksOfAnotherSizeAreRecut) {
  TempDir td;
  const std::string path = td.file("r.h5");
  const std::int64_t n = 30;
  {
    auto w = make_writer(path, n);
    for (std::int64_t id = 0; id < n; ++id)
      w->write_run(id, test_record(id), encode_history(test_history(id), 1, id % 3 == 0 ? 0 : 17));
    w->close();
  }
  expect_layout_holds(path, n);
}

// Copying runs into another file (the MPI merge, a resume that reuses runs) moves the chunks as
// they are: the destination's chunks are byte-equal to the source's, and the values are the runs'.
TEST(StoreHistories, RunsCopyChunkByChunk) {
  TempDir td;
  const std::string a = td.file("a.h5"), b = td.file("b.h5");
  const std::int64_t n = 40;
  {
    auto w = make_writer(a, n);
    for (std::int64_t id = 0; id < n; ++id)
      w->write_run(id, test_record(id), encode_history(test_history(id), 3, w->history_chunk_rows()));
    w->close();
  }
  {
    ResultsReader r(a);
    auto w = make_writer(b, n);
    for (std::int64_t id = n - 1; id >= 0; --id) w->write_run(id, r.read_record(id), r.read_history_chunks(id));
    w->close();
  }
  expect_layout_holds(b, n);
  ResultsReader ra(a), rb(b);
  for (std::int64_t id = 0; id < n; ++id) {
    const EncodedHistory ea = ra.read_history_chunks(id), eb = rb.read_history_chunks(id);
    ASSERT_EQ(ea.arrays.size(), eb.arrays.size());
    for (std::size_t k = 0; k < ea.arrays.size(); ++k) {
      ASSERT_EQ(ea.arrays[k].chunks.size(), eb.arrays[k].chunks.size());
      for (std::size_t c = 0; c < ea.arrays[k].chunks.size(); ++c) {
        EXPECT_EQ(ea.arrays[k].chunks[c].bytes, eb.arrays[k].chunks[c].bytes) << id;
        EXPECT_EQ(ea.arrays[k].chunks[c].filter_mask, eb.arrays[k].chunks[c].filter_mask) << id;
      }
    }
  }
}

// A resumed writer continues the row space: the runs written before and after are all intact.
TEST(StoreHistories, ResumeContinuesTheRowSpace) {
  TempDir td;
  const std::string path = td.file("r.h5");
  const std::int64_t n = 50;
  {
    auto w = make_writer(path, n);
    for (std::int64_t id = 0; id < n; id += 2)
      w->write_run(id, test_record(id), encode_history(test_history(id), 2, w->history_chunk_rows()));
    w->close();
  }
  {
    auto resumed = ResultsWriter::open_for_resume(path, test_meta().study_sha256);
    auto& w = *resumed.writer;
    EXPECT_GT(w.history_chunk_rows(), 0u);
    for (std::int64_t id = 1; id < n; id += 2)
      w.write_run(id, test_record(id), encode_history(test_history(id), 2, w.history_chunk_rows()));
    w.close();
  }
  expect_layout_holds(path, n);
}

TEST(StoreHistories, ArraysOfOneRunShareTheirRows) {
  TempDir td;
  auto w = make_writer(td.file("r.h5"), 2);
  EncodedHistory h = encode_history(test_history(1), 1);
  h.arrays[1].rows += 1;
  EXPECT_THROW(w->write_run(1, test_record(1), h), StoreError);
}

}  // namespace
