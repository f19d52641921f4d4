// Self-describing /runs columns: the role and kinds attributes (format_version 2), files of format 1
// (read with the caller's column tables; refused by resume, untouched), and files that are no
// results file at all.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <stdlib.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "store/store.hpp"
#include "store_testgen.hpp"

namespace {
namespace fs = std::filesystem;
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;

/// A complete file of `n` runs of the test study (store_testgen.cpp).
void write_test_file(const std::string& path, std::int64_t n) {
  auto w = ResultsWriter::create(path, test_meta(), test_columns(), n);
  for (std::int64_t id = 0; id < n; ++id) w->write_run(id, test_record(id), test_history(id));
  w->close();
}

/// Rewrites a file as another format would have it, with the plain HDF5 API: format_version =
/// `version`, and (drop_roles) no role / kinds attribute on any /runs dataset, as in format 1.
void rewrite_as(const std::string& path, std::int64_t version, bool drop_roles) {
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  hid_t a = H5Aopen(f, "format_version", H5P_DEFAULT);
  ASSERT_GE(a, 0);
  ASSERT_GE(H5Awrite(a, H5T_NATIVE_INT64, &version), 0);
  H5Aclose(a);
  if (drop_roles) {
    std::vector<std::string> names{"done"};
    for (const auto& c : test_columns()) names.push_back(c.name);
    for (const auto& name : names) {
      hid_t d = H5Dopen2(f, ("runs/" + name).c_str(), H5P_DEFAULT);
      ASSERT_GE(d, 0) << name;
      EXPECT_GE(H5Adelete(d, "role"), 0) << name;
      EXPECT_GE(H5Adelete(d, "kinds"), 0) << name;
      H5Dclose(d);
    }
  }
  H5Fclose(f);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const StoreError& e) {
    return e.what();
  }
  return "(no StoreError)";
}

TEST(StoreColumns, RoleWordsRoundTrip) {
  for (Role r : {Role::parameter, Role::metric, Role::bookkeeping}) {
    Role back = r == Role::metric ? Role::parameter : Role::metric;
    ASSERT_TRUE(parse(to_string(r), back)) << to_string(r);
    EXPECT_EQ(back, r);
  }
  EXPECT_EQ(to_string(Role::parameter), "parameter");
  EXPECT_EQ(to_string(Role::metric), "metric");
  EXPECT_EQ(to_string(Role::bookkeeping), "bookkeeping");
  Role r = Role::metric;
  for (const char* bad : {"", "Parameter", "metrics", "parameter "}) {
    EXPECT_FALSE(parse(bad, r)) << "'" << bad << "'";
    EXPECT_EQ(r, Role::metric);  // untouched
  }
}

TEST(StoreColumns, EverySpecFieldIsWrittenAndReadBack) {
  TempDir td;
  const std::string path = td.file("v2.h5");
  std::vector<ColumnSpec> cols = test_columns();
  cols.push_back({"wall_time", CellType::f64, "s", "wall-clock time", Role::bookkeeping, ""});
  {
    auto w = ResultsWriter::create(path, test_meta(), cols, 3);
    w->close();
  }
  ResultsReader r(path);
  EXPECT_EQ(r.meta().format_version, kFormatVersion);
  ASSERT_EQ(r.columns().size(), cols.size());
  for (std::size_t i = 0; i < cols.size(); ++i) {
    const ColumnSpec &got = r.columns()[i], &want = cols[i];
    EXPECT_EQ(got.name, want.name);
    EXPECT_EQ(got.type, want.type) << want.name;
    EXPECT_EQ(got.unit, want.unit) << want.name;
    EXPECT_EQ(got.description, want.description) << want.name;
    EXPECT_EQ(got.role, want.role) << want.name;
    EXPECT_EQ(got.kinds, want.kinds) << want.name;
    EXPECT_EQ(got.labels, want.type == CellType::str ? want.labels : std::vector<std::string>{}) << want.name;
  }
  // resume reads the same specs
  auto res = ResultsWriter::open_for_resume(path, test_meta().study_sha256);
  ASSERT_EQ(res.writer->columns().size(), cols.size());
  for (std::size_t i = 0; i < cols.size(); ++i) {
    EXPECT_EQ(res.writer->columns()[i].role, cols[i].role) << cols[i].name;
    EXPECT_EQ(res.writer->columns()[i].kinds, cols[i].kinds) << cols[i].name;
    EXPECT_EQ(res.writer->columns()[i].labels, cols[i].labels) << cols[i].name;
  }
}

TEST(StoreColumns, Version1FileIsReadWithTheCallersTables) {
  TempDir td;
  const std::string path = td.file("v1.h5");
  write_test_file(path, 12);
  rewrite_as(path, 1, true);
  {
    ResultsReader plain(path);  // no tables given: the ColumnSpec defaults
    EXPECT_EQ(plain.meta().format_version, 1);
    for (const auto& c : plain.columns()) {
      EXPECT_EQ(c.role, Role::bookkeeping) << c.name;
      EXPECT_EQ(c.kinds, "") << c.name;
    }
  }
  int calls = 0;
  ResultsReader r(path, [&](std::vector<ColumnSpec>& cols) {
    ++calls;
    for (auto& c : cols)
      for (const auto& want : test_columns())
        if (c.name == want.name) c.role = want.role, c.kinds = want.kinds;
  });
  EXPECT_EQ(calls, 1);
  ASSERT_EQ(r.columns().size(), test_columns().size());
  for (std::size_t i = 0; i < r.columns().size(); ++i) {
    EXPECT_EQ(r.columns()[i].role, test_columns()[i].role) << test_columns()[i].name;
    EXPECT_EQ(r.columns()[i].kinds, test_columns()[i].kinds) << test_columns()[i].name;
    EXPECT_EQ(r.columns()[i].unit, test_columns()[i].unit) << test_columns()[i].name;
  }
  const auto done = r.done_mask();
  EXPECT_EQ(std::count(done.begin(), done.end(), 1), 12);
  EXPECT_EQ(r.read_f64("E")[4], std::get<double>(test_record(4).cells[1]));
  r.refresh();  // the tables are applied on every open
  EXPECT_EQ(calls, 2);
}

