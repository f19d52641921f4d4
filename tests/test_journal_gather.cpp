// The journal driver's gathering of small writes past the committed size (journal_vfd.cpp): every
// byte HDF5 writes is what it reads back, before and after a commit, and what a plain HDF5 open of
// the closed file reads.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "store/journal/vfd.hpp"

namespace {
namespace fs = std::filesystem;

/// Row r of the test dataset: its chunk of `cols` values (every value distinct).
std::vector<double> row(std::size_t r, std::size_t cols) {
  std::vector<double> v(cols);
  for (std::size_t c = 0; c < cols; ++c) v[c] = static_cast<double>(r) * 1000.0 + static_cast<double>(c) + 0.25;
  return v;
}

/// Reads row r through `d` (chunk cache off: from the file, through the driver).
std::vector<double> read_row(hid_t d, std::size_t r, std::size_t cols) {
  std::vector<double> v(cols, -1.0);
  hid_t fs = H5Dget_space(d);
  const hsize_t start[2] = {r, 0}, count[2] = {1, cols};
  H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, nullptr, count, nullptr);
  hid_t ms = H5Screate_simple(2, count, nullptr);
  EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, v.data()), 0);
  H5Sclose(ms);
  H5Sclose(fs);
  return v;
}

TEST(JournalGather, SmallAndLargeChunkWritesReadBackBeforeAndAfterCommits) {
  const fs::path dir = fs::temp_directory_path() / ("ks_gather_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "g.h5").string();
  // Row sizes from 64 B to 96 KiB: below and above the driver's direct-write size (16 KiB).
  const std::vector<std::size_t> widths = {8, 100, 1500, 3000, 12000};
  const std::size_t rows = 300;
  {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_V18);
    hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    for (std::size_t k = 0; k < widths.size(); ++k) {
      const hsize_t dims[2] = {0, widths[k]}, maxdims[2] = {H5S_UNLIMITED, widths[k]}, chunk[2] = {1, widths[k]};
      hid_t space = H5Screate_simple(2, dims, maxdims);
      hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
      H5Pset_chunk(dcpl, 2, chunk);
      hid_t d = H5Dcreate2(f, ("d" + std::to_string(k)).c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
      H5Dclose(d);
      H5Pclose(dcpl);
      H5Sclose(space);
    }
    H5Fclose(f);
    H5Pclose(fapl);
  }
  std::mt19937 g(5);
  {
    hid_t fapl = ks::store::detail::make_journal_fapl(false);
    H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_V18);
    hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl);
    ASSERT_GE(f, 0);
    hid_t dapl = H5Pcreate(H5P_DATASET_ACCESS);
    H5Pset_chunk_cache(dapl, 0, 0, 1.0);  // every read goes to the driver
    std::vector<hid_t> d;
    for (std::size_t k = 0; k < widths.size(); ++k) d.push_back(H5Dopen2(f, ("d" + std::to_string(k)).c_str(), dapl));
    for (std::size_t r = 0; r < rows; ++r) {
      for (std::size_t k = 0; k < widths.size(); ++k) {
        const hsize_t ext[2] = {r + 1, widths[k]}, offset[2] = {r, 0};
        ASSERT_GE(H5Dset_extent(d[k], ext), 0);
        const std::vector<double> v = row(r, widths[k]);
        ASSERT_GE(H5Dwrite_chunk(d[k], H5P_DEFAULT, 0, offset, v.size() * 8, v.data()), 0);
        // Read back a recent row and a random earlier one (gathered, written or committed).
        const std::size_t back = g() % 3 == 0 ? g() % (r + 1) : r;
        EXPECT_EQ(read_row(d[k], back, widths[k]), row(back, widths[k])) << "d" << k << " row " << back << " after " << r;
      }
      if (r % 37 == 36) {
        ASSERT_GE(H5Fflush(f, H5F_SCOPE_LOCAL), 0);  // a commit now and then
      }
    }
    for (hid_t x : d) H5Dclose(x);
    H5Pclose(dapl);
    ASSERT_GE(H5Fclose(f), 0);
    H5Pclose(fapl);
  }
  {  // the closed file, with HDF5's own driver
    hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    for (std::size_t k = 0; k < widths.size(); ++k) {
      hid_t d = H5Dopen2(f, ("d" + std::to_string(k)).c_str(), H5P_DEFAULT);
      for (std::size_t r = 0; r < rows; ++r) EXPECT_EQ(read_row(d, r, widths[k]), row(r, widths[k])) << "d" << k << " row " << r;
      H5Dclose(d);
    }
    H5Fclose(f);
  }
  EXPECT_FALSE(fs::exists(ks::store::detail::journal_path(path))) << "a clean close leaves no journal";
  fs::remove_all(dir);
}

}  // namespace
