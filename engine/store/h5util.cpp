#include "store/h5util.hpp"

#include <hdf5_hl.h>  // H5DS: dimension scales

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <unordered_set>

#include "store/checked_read_vfd.hpp"
#include "store/label_columns.hpp"

namespace ks::store {

void print_hdf5_error_stack(bool print) {
  if (print) H5Eset_auto2(H5E_DEFAULT, reinterpret_cast<H5E_auto2_t>(H5Eprint2), stderr);
  else H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

}  // namespace ks::store

namespace ks::store::detail {

namespace {
herr_t walk_cb(unsigned n, const H5E_error2_t* e, void* data) {
  auto* out = static_cast<std::string*>(data);
  if (n > 3) return 0;  // the innermost few messages carry the cause
  if (!out->empty()) *out += "; ";
  *out += e->desc ? e->desc : "?";
  if (e->func_name) *out += std::string(" (") + e->func_name + ")";
  return 0;
}
}  // namespace

std::string h5_error_text() {
  std::string out;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, walk_cb, &out);
  H5Eclear2(H5E_DEFAULT);
  return out.empty() ? "HDF5 error" : out;
}

hid_t check(hid_t id, const std::string& path, const std::string& what) {
  if (id < 0) throw StoreError(path, what + ": " + h5_error_text());
  return id;
}

hid_t utf8_vlen_type() {
  hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, H5T_VARIABLE);
  H5Tset_cset(t, H5T_CSET_UTF8);
  return t;
}

namespace {
/// The blocks HDF5 allocated through one transfer property list (H5Pset_vlen_mem_manager) and has
/// not freed; all freed when this goes out of scope.
struct VlenBlocks {
  std::unordered_set<void*> live;
  VlenBlocks() = default;
  VlenBlocks(const VlenBlocks&) = delete;
  VlenBlocks& operator=(const VlenBlocks&) = delete;
  ~VlenBlocks() {
    for (void* p : live) std::free(p);
  }
};

void* vlen_alloc(std::size_t size, void* info) {
  void* p = std::malloc(size);
  if (!p) return nullptr;
  try {
    static_cast<VlenBlocks*>(info)->live.insert(p);
  } catch (...) {  // no exception crosses HDF5's C frames: the read fails as out of memory
    std::free(p);
    return nullptr;
  }
  return p;
}

void vlen_free(void* p, void* info) {
  if (!p) return;
  static_cast<VlenBlocks*>(info)->live.erase(p);
  std::free(p);
}
}  // namespace

std::vector<std::string> read_vlen_strings(hid_t dset, hid_t mem_space, hid_t file_space, std::size_t n,
                                           const std::string& path, const std::string& what) {
  std::vector<std::string> out;
  {  // the memory dataspace (the dataset's own with H5S_ALL) must fit the buffer of n pointers
    Hid ds(mem_space == H5S_ALL ? H5Dget_space(dset) : H5Scopy(mem_space));
    const hssize_t extent = H5Sget_simple_extent_npoints(check(ds, path, what));
    if (extent < 0 || static_cast<std::size_t>(extent) != n)
      throw StoreError(path, what + ": " + std::to_string(extent) + " strings where " + std::to_string(n) +
                                 " were expected");
  }
  if (n == 0) return out;
  VlenBlocks blocks;  // outlives the transfer list that allocates into it
  Hid xfer(check(string_transfer(n), path, what));
  check(H5Pset_vlen_mem_manager(xfer, vlen_alloc, &blocks, vlen_free, &blocks), path, what);
  Hid type(utf8_vlen_type());
  std::vector<char*> ptrs(n, nullptr);
  check_vlen_references(dset, file_space, path, what);  // HDF5 1.10 trusts them
  check(H5Dread(dset, type, mem_space, file_space, xfer, ptrs.data()), path, what);
  out.reserve(n);
  for (char* p : ptrs) out.emplace_back(p ? p : "");
  return out;
}

hid_t conversion_transfer(std::size_t n, std::size_t element_bytes) {
  const hid_t xfer = H5Pcreate(H5P_DATASET_XFER);
  if (xfer < 0) return xfer;
  // HDF5 strip-mines a transfer larger than the buffer; the cap keeps a huge read's buffer at the default
  const std::size_t bytes = std::min<std::size_t>(std::max<std::size_t>(n, 1) * element_bytes, std::size_t{1} << 20);
  if (H5Pset_buffer(xfer, bytes, nullptr, nullptr) < 0) {
    H5Pclose(xfer);
    return -1;
  }
  return xfer;
}

hid_t string_transfer(std::size_t n) { return conversion_transfer(n, 16); }

void write_str_attr(hid_t obj, const char* name, const std::string& value) {
  if (H5Aexists(obj, name) > 0) H5Adelete(obj, name);
  Hid type(utf8_vlen_type());
  Hid space(H5Screate(H5S_SCALAR));
  Hid attr(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT));
  if (!attr.ok()) throw StoreError("", std::string("cannot create attribute ") + name + ": " + h5_error_text());
  const char* p = value.c_str();
  if (H5Awrite(attr, type, &p) < 0)
    throw StoreError("", std::string("cannot write attribute ") + name + ": " + h5_error_text());
}