TEST(StoreColumns, ResumeRefusesAVersion1FileAndLeavesItUntouched) {
  TempDir td;
  const std::string path = td.file("old.h5");
  write_test_file(path, 9);
  rewrite_as(path, 1, true);
  const std::string before = slurp(path);
  const auto mtime = fs::last_write_time(path);
  const std::string msg = error_of([&] { ResultsWriter::open_for_resume(path, test_meta().study_sha256); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("results file format v1 (written by kinesweep " KINESWEEP_VERSION
                     "); this kinesweep resumes v3 to v5: rerun with --overwrite"),
            std::string::npos)
      << msg;
  EXPECT_EQ(slurp(path), before);
  EXPECT_EQ(fs::last_write_time(path), mtime);
  EXPECT_FALSE(fs::exists(path + ".journal"));
  // a wrong study is still refused for the format first (the format decides whether anything fits)
  EXPECT_NE(error_of([&] { ResultsWriter::open_for_resume(path, std::string(64, '0')); }).find("format v1"),
            std::string::npos);
  EXPECT_EQ(slurp(path), before);
}

TEST(StoreColumns, NewerFormatIsRefusedByReaderAndResume) {
  TempDir td;
  const std::string path = td.file("newer.h5");
  write_test_file(path, 4);
  const std::string newer = std::to_string(kFormatVersion + 1);
  rewrite_as(path, kFormatVersion + 1, false);
  const std::string before = slurp(path);
  const std::string read = error_of([&] { ResultsReader r(path); });
  EXPECT_NE(read.find("unsupported format_version " + newer), std::string::npos) << read;
  const std::string resume = error_of([&] { ResultsWriter::open_for_resume(path, test_meta().study_sha256); });
  EXPECT_NE(resume.find("results file format v" + newer), std::string::npos) << resume;
  EXPECT_EQ(slurp(path), before);
}

TEST(StoreColumns, AFileOfFormat2OrLaterWithoutRolesIsRejected) {
  TempDir td;
  const std::string path = td.file("broken.h5");
  write_test_file(path, 4);
  rewrite_as(path, kFormatVersion, true);
  const std::string msg = error_of([&] { ResultsReader r(path); });
  EXPECT_NE(msg.find("role"), std::string::npos) << msg;
  EXPECT_NE(error_of([&] { ResultsWriter::open_for_resume(path, test_meta().study_sha256); }).find("role"),
            std::string::npos);
}

TEST(StoreColumns, AFileThatIsNoHdf5FileIsNamedAsSuch) {
  TempDir td;
  const std::string path = td.file("study.toml");
  std::ofstream(path) << "[study]\nname = \"x\"\n";
  const std::string msg = error_of([&] { ResultsReader r(path); });
  EXPECT_NE(msg.find(path + ": not an HDF5 file"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

TEST(StoreColumns, AStringColumnWhoseReadFailsHalfWayThrowsAndKeepsNoString) {
  // Row 1 of /runs/status (free text) refers to a global heap collection past the end of the file: HDF5 converts
  // row 0's string, then fails on row 1 and never copies row 0's pointer out. The reader frees the
  // strings HDF5 allocated on that path too (LeakSanitizer checks this in sanitizer builds).
  TempDir td;
  const std::string path = td.file("bad_heap_ref.h5");
  write_test_file(path, 3);
  haddr_t offset = HADDR_UNDEF;
  {
    hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    hid_t d = H5Dopen2(f, "runs/status", H5P_DEFAULT);
    ASSERT_GE(d, 0);
    offset = H5Dget_offset(d);  // contiguous: rows at fixed addresses
    H5Dclose(d);
    H5Fclose(f);
  }
  ASSERT_NE(offset, HADDR_UNDEF);
  // A row on disk: the string's length (4 bytes), its heap collection's address (8), its index (4).
  std::fstream io(path, std::ios::in | std::ios::out | std::ios::binary);
  std::uint32_t len0 = 0;
  io.seekg(static_cast<std::streamoff>(offset));
  io.read(reinterpret_cast<char*>(&len0), sizeof len0);
  ASSERT_EQ(len0, 2u);  // row 0 is "ok": the layout is as assumed
  const std::uint64_t past_the_end = std::uint64_t{1} << 40;
  io.seekp(static_cast<std::streamoff>(offset + 16 + 4));
  io.write(reinterpret_cast<const char*>(&past_the_end), sizeof past_the_end);
  io.close();
  ASSERT_TRUE(io);

  ResultsReader r(path);
  const std::string msg = error_of([&] { r.read_str("status"); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("read /runs/status"), std::string::npos) << msg;
  EXPECT_NE(error_of([&] { r.read_record(1); }).find("read /runs/status"), std::string::npos);
  // the rows around it still read
  EXPECT_EQ(std::get<std::string>(r.read_record(0).cells[3]), "ok");
  EXPECT_EQ(std::get<std::string>(r.read_record(2).cells[3]), "singular");
  EXPECT_EQ(r.read_str("method"), (std::vector<std::string>{"pinv", "dls", "pinv"}));
}

}  // namespace
