#pragma once
// Deterministic test content for the store tests and store_writer_helper (defined in store_testgen.cpp;
// tests/python/check_store.py recomputes the same formulas independently).
#include <stdlib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "store/store.hpp"

namespace ks::store_test {
std::vector<ColumnSpec> test_columns();
Record test_record(std::int64_t id);
RunHistory test_history(std::int64_t id);
store::StoreMeta test_meta();
store::LandscapeSpec test_landscape();
/// Three columns (a smooth f64 "x", an i64 "n" with missing values, a labelled "word") and run id's
/// row of them: the column tests' and the merge tests' content.
std::vector<ColumnSpec> copy_columns();
Record copy_record(std::int64_t id);

/// A fresh directory under /tmp, removed with its contents at scope exit.
struct TempDir {
  std::filesystem::path dir;
  TempDir() {
    char tmpl[] = "/tmp/ks_store_test_XXXXXX";
    dir = mkdtemp(tmpl);
  }
  ~TempDir() { std::filesystem::remove_all(dir); }
  std::string file(const std::string& name) const { return (dir / name).string(); }
};

/// The bytes of a file.
inline std::string slurp(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}
}  // namespace ks::store_test