void write_i64_attr(hid_t obj, const char* name, std::int64_t value) {
  if (H5Aexists(obj, name) > 0) H5Adelete(obj, name);
  Hid space(H5Screate(H5S_SCALAR));
  Hid attr(H5Acreate2(obj, name, H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT));
  if (!attr.ok() || H5Awrite(attr, H5T_NATIVE_INT64, &value) < 0)
    throw StoreError("", std::string("cannot write attribute ") + name + ": " + h5_error_text());
}

void write_i64_list_attr(hid_t obj, const char* name, const std::vector<std::int64_t>& values) {
  if (H5Aexists(obj, name) > 0) H5Adelete(obj, name);
  hsize_t n = values.size();
  Hid space(H5Screate_simple(1, &n, nullptr));
  Hid attr(H5Acreate2(obj, name, H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT));
  if (!attr.ok() || (!values.empty() && H5Awrite(attr, H5T_NATIVE_INT64, values.data()) < 0))
    throw StoreError("", std::string("cannot write attribute ") + name + ": " + h5_error_text());
}

std::vector<std::int64_t> read_i64_list_attr(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) return {};
  Hid attr(H5Aopen(obj, name, H5P_DEFAULT));
  Hid space(H5Aget_space(attr));
  std::vector<std::int64_t> v(static_cast<std::size_t>(std::max<hssize_t>(0, H5Sget_simple_extent_npoints(space))));
  if (!v.empty() && H5Aread(attr, H5T_NATIVE_INT64, v.data()) < 0) v.clear();
  return v;
}

void write_str_list_attr(hid_t obj, const char* name, const std::vector<std::string>& values) {
  if (H5Aexists(obj, name) > 0) H5Adelete(obj, name);
  Hid type(utf8_vlen_type());
  hsize_t n = values.size();
  Hid space(H5Screate_simple(1, &n, nullptr));
  Hid attr(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT));
  if (!attr.ok()) throw StoreError("", std::string("cannot create attribute ") + name + ": " + h5_error_text());
  std::vector<const char*> ptrs;
  for (auto& v : values) ptrs.push_back(v.c_str());
  if (!values.empty() && H5Awrite(attr, type, ptrs.data()) < 0)
    throw StoreError("", std::string("cannot write attribute ") + name + ": " + h5_error_text());
}

bool has_attr(hid_t obj, const char* name) { return H5Aexists(obj, name) > 0; }

namespace {
std::vector<std::string> read_strings(hid_t attr) {
  std::vector<std::string> out;
  Hid ftype(H5Aget_type(attr));
  Hid space(H5Aget_space(attr));
  hssize_t n = H5Sget_simple_extent_npoints(space);
  if (n <= 0) return out;
  if (H5Tis_variable_str(ftype) > 0) {
    Hid mtype(utf8_vlen_type());
    VlenStrings strs(mtype, space, static_cast<std::size_t>(n));
    if (H5Aread(attr, mtype, strs.data()) < 0) return out;
    for (char* p : strs.ptrs) out.emplace_back(p ? p : "");
  } else {
    std::size_t sz = H5Tget_size(ftype);
    Hid mtype(H5Tcopy(H5T_C_S1));
    H5Tset_size(mtype, sz);
    std::vector<char> buf(sz * static_cast<std::size_t>(n));
    if (H5Aread(attr, mtype, buf.data()) < 0) return out;
    for (hssize_t i = 0; i < n; ++i) {
      const char* p = buf.data() + static_cast<std::size_t>(i) * sz;
      out.emplace_back(p, strnlen(p, sz));
    }
  }
  return out;
}
}  // namespace

std::string read_str_attr(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) return {};
  Hid attr(H5Aopen(obj, name, H5P_DEFAULT));
  auto v = read_strings(attr);
  return v.empty() ? std::string() : v.front();
}

std::int64_t read_i64_attr(hid_t obj, const char* name, std::int64_t fallback) {
  if (H5Aexists(obj, name) <= 0) return fallback;
  Hid attr(H5Aopen(obj, name, H5P_DEFAULT));
  std::int64_t v = fallback;
  if (H5Aread(attr, H5T_NATIVE_INT64, &v) < 0) return fallback;
  return v;
}

std::vector<std::string> read_str_list_attr(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) return {};
  Hid attr(H5Aopen(obj, name, H5P_DEFAULT));
  return read_strings(attr);
}

