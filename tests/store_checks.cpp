// Checks shared by the store tests (store_checks.hpp).
#include "store_checks.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstring>

#include "store_testgen.hpp"

namespace ks::store_test {
using namespace ks::store;

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool same_cell(const Cell& a, const Cell& b) {
  if (a.index() != b.index()) return false;
  if (auto* x = std::get_if<double>(&a)) return same_bits(*x, std::get<double>(b));
  return a == b;
}

void expect_same_history(const RunHistory& got, const RunHistory& want, std::int64_t id) {
  ASSERT_EQ(got.arrays.size(), want.arrays.size()) << "run " << id;
  for (std::size_t k = 0; k < want.arrays.size(); ++k) {
    const auto &g = got.arrays[k], &w = want.arrays[k];
    EXPECT_EQ(g.name, w.name);
    EXPECT_EQ(g.unit, w.unit);
    EXPECT_EQ(g.rows, w.rows);
    EXPECT_EQ(g.cols, w.cols);
    ASSERT_EQ(g.data.size(), w.data.size());
    if (!w.data.empty()) {  // memcmp of an empty vector's null data is undefined
      EXPECT_EQ(0, std::memcmp(g.data.data(), w.data.data(), w.data.size() * sizeof(double)))
          << "run " << id << " array " << w.name << " not bit-identical";
    }
  }
}

std::int64_t verify_done_runs(const ResultsReader& r) {
  auto done = r.done_mask();
  std::vector<std::vector<Cell>> cols;
  for (auto& c : r.columns()) cols.push_back(r.read_column(c.name));
  std::int64_t n_done = 0;
  for (std::int64_t id = 0; id < r.n_runs(); ++id) {
    const auto want = test_record(id);
    if (!done[static_cast<std::size_t>(id)]) {
      // An undone row holds the missing values, or (when the writer died between committing the rows
      // and committing their done flags) exactly the right values; never anything else.
      bool all_missing = true, all_right = true;
      for (std::size_t c = 0; c < cols.size(); ++c) {
        const Cell& g = cols[c][static_cast<std::size_t>(id)];
        if (auto* d = std::get_if<double>(&g)) {
          all_missing = all_missing && std::isnan(*d);
        } else if (auto* i = std::get_if<std::int64_t>(&g)) {
          all_missing = all_missing && *i == -1;
        } else {
          all_missing = all_missing && std::get<std::string>(g).empty();
        }
        all_right = all_right && same_cell(g, want.cells[c]);
      }
      EXPECT_TRUE(all_missing || all_right) << "undone run " << id << " holds a torn row";
      if (r.has_history(id)) expect_same_history(r.read_history(id), test_history(id), id);
      continue;
    }
    ++n_done;
    for (std::size_t c = 0; c < cols.size(); ++c)
      EXPECT_TRUE(same_cell(cols[c][static_cast<std::size_t>(id)], want.cells[c]))
          << "run " << id << " column " << r.columns()[c].name;
    expect_same_history(r.read_history(id), test_history(id), id);
  }
  return n_done;
}

std::string check_snapshot(const ResultsReader& r, std::int64_t* n_done, int history_stride) {
  auto done = r.done_mask();
  std::vector<std::vector<Cell>> cols;
  for (auto& c : r.columns()) cols.push_back(r.read_column(c.name));
  *n_done = 0;
  for (std::int64_t id = 0; id < r.n_runs(); ++id) {
    if (!done[static_cast<std::size_t>(id)]) continue;
    ++*n_done;
    const auto want = test_record(id);
    for (std::size_t c = 0; c < cols.size(); ++c)
      if (!same_cell(cols[c][static_cast<std::size_t>(id)], want.cells[c]))
        return "run " + std::to_string(id) + " column " + r.columns()[c].name;
    if (id % history_stride != 0 && id + 8 < r.n_runs() && done[static_cast<std::size_t>(id + 8)]) continue;
    const auto got = r.read_history(id), w = test_history(id);
    if (got.arrays.size() != w.arrays.size()) return "run " + std::to_string(id) + " history arrays";
    for (std::size_t k = 0; k < w.arrays.size(); ++k)
      if (got.arrays[k].data.size() != w.arrays[k].data.size() ||
          (!w.arrays[k].data.empty() &&
           std::memcmp(got.arrays[k].data.data(), w.arrays[k].data.data(), w.arrays[k].data.size() * 8) != 0))
        return "run " + std::to_string(id) + " history " + w.arrays[k].name;
  }
  return "";
}

std::unique_ptr<ResultsWriter> make_writer(const std::string& path, std::int64_t n, StoreOptions opt) {
  return ResultsWriter::create(path, test_meta(), test_columns(), n, opt);
}

bool opens_with_plain_hdf5(const std::string& path) {
  H5E_auto2_t f;
  void* d;
  H5Eget_auto2(H5E_DEFAULT, &f, &d);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  bool ok = id >= 0;
  if (ok) {
    hid_t ds = H5Dopen2(id, "runs/done", H5P_DEFAULT);
    ok = ds >= 0;
    if (ok) H5Dclose(ds);
    H5Fclose(id);
  }
  H5Eset_auto2(H5E_DEFAULT, f, d);
  return ok;
}

bool journal_has_commit(const std::string& results) {
  // same check as store::detail::journal_has_pending_commit, read from the file format (FORMAT.md)
  std::string j = slurp(results + ".journal");
  if (j.size() < 64) return false;
  return j.compare(j.size() - 32, 8, "KSJCMT01") == 0;
}

}  // namespace ks::store_test
