// Deterministic test content for the store tests and store_writer_helper (tests/python/check_store.py
// recomputes the same formulas independently). Every value is an exact IEEE expression so that C++
// and Python agree bit for bit.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "store_testgen.hpp"

namespace ks::store_test {

std::vector<ColumnSpec> test_columns() {
  return {{"alpha", CellType::f64, "rad", "first swept angle", Role::parameter, "trajectory"},
          {"E", CellType::f64, "Nm", "energy-like metric", Role::metric, "trajectory"},
          {"iters", CellType::i64, "", "iterations used", Role::metric, "ik"},
          {"status", CellType::str, "", "outcome word", Role::bookkeeping, ""},
          {"method", CellType::str, "", "redundancy resolution", Role::parameter, "trajectory,ik", {"pinv", "dls"}}};
}

Record test_record(std::int64_t id) {
  static const char* statuses[] = {"ok", "diverged", "singular", "ok-\xc3\xb1"};  // "ok-ñ" (UTF-8)
  Record r;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.cells.emplace_back(id % 11 == 3 ? nan : static_cast<double>(id) / 7.0);
  r.cells.emplace_back(static_cast<double>(id) * 0.5 - 3.25);
  r.cells.emplace_back(id % 13 == 0 ? std::int64_t{-1} : id * 3 - 5);
  r.cells.emplace_back(std::string(id % 17 == 5 ? "" : statuses[id % 4]));
  r.cells.emplace_back(std::string(id % 2 ? "dls" : "pinv"));
  return r;
}

RunHistory test_history(std::int64_t id) {
  RunHistory h;
  if (id % 5 == 4) return h;  // some runs have no history
  const std::size_t n = id % 7 == 6 ? 0 : 10 + static_cast<std::size_t>(id % 7) * 40;  // some have 0 rows
  HistoryArray t{"t", "s", n, 1, {}};
  HistoryArray q{"q", "rad", n, 3, {}};
  HistoryArray tau{"tau", "Nm", n, 2, {}};
  const double special[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), -0.0,
                            1e-310 * static_cast<double>(id + 1)};
  for (std::size_t i = 0; i < n; ++i) {
    t.data.push_back(static_cast<double>(i) / 8.0 + static_cast<double>(id));
    for (std::size_t j = 0; j < 3; ++j)
      q.data.push_back(static_cast<double>(id) + static_cast<double>(i) * 0.25 - static_cast<double>(j) / 3.0);
    for (std::size_t j = 0; j < 2; ++j)
      tau.data.push_back(i < 2 ? special[2 * i + j] : std::sin(static_cast<double>(id * 100 + i * 2 + j)));
  }
  HistoryArray none{"none", "", n, 0, {}};  // an array of no columns
  h.arrays = {t, q, tau, none};
  return h;
}

store::StoreMeta test_meta() {
  store::StoreMeta m;
  m.study_name = "store-test";
  m.study_path = "studies/store-test.toml";
  m.study_text = "# a study\nname = \"store-test\"\n[block.A]\nalpha = [0, 1]\n";
  m.study_sha256 = "5f2b9c0e7d4a1b3c5f2b9c0e7d4a1b3c5f2b9c0e7d4a1b3c5f2b9c0e7d4a1b3c";
  return m;
}

store::LandscapeSpec test_landscape() {
  store::LandscapeSpec s;
  s.block.assign(1, 'A');
  s.axes = {{"alpha1A", "rad", {0.0, 0.5, 1.0}}, {"alpha2A", "rad", {-1.0, 1.0}}};
  store::LandscapeMetric E{"E", "Nm", "mean energy", {}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) E.grid.push_back(i == 1 && j == 0 ? std::nan("") : i * 10.0 + j);
  s.metrics = {E};
  return s;
}

std::vector<ColumnSpec> copy_columns() {
  return {{"x", CellType::f64, "m", "a smooth value", Role::metric, ""},
          {"n", CellType::i64, "", "an integer", Role::metric, ""},
          {"word", CellType::str, "", "one of three words or none", Role::parameter, "", {"alpha", "beta", "delta"}}};
}

Record copy_record(std::int64_t id) {
  static const char* words[] = {"alpha", "beta", "delta", ""};
  Record r;
  r.cells.emplace_back(std::sin(0.001 * static_cast<double>(id)) + 1e-3 * static_cast<double>(id % 97));
  r.cells.emplace_back(id % 11 == 0 ? std::int64_t{-1} : id * 3);
  r.cells.emplace_back(std::string(words[id % 4]));
  return r;
}

}  // namespace ks::store_test
