#pragma once
// Internal: reading rows of the /runs datasets (a range or a list of run ids), shared by the
// reader and the writer (which reads back committed rows on resume). Only store/*.cpp.
#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

#include "store/record.hpp"

namespace ks::store::detail {

/// Which rows a read takes: `count` rows from `first`, or, when `ids` is set, those run ids
/// (ascending, each < the row count).
struct RowSelection {
  hsize_t first = 0, count = 0;
  const std::vector<std::int64_t>* ids = nullptr;
  hsize_t size() const { return ids ? static_cast<hsize_t>(ids->size()) : count; }
};

/// Rows `sel` of /runs/<name> as `mtype` (H5T_NATIVE_DOUBLE, _INT64 or _UINT8) into `out` (size()
/// values). Throws StoreError naming `path`.
void read_runs_numbers(hid_t file, const std::string& path, const std::string& name, hid_t mtype,
                       const RowSelection& sel, void* out);
/// Rows `sel` of the open /runs dataset `dset` (column `name`) read as `mtype` into `out`.
void read_runs_typed(hid_t dset, const std::string& path, const std::string& name, hid_t mtype,
                     const RowSelection& sel, void* out);
/// Rows `sel` of the text column /runs/<name> ("" for a null string or the missing code of a
/// labelled column). Throws StoreError.
std::vector<std::string> read_runs_strings(hid_t file, const std::string& path, const std::string& name,
                                           const RowSelection& sel);

template <class T>
std::vector<T> read_runs_column(hid_t file, const std::string& path, const std::string& name, hid_t mtype,
                                const RowSelection& sel) {
  std::vector<T> out(sel.size());
  if (!out.empty()) read_runs_numbers(file, path, name, mtype, sel, out.data());
  return out;
}

/// Rows `sel` of the columns `columns` (one Record per row, cells in the order of `columns`).
std::vector<Record> read_runs_rows(hid_t file, const std::string& path, const std::vector<ColumnSpec>& columns,
                                   const RowSelection& sel);

}  // namespace ks::store::detail
