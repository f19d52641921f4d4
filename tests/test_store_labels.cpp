// Format 4 /runs layout: labelled text columns (HDF5 enums with CF flag attributes, the missing
// value a code without a member) and chunked columns, each chunk encoded once (deflated when that
// pays, stored otherwise), read back with the plain HDF5 API as the oracle.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "store/label_columns.hpp"
#include "store/runs_chunks.hpp"
#include "store/store.hpp"
#include "store_testgen.hpp"

namespace {
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;

std::vector<ColumnSpec> labelled_columns() {
  return {{"x", CellType::f64, "m", "a smooth value", Role::metric, ""},
          {"c", CellType::f64, "", "a constant", Role::parameter, ""},
          {"n", CellType::i64, "", "an integer", Role::metric, ""},
          {"word", CellType::str, "", "one of three words or none", Role::parameter, "", {"alpha", "beta gamma", "delta"}},
          {"free", CellType::str, "", "any text", Role::bookkeeping, ""}};
}

Record labelled_record(std::int64_t id) {
  static const char* words[] = {"alpha", "beta gamma", "delta", ""};
  Record r;
  r.cells.emplace_back(std::sin(0.001 * static_cast<double>(id)));
  r.cells.emplace_back(2.5);
  r.cells.emplace_back(id % 7 == 0 ? std::int64_t{-1} : id);
  r.cells.emplace_back(std::string(words[id % 4]));
  r.cells.emplace_back("run " + std::to_string(id));
  return r;
}

/// Reads dataset /runs/<name> whole as `mtype` with the plain HDF5 API.
template <class T>
std::vector<T> raw(const std::string& path, const std::string& name, hid_t mtype, std::size_t n) {
  std::vector<T> v(n);
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t d = H5Dopen2(f, ("runs/" + name).c_str(), H5P_DEFAULT);
  EXPECT_GE(H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << name;
  H5Dclose(d);
  H5Fclose(f);
  return v;
}

TEST(StoreLabels, LabelledColumnsAreEnumsWithFlagAttributesAndReadBackAsText) {
  TempDir td;
  const std::string path = td.file("labels.h5");
  const std::int64_t n = 40000;  // three chunks, the last one partial
  {
    auto w = ResultsWriter::create(path, test_meta(), labelled_columns(), n);
    for (std::int64_t id = n - 1; id >= 0; --id) w->write_run(id, labelled_record(id));  // any order
    w->close();
  }
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t d = H5Dopen2(f, "runs/word", H5P_DEFAULT);
  hid_t t = H5Dget_type(d);
  ASSERT_EQ(H5Tget_class(t), H5T_ENUM);
  EXPECT_EQ(H5Tget_size(t), 1u);
  ASSERT_EQ(H5Tget_nmembers(t), 4);  // the labels and the missing code
  EXPECT_GT(H5Tcommitted(t), 0);      // a named type, as netCDF-4 readers need
  for (unsigned i = 0; i < 4; ++i) {
    std::uint8_t v = 0;
    H5Tget_member_value(t, i, &v);
    char* name = H5Tget_member_name(t, i);
    EXPECT_EQ(std::string(name), v == 255 ? std::string("_missing") : labelled_columns()[3].labels[v]);
    H5free_memory(name);
  }
  hid_t named = H5Topen2(f, "runs_word_t", H5P_DEFAULT);
  ASSERT_GE(named, 0);
  EXPECT_GT(H5Tequal(named, t), 0);
  H5Tclose(named);
  std::uint8_t fill[2] = {0, 0}, flags[3] = {9, 9, 9};
  hid_t a = H5Aopen(d, "_FillValue", H5P_DEFAULT);
  H5Aread(a, H5T_NATIVE_UINT8, fill);
  H5Aclose(a);
  EXPECT_EQ(fill[0], 255);
  a = H5Aopen(d, "flag_values", H5P_DEFAULT);
  H5Aread(a, H5T_NATIVE_UINT8, flags);
  H5Aclose(a);
  EXPECT_EQ(flags[0], 0);
  EXPECT_EQ(flags[2], 2);
  a = H5Aopen(d, "flag_meanings", H5P_DEFAULT);
  hid_t st = H5Aget_type(a);
  char* meanings = nullptr;
  H5Aread(a, st, &meanings);
  EXPECT_STREQ(meanings, "alpha beta_gamma delta");
  H5free_memory(meanings);
  H5Tclose(st);
  H5Aclose(a);
  H5Tclose(t);
  H5Dclose(d);
  H5Fclose(f);

  const auto codes = raw<std::uint8_t>(path, "word", H5T_NATIVE_UINT8, n);
  const auto x = raw<double>(path, "x", H5T_NATIVE_DOUBLE, n);
  const auto c = raw<double>(path, "c", H5T_NATIVE_DOUBLE, n);
  const auto k = raw<std::int64_t>(path, "n", H5T_NATIVE_INT64, n);
  for (std::int64_t id = 0; id < n; ++id) {
    const Record r = labelled_record(id);
    const auto i = static_cast<std::size_t>(id);
    ASSERT_EQ(codes[i], id % 4 == 3 ? 255 : id % 4) << id;
    ASSERT_EQ(x[i], std::get<double>(r.cells[0])) << id;
    ASSERT_EQ(c[i], 2.5) << id;
    ASSERT_EQ(k[i], std::get<std::int64_t>(r.cells[2])) << id;
  }
  ResultsReader rd(path);
  EXPECT_EQ(rd.columns()[3].labels, labelled_columns()[3].labels);
  const auto words = rd.read_str("word", 100, 8);
  for (std::size_t i = 0; i < words.size(); ++i)
    EXPECT_EQ(words[i], std::get<std::string>(labelled_record(100 + static_cast<std::int64_t>(i)).cells[3]));
  EXPECT_EQ(rd.read_str("free", 39999, 1)[0], "run 39999");
  // the constant column costs almost nothing; the smooth one less than its raw bytes
  hid_t f2 = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t dc = H5Dopen2(f2, "runs/c", H5P_DEFAULT), dx = H5Dopen2(f2, "runs/x", H5P_DEFAULT);
  EXPECT_LT(H5Dget_storage_size(dc), static_cast<hsize_t>(n) / 10);
  EXPECT_LT(H5Dget_storage_size(dx), static_cast<hsize_t>(n) * 8);
  H5Dclose(dc);
  H5Dclose(dx);
  H5Fclose(f2);
}

TEST(StoreLabels, AValueOutsideTheLabelsIsRefusedAndTheWriterStaysUsable) {
  TempDir td;
  const std::string path = td.file("bad.h5");
  auto w = ResultsWriter::create(path, test_meta(), labelled_columns(), 4);
  Record r = labelled_record(1);
  r.cells[3] = std::string("epsilon");
  try {
    w->write_run(1, r);
    FAIL() << "no StoreError";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("column 'word' holds 'epsilon', not one of its labels (alpha, beta gamma, delta)"),
              std::string::npos)
        << e.what();
  }
  w->write_run(1, labelled_record(1));
  w->close();
  EXPECT_EQ(ResultsReader(path).read_str("word", 1, 1)[0], "beta gamma");
  std::vector<ColumnSpec> dup = labelled_columns();
  dup[3].labels = {"a", "a"};
  EXPECT_THROW(ResultsWriter::create(td.file("dup.h5"), test_meta(), dup, 2), StoreError);
}

TEST(StoreLabels, RowsCommittedBeforeTheirChunkIsCompleteReadBackAndResumeCompletesIt) {
  TempDir td;
  const std::string path = td.file("partial.h5");
  const std::int64_t n = 20000;
  StoreOptions opt;
  opt.flush_every_runs = 0;
  opt.flush_every_seconds = 0;
  {
    auto w = ResultsWriter::create(path, test_meta(), labelled_columns(), n, opt);
    for (std::int64_t id = 0; id < n; id += 3) w->write_run(id, labelled_record(id));
    w->flush();  // incomplete chunks, stored as they are
    ResultsReader r(path);
    EXPECT_EQ(r.read_f64("x", 3, 1)[0], std::get<double>(labelled_record(3).cells[0]));
    EXPECT_TRUE(std::isnan(r.read_f64("x", 4, 1)[0]));  // not written: the fill value
    EXPECT_EQ(r.read_str("word", 4, 1)[0], "");
    w->close();
  }
  {
    auto res = ResultsWriter::open_for_resume(path, test_meta().study_sha256);
    for (std::int64_t id = 0; id < n; ++id)
      if (!res.writer->is_done(id)) res.writer->write_run(id, labelled_record(id));
    res.writer->close();
  }
  const auto x = raw<double>(path, "x", H5T_NATIVE_DOUBLE, n);
  const auto codes = raw<std::uint8_t>(path, "word", H5T_NATIVE_UINT8, n);
  for (std::int64_t id = 0; id < n; ++id) {
    ASSERT_EQ(x[static_cast<std::size_t>(id)], std::get<double>(labelled_record(id).cells[0])) << id;
    ASSERT_EQ(codes[static_cast<std::size_t>(id)], id % 4 == 3 ? 255 : id % 4) << id;
  }
}

TEST(StoreLabels, ChunkEncodingIsHdf5sShuffleAndDeflate) {
  // Encoded chunks go through HDF5's own filters on read: write them with H5Dwrite_chunk into a
  // dataset with shuffle + deflate and read them back with H5Dread (the oracle), for element sizes
  // 1, 2, 8 and for data that deflates (a ramp) and data that does not (noise: stored blocks).
  TempDir td;
  const std::string path = td.file("chunks.h5");
  hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const hsize_t rows = 70000;  // more than one stored block (65535 bytes) per plane
  std::uint64_t state = 88172645463325252ull;
  for (hid_t type : {H5T_NATIVE_UINT8, H5T_NATIVE_UINT16, H5T_NATIVE_DOUBLE})
    for (bool noise : {false, true}) {
      const std::size_t size = H5Tget_size(type);
      std::vector<unsigned char> bytes(rows * size);
      for (std::size_t i = 0; i < bytes.size(); ++i) {
        state ^= state << 13, state ^= state >> 7, state ^= state << 17;
        bytes[i] = noise ? static_cast<unsigned char>(state) : static_cast<unsigned char>(i / size / 300);
      }
      hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
      H5Pset_chunk(dcpl, 1, &rows);
      H5Pset_shuffle(dcpl);
      H5Pset_deflate(dcpl, 1);
      hid_t space = H5Screate_simple(1, &rows, nullptr);
      const std::string name = std::to_string(size) + (noise ? "noise" : "ramp");
      hid_t d = H5Dcreate2(f, name.c_str(), type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
      const EncodedChunk e = detail::encode_column_chunk(bytes.data(), rows, size, true);
      if (!noise) EXPECT_LT(e.bytes.size(), bytes.size() / 2) << name;  // deflated
      else EXPECT_GT(e.bytes.size(), bytes.size()) << name;            // stored
      const hsize_t offset = 0;
      ASSERT_GE(H5Dwrite_chunk(d, H5P_DEFAULT, e.filter_mask, &offset, e.bytes.size(), e.bytes.data()), 0);
      std::vector<unsigned char> back(bytes.size());
      ASSERT_GE(H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, back.data()), 0) << name;
      EXPECT_EQ(back, bytes) << name;
      H5Dclose(d);
      H5Sclose(space);
      H5Pclose(dcpl);
    }
  H5Fclose(f);
}

// The labels of an enum type, as format 4 wrote it (no member for the missing code) and as format 5
// does (a member `_missing` = 255, `_missing_` when `_missing` is a label): the same labels by code.
TEST(StoreLabels, EnumLabelsOfFormat4And5TypesAreTheSame) {
  const std::vector<std::string> labels = {"ok", "_missing", "bad"};
  hid_t v4 = H5Tenum_create(H5T_STD_U8LE);
  for (std::uint8_t i = 0; i < 3; ++i) H5Tenum_insert(v4, labels[i].c_str(), &i);
  hid_t v5 = ks::store::detail::enum_file_type(labels);
  ASSERT_GE(v5, 0);
  ASSERT_EQ(H5Tget_nmembers(v5), 4);
  char* name = H5Tget_member_name(v5, 3);
  EXPECT_STREQ(name, "_missing_");
  H5free_memory(name);
  std::uint8_t v = 0;
  H5Tget_member_value(v5, 3, &v);
  EXPECT_EQ(v, 255);
  EXPECT_EQ(ks::store::detail::enum_labels(v4, "f.h5", "c"), labels);
  EXPECT_EQ(ks::store::detail::enum_labels(v5, "f.h5", "c"), labels);
  H5Tclose(v4);
  H5Tclose(v5);
}

}  // namespace
