#pragma once
// Internal: the format 3 history datasets as both the writer and the reader see them (FORMAT.md:
// "/histories"). Only store/*.cpp.
#include <string>
#include <vector>

#include "store/h5util.hpp"

namespace ks::store::detail {

/// One shared history dataset: rows x cols doubles, every run's rows of one array at its start.
struct HistoryDataset {
  std::string name, array, unit;  ///< dataset name (the array name, or "<array>.<n>"), array name, unit
  std::size_t cols = 1;
  Hid dset;
  hsize_t extent = 0;             ///< rows of the dataset's current extent
};

/// The dataset names of one entry of the attribute `layouts` of /histories ("q,qd,tau").
std::vector<std::string> split_layout(const std::string& layout);

/// Opens /histories/<name> under the /histories group `histories`, with its attributes and extent.
/// Throws StoreError naming `path`.
HistoryDataset open_history_dataset(hid_t histories, const std::string& name, const std::string& path);

}  // namespace ks::store::detail