hid_t netcdf_dimension(hid_t g, const std::string& name, hsize_t n, bool unlimited) {
  if (link_exists(g, name)) return H5Dopen2(g, name.c_str(), H5P_DEFAULT);
  hsize_t max = unlimited ? H5S_UNLIMITED : n;
  Hid space(H5Screate_simple(1, &n, &max));
  Hid dcpl(H5Pcreate(H5P_DATASET_CREATE));
  if (unlimited) {
    const hsize_t chunk = 1024;
    H5Pset_chunk(dcpl, 1, &chunk);
  }
  H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER);
  hid_t d = H5Dcreate2(g, name.c_str(), H5T_IEEE_F32LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  if (d < 0) return -1;
  const std::string tag = "This is a netCDF dimension but not a netCDF variable. " + std::to_string(n);
  if (H5DSset_scale(d, tag.c_str()) < 0) {
    H5Dclose(d);
    return -1;
  }
  return d;
}

bool name_netcdf_dimensions(hid_t g, const std::string& rows, const std::string& columns) {
  H5G_info_t info{};
  if (H5Gget_info(g, &info) < 0) return false;
  std::vector<std::string> names;
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    char name[256];
    if (H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof name, H5P_DEFAULT) > 0) names.emplace_back(name);
  }
  for (const std::string& name : names) {
    H5O_info_t oi{};
    if (H5Oget_info_by_name2(g, name.c_str(), &oi, H5O_INFO_BASIC, H5P_DEFAULT) < 0 || oi.type != H5O_TYPE_DATASET) continue;
    Hid d(H5Dopen2(g, name.c_str(), H5P_DEFAULT));
    if (!d.ok() || H5DSis_scale(d) > 0 || name == rows || name == columns) continue;
    Hid space(H5Dget_space(d));
    const int rank = H5Sget_simple_extent_ndims(space);
    hsize_t dims[2] = {0, 0};
    if (rank < 1 || rank > 2 || H5Sget_simple_extent_dims(space, dims, nullptr) < 0) continue;
    Hid r(netcdf_dimension(g, rows, dims[0]));
    if (!r.ok() || H5DSattach_scale(d, r, 0) < 0) return false;
    if (rank == 1) continue;
    std::string c = columns.empty() ? name + "_column" : columns;
    hsize_t have = dims[1];
    if (link_exists(g, c)) {
      Hid e(H5Dopen2(g, c.c_str(), H5P_DEFAULT));
      Hid es(H5Dget_space(e));
      H5Sget_simple_extent_dims(es, &have, nullptr);
      if (have != dims[1]) c = name + "_column";
    }
    Hid s(netcdf_dimension(g, c, dims[1]));
    if (!s.ok() || H5DSattach_scale(d, s, 1) < 0) return false;
  }
  return true;
}

std::string axis_dataset_name(const std::string& axis) {
  for (const char* k : {"method", "tolerance", "drop", "indexers"})
    if (axis == k) return axis + "_";
  return axis;
}

hid_t open_axis_dataset(hid_t g, const std::string& axis) {
  const std::string name = axis_dataset_name(axis);
  if (link_exists(g, name)) return H5Dopen2(g, name.c_str(), H5P_DEFAULT);
  if (name != axis && link_exists(g, axis)) return H5Dopen2(g, axis.c_str(), H5P_DEFAULT);
  return -1;
}

int file_descriptor(hid_t file) {
  void* handle = nullptr;
  if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0 || !handle) return -1;
  return *static_cast<int*>(handle);
}

bool link_exists(hid_t loc, const std::string& path) { return H5Lexists(loc, path.c_str(), H5P_DEFAULT) > 0; }

std::vector<ColumnSpec> read_run_columns(hid_t file, const std::string& path, std::int64_t& n_runs,
                                         bool roles_stored) {
  Hid runs(check(H5Gopen2(file, "runs", H5P_DEFAULT), path, "open /runs"));
  n_runs = read_i64_attr(runs, "n_runs", -1);
  std::vector<ColumnSpec> columns;
  for (auto& name : read_str_list_attr(runs, "columns")) {
    Hid d(check(H5Dopen2(runs, name.c_str(), H5P_DEFAULT), path, "open /runs/" + name));
    Hid t(H5Dget_type(d));
    ColumnSpec c;
    c.name = name;
    H5T_class_t cls = H5Tget_class(t);
    c.type = cls == H5T_FLOAT ? CellType::f64 : cls == H5T_INTEGER ? CellType::i64 : CellType::str;
    if (cls == H5T_ENUM) c.labels = enum_labels(t, path, name);
    c.unit = read_str_attr(d, "unit");
    c.description = read_str_attr(d, "description");
    if (roles_stored) {
      const std::string role = read_str_attr(d, "role");
      if (!parse(role, c.role))
        throw StoreError(path, std::string(kBadColumnAttribute) + "/runs/" + name + " has role '" + role +
                                   "' (expected parameter, metric or bookkeeping)");
      if (!has_attr(d, "kinds"))
        throw StoreError(path, std::string(kBadColumnAttribute) + "/runs/" + name + " has no kinds attribute");
      c.kinds = read_str_attr(d, "kinds");
      if (has_attr(d, "display_name")) c.display_name = read_str_attr(d, "display_name");
    }
    columns.push_back(std::move(c));
  }
  return columns;
}

}  // namespace ks::store::detail
