#pragma once
// Checks shared by the store tests: bitwise comparisons of rows and histories against the
// deterministic generator (store_testgen.hpp), and opening a file with the plain HDF5 C API.
#include <cstdint>
#include <memory>
#include <string>

#include "store/store.hpp"

namespace ks::store_test {

/// Equal doubles bit for bit (NaN == NaN, -0 != +0).
bool same_bits(double a, double b);
/// Equal cells; doubles compared bit for bit.
bool same_cell(const Cell& a, const Cell& b);
/// EXPECTs `got` equal to `want` (names, units, shapes, data bit for bit).
void expect_same_history(const RunHistory& got, const RunHistory& want, std::int64_t id);
/// Checks every run marked done against the generator (and that undone rows are missing or right,
/// never torn); returns the number of done runs.
std::int64_t verify_done_runs(const store::ResultsReader& r);
/// Non-asserting variant for possibly mixed snapshots: "" when every done run is right (histories
/// of runs that are not multiples of `history_stride` are checked only when a later run is done).
std::string check_snapshot(const store::ResultsReader& r, std::int64_t* n_done, int history_stride = 1);
/// A writer of test_columns() with test_meta() for `n` runs.
std::unique_ptr<store::ResultsWriter> make_writer(const std::string& path, std::int64_t n, store::StoreOptions opt = {});
/// Opens the file with the plain HDF5 C API (default sec2 driver, read-only, no recovery) and its /runs/done.
bool opens_with_plain_hdf5(const std::string& path);
/// Whether the journal of `results` holds a complete commit record (read from the format, FORMAT.md).
bool journal_has_commit(const std::string& results);

}  // namespace ks::store_test
