#pragma once
// Internal: consecutive cells of a row-major grid as HDF5 hyperslab blocks. Only store/*.cpp.
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
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

/// Writes the `n` cells `v` to the selection `fs` (`ms` in memory) of grid dataset `d`: as they are
/// to an f64 grid; to a grid of integer codes rounded, NaN as -1 (no code). False on an HDF5 error.
inline bool write_cells(hid_t d, hid_t ms, hid_t fs, const double* v, hsize_t n) {
  const hid_t type = H5Dget_type(d);
  const bool codes = type >= 0 && H5Tget_class(type) == H5T_INTEGER;
  if (type >= 0) H5Tclose(type);
  if (!codes) return H5Dwrite(d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, v) >= 0;
  std::vector<std::int64_t> c(n);
  for (hsize_t i = 0; i < n; ++i) c[i] = v[i] == v[i] ? static_cast<std::int64_t>(std::llround(v[i])) : -1;
  return H5Dwrite(d, H5T_NATIVE_INT64, ms, fs, H5P_DEFAULT, c.data()) >= 0;
}

/// Reads `n` cells of grid dataset `d` (selection `fs`, `ms` in memory) into `v`: a grid of integer
/// codes with -1 (no code) as NaN. False on an HDF5 error.
inline bool read_cells(hid_t d, hid_t ms, hid_t fs, double* v, hsize_t n) {
  if (H5Dread(d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, v) < 0) return false;
  const hid_t type = H5Dget_type(d);
  const bool codes = type >= 0 && H5Tget_class(type) == H5T_INTEGER;
  if (type >= 0) H5Tclose(type);
  if (codes)
    for (hsize_t i = 0; i < n; ++i)
      if (v[i] == -1.0) v[i] = std::numeric_limits<double>::quiet_NaN();
  return true;
}

/// Writes `count` consecutive cells (row-major) from `first` of the grid dataset `d` of shape
/// `dims` from `v` (write_cells). False on an HDF5 error.
inline bool write_consecutive(hid_t d, const std::vector<hsize_t>& dims, hsize_t first, hsize_t count, const double* v) {
  return transfer_consecutive(d, dims, first, count, [&](hid_t ms, hid_t fs, hsize_t done) {
    return write_cells(d, ms, fs, v + done, static_cast<hsize_t>(H5Sget_simple_extent_npoints(ms)));
  });
}

/// Reads `count` consecutive cells (row-major) from `first` of the grid dataset `d` of shape
/// `dims` into `v` (read_cells). False on an HDF5 error.
inline bool read_consecutive(hid_t d, const std::vector<hsize_t>& dims, hsize_t first, hsize_t count, double* v) {
  return transfer_consecutive(d, dims, first, count, [&](hid_t ms, hid_t fs, hsize_t done) {
    return read_cells(d, ms, fs, v + done, static_cast<hsize_t>(H5Sget_simple_extent_npoints(ms)));
  });
}

}  // namespace ks::store::detail
