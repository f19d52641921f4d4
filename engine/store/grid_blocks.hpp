#pragma once
// Internal: consecutive cells of a row-major grid as HDF5 hyperslab blocks. Only store/*.cpp.
#include <hdf5.h>

#include <algorithm>
#include <vector>

namespace ks::store::detail {

/// Calls block(start, shape, cells) for each hyperslab block that makes up the cells [first, first +
/// count) of a row-major grid of shape `dims`, in row-major order: at most 2 * rank - 1 blocks (a
/// partial row, whole slabs, a partial row again). Stops and returns false when block() does.
template <class F>
bool for_each_block(const std::vector<hsize_t>& dims, hsize_t first, hsize_t count, F&& block) {
  const std::size_t r = dims.size();
  std::vector<hsize_t> stride(r + 1, 1);  // stride[k]: cells in the trailing k dimensions
  for (std::size_t k = 1; k <= r; ++k) stride[k] = stride[k - 1] * dims[r - k];
  std::vector<hsize_t> start(r), shape(r);
  while (count > 0) {
    std::size_t k = 0;  // the most trailing dimensions that `first` starts whole and `count` covers
    while (k < r && first % stride[k + 1] == 0 && count >= stride[k + 1]) ++k;
    hsize_t rest = first;
    for (std::size_t j = r; j-- > 0;) start[j] = rest % dims[j], rest /= dims[j];
    std::fill(shape.begin(), shape.end(), 1);
    for (std::size_t j = r - k; j < r; ++j) shape[j] = dims[j];
    hsize_t take = stride[k];
    if (k < r) {  // several slabs along the next dimension, up to its end
      const std::size_t d = r - 1 - k;
      const hsize_t m = std::min(count / stride[k], dims[d] - start[d]);
      shape[d] = m;
      take *= m;
    }
    if (!block(start, shape, take)) return false;
    first += take;
    count -= take;
  }
  return true;
}

/// Calls io(mspace, fspace, done) for each block of the `count` consecutive cells (row-major) from
/// `first` of the dataset `d` of a grid of shape `dims`: fspace selects the block, mspace is its
/// `n` cells in memory, `done` the cells of the blocks before it. False on an HDF5 error or a false io().
template <class Io>
bool transfer_consecutive(hid_t d, const std::vector<hsize_t>& dims, hsize_t first, hsize_t count, Io&& io) {
  const hid_t fspace = H5Dget_space(d);
  if (fspace < 0) return false;
  hsize_t done = 0;
  const bool ok = for_each_block(dims, first, count, [&](const std::vector<hsize_t>& start, const std::vector<hsize_t>& shape, hsize_t n) {
    const hid_t mspace = H5Screate_simple(1, &n, nullptr);
    const bool moved = mspace >= 0 &&
                       H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start.data(), nullptr, shape.data(), nullptr) >= 0 &&
                       io(mspace, fspace, done);
    if (mspace >= 0) H5Sclose(mspace);
    done += n;
    return moved;
  });
  H5Sclose(fspace);
  return ok;
}

/// Writes `count` consecutive cells (row-major) from `first` of the f64 grid dataset `d` of shape
/// `dims` from `v`. False on an HDF5 error.
inline bool write_consecutive(hid_t d, const std::vector<hsize_t>& dims, hsize_t first, hsize_t count, const double* v) {
  return transfer_consecutive(d, dims, first, count, [&](hid_t ms, hid_t fs, hsize_t done) {
    return H5Dwrite(d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, v + done) >= 0;
  });
}

/// Reads `count` consecutive cells (row-major) from `first` of the f64 grid dataset `d` of shape
/// `dims` into `v`. False on an HDF5 error.
inline bool read_consecutive(hid_t d, const std::vector<hsize_t>& dims, hsize_t first, hsize_t count, double* v) {
  return transfer_consecutive(d, dims, first, count, [&](hid_t ms, hid_t fs, hsize_t done) {
    return H5Dread(d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, v + done) >= 0;
  });
}

}  // namespace ks::store::detail
