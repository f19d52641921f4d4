#pragma once
// Internal: the state of a ResultsReader, shared by reader.cpp and reader_histories.cpp. Only store/*.cpp.
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "store/h5util.hpp"
#include "store/history_datasets.hpp"
#include "store/runs_read.hpp"
#include "store/store.hpp"

namespace ks::store {

/// What one open of a format 3 file knows of /histories once a history was read: the index
/// datasets, the layouts, the datasets opened so far and the last block of index values read.
/// It belongs to one open (refresh() drops it), so its reads see the state of that open.
struct HistoryIndexCache {
  bool present = false;             ///< the file has /histories/start
  detail::Hid group, start, rows, layout;
  std::vector<std::vector<std::string>> layouts;  ///< dataset names per layout
  hsize_t chunk_rows = 0;
  std::deque<detail::HistoryDataset> datasets;    ///< opened so far (a deque: entries keep their address)
  static constexpr std::int64_t kBlock = 4096;    ///< index values read at once
  std::int64_t block_first = -1;
  std::vector<std::int64_t> block_start, block_rows, block_layout;
};

struct ResultsReader::Impl {
  std::string path;
  detail::Hid file;
  StoreMeta meta;
  std::vector<ColumnSpec> columns;
  std::int64_t n_runs = 0;
  std::string stamp;  // consistency stamp at open
  bool overlay = false;  // opened through the journal's overlay of a commit not yet applied
  V1ColumnRoles v1_roles;
  /// Handles and index of /histories, read at the first history read after an open (reader_histories.cpp).
  std::unique_ptr<HistoryIndexCache> hist;

  /// Reads the root attributes, /study and the /runs columns of the open file (reader.cpp).
  void load();

  const ColumnSpec& column(const std::string& name) const {
    for (auto& c : columns)
      if (c.name == name) return c;
    throw StoreError(path, "no column '" + name + "'");
  }

  /// Rows `first` .. `first + count` (clamped to n_runs).
  detail::RowSelection range(std::int64_t first, std::int64_t count) const {
    if (first < 0 || count < 0) throw StoreError(path, "negative row range");
    const std::int64_t end = std::min(n_runs, first + std::min(count, n_runs));
    return {static_cast<hsize_t>(std::min(first, n_runs)), static_cast<hsize_t>(std::max<std::int64_t>(0, end - first))};
  }
  const ColumnSpec& typed(const std::string& name, CellType type) const {
    const ColumnSpec& c = column(name);
    static const char* names[] = {"f64", "i64", "str"};
    if (c.type != type) throw StoreError(path, "column " + name + " is not " + names[static_cast<int>(type)]);
    return c;
  }
};

/// The run kinds' meanings of an open results file (/kinds, FORMAT.md): one KindMeta per group, its
/// string-list attributes as written; empty when the file has no /kinds (kinds_read.cpp).
std::vector<KindMeta> read_kind_meta(hid_t file, const std::string& path);

}  // namespace ks::store
