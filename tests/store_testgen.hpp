#pragma once
// Deterministic test content for the store tests and store_writer_helper (defined in store_testgen.cpp;
// tests/python/check_store.py recomputes the same formulas independently).
#include <cstdint>
#include <vector>

#include "store/store.hpp"

namespace ks::store_test {
std::vector<ColumnSpec> test_columns();
Record test_record(std::int64_t id);
RunHistory test_history(std::int64_t id);
store::StoreMeta test_meta();
store::LandscapeSpec test_landscape();
}  // namespace ks::store_test
