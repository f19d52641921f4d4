// The format 3 history datasets (history_datasets.hpp).
#include "store/history_datasets.hpp"

#include <algorithm>

namespace ks::store::detail {

std::vector<std::string> split_layout(const std::string& layout) {
  std::vector<std::string> names;
  for (std::size_t at = 0; at < layout.size();) {
    const std::size_t comma = std::min(layout.find(',', at), layout.size());
    names.push_back(layout.substr(at, comma - at));
    at = comma + 1;
  }
  return names;
}

HistoryDataset open_history_dataset(hid_t histories, const std::string& name, const std::string& path) {
  HistoryDataset d;
  d.name = name;
  d.dset = Hid(check(H5Dopen2(histories, name.c_str(), H5P_DEFAULT), path, "open /histories/" + name));
  d.array = read_str_attr(d.dset, "array");
  d.unit = read_str_attr(d.dset, "unit");
  hsize_t dims[2] = {0, 0};
  Hid space(H5Dget_space(d.dset));
  if (H5Sget_simple_extent_ndims(space) != 2 || H5Sget_simple_extent_dims(space, dims, nullptr) < 0)
    throw StoreError(path, "/histories/" + name + " is not a two-dimensional dataset");
  d.extent = dims[0];
  d.cols = dims[1];
  return d;
}

}  // namespace ks::store::detail
