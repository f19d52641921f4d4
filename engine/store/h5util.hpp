#pragma once
// Internal HDF5 helpers of the store (RAII ids, string attributes, error text). Only store/*.cpp.
#include <hdf5.h>

#include <string>
#include <utility>
#include <vector>

#include "store/store.hpp"

namespace ks::store::detail {

/// Owns an HDF5 id; closes it with H5Idec_ref-like semantics via H5Oclose/H5Sclose/... by type.
class Hid {
 public:
  Hid() = default;
  explicit Hid(hid_t id) : id_(id) {}
  Hid(Hid&& o) noexcept : id_(std::exchange(o.id_, -1)) {}
  Hid& operator=(Hid&& o) noexcept {
    if (this != &o) { reset(); id_ = std::exchange(o.id_, -1); }
    return *this;
  }
  ~Hid() { reset(); }
  void reset() {
    if (id_ >= 0) {
      switch (H5Iget_type(id_)) {
        case H5I_FILE: H5Fclose(id_); break;
        case H5I_GROUP: H5Gclose(id_); break;
        case H5I_DATASET: H5Dclose(id_); break;
        case H5I_DATASPACE: H5Sclose(id_); break;
        case H5I_DATATYPE: H5Tclose(id_); break;
        case H5I_ATTR: H5Aclose(id_); break;
        case H5I_GENPROP_LST: H5Pclose(id_); break;
        default: break;
      }
    }
    id_ = -1;
  }
  hid_t get() const { return id_; }
  hid_t release() { return std::exchange(id_, -1); }
  operator hid_t() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_ = -1;
};

/// Silences HDF5's automatic error printing for this thread while alive.
struct QuietHdf5 {
  H5E_auto2_t func = nullptr;
  void* data = nullptr;
  QuietHdf5() {
    H5Eget_auto2(H5E_DEFAULT, &func, &data);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, func, data); }
};

/// Owns the strings HDF5 allocates when H5Aread reads variable-length strings into `ptrs` (memory
/// type `type`, `space` the attribute's dataspace): frees them (H5Dvlen_reclaim) when it goes out of
/// scope, also when the copy into std::string throws. H5Aread takes no transfer property list, so
/// attribute reads cannot use read_vlen_strings' allocator; dataset reads use read_vlen_strings.
class VlenStrings {
 public:
  VlenStrings(hid_t type, hid_t space, std::size_t n) : type_(type), space_(space), ptrs(n, nullptr) {}
  ~VlenStrings() {
    if (!ptrs.empty()) H5Dvlen_reclaim(type_, space_, H5P_DEFAULT, ptrs.data());
  }
  VlenStrings(const VlenStrings&) = delete;
  VlenStrings& operator=(const VlenStrings&) = delete;
  void* data() { return ptrs.data(); }

 private:
  hid_t type_, space_;

 public:
  std::vector<char*> ptrs;
};

/// Reads the `n` variable-length UTF-8 strings that `file_space` selects in dataset `dset` into a
/// memory dataspace of `n` elements (`mem_space`; H5S_ALL for both: the whole dataset, which then
/// holds `n`; another size is a StoreError). A null string reads as "". Every
/// string HDF5 allocates goes through an allocator of this call that frees them all at its end, also
/// when H5Dread fails half-way: HDF5 then drops strings it converted but never copied into the
/// output buffer. Throws StoreError(path, what + HDF5's error text) when the read fails.
std::vector<std::string> read_vlen_strings(hid_t dset, hid_t mem_space, hid_t file_space, std::size_t n,
                                           const std::string& path, const std::string& what);

/// The current HDF5 error stack as one line (and clears it).
std::string h5_error_text();
/// Throws StoreError(path, what + HDF5 error text) when id < 0 / rc < 0.
hid_t check(hid_t id, const std::string& path, const std::string& what);

hid_t utf8_vlen_type();  // caller closes
/// A dataset-transfer property list (caller closes; negative on failure) whose type-conversion
/// buffer holds `n` converted elements of at most `element_bytes` each. Without it every H5Dread or
/// H5Dwrite that converts (variable-length strings do) allocates and zeroes HDF5's default 1 MiB,
/// whatever the number of elements.
hid_t conversion_transfer(std::size_t n, std::size_t element_bytes);
/// conversion_transfer() for `n` variable-length strings (16 bytes each in memory and in the file).
hid_t string_transfer(std::size_t n);
void write_str_attr(hid_t obj, const char* name, const std::string& value);
void write_i64_attr(hid_t obj, const char* name, std::int64_t value);
void write_i64_list_attr(hid_t obj, const char* name, const std::vector<std::int64_t>& values);
std::vector<std::int64_t> read_i64_list_attr(hid_t obj, const char* name);  // empty when absent
void write_str_list_attr(hid_t obj, const char* name, const std::vector<std::string>& values);
bool has_attr(hid_t obj, const char* name);
/// The CF `units` (UDUNITS-2) of an engine unit label: "Nm" -> "N m", "1/s" -> "s^-1"; "" when the
/// label has none: dimensionless (""), categorical ("labels:..."), a per-column list ("rad, rad, mm"),
/// or no UDUNITS-2 form (a half power, "problem units", "rad or mm") (cf_units.cpp).
std::string cf_units(const std::string& unit);
/// The CF units of each of `cols` columns of a per-column label ("rad, rad, mm"); empty unless every
/// column has one.
std::vector<std::string> cf_column_units(const std::string& unit, std::size_t cols);
/// Writes `units` on dataset `d` (cf_units of `unit`, or the one unit all its `cols` columns share)
/// or, when the columns differ, `column_units` (one UDUNITS-2 string per column); nothing otherwise.
void write_cf_units(hid_t d, const std::string& unit, std::size_t cols = 1);
std::string read_str_attr(hid_t obj, const char* name);  // "" when absent
std::int64_t read_i64_attr(hid_t obj, const char* name, std::int64_t fallback);
std::vector<std::string> read_str_list_attr(hid_t obj, const char* name);
bool link_exists(hid_t loc, const std::string& path);
/// A netCDF dimension without a coordinate variable, as netCDF-4 stores one: a dimension scale
/// `name` of length `n` in group `g` whose NAME says "This is a netCDF dimension but not a netCDF
/// variable." (never written: it takes no space; `unlimited`: extendible, H5Dset_extent it with
/// the datasets it measures). Returns it (the one there when `g` already has it), or -1.
hid_t netcdf_dimension(hid_t g, const std::string& name, hsize_t n, bool unlimited = false);
/// Names the dimensions of every dataset of group `g` (not its subgroups) for netCDF readers:
/// dimension 0 of each is `rows` (created with the length of the first such dataset when absent),
/// dimension 1 `columns` or, when that is empty or of another length, `<dataset>_column`.
/// Datasets that are dimension scales are left alone. False on an HDF5 failure.
bool name_netcdf_dimensions(hid_t g, const std::string& rows, const std::string& columns = "");

/// The dataset (and dimension) name of landscape axis `axis`: the axis name, with "_" appended when
/// it is a keyword of xarray's Dataset.sel (method, tolerance, drop, indexers), so that
/// ds.sel(method_=...) selects along it (ds.sel(method=...) would be taken as sel's own argument).
std::string axis_dataset_name(const std::string& axis);
/// Landscape axis `axis` of group `g`: its dataset under axis_dataset_name, or under the axis name
/// (files written before the rename). -1 when neither exists.
hid_t open_axis_dataset(hid_t g, const std::string& axis);
/// The file descriptor of an open HDF5 file (its driver's handle: the sec2 and journal drivers hold
/// one), or -1.
int file_descriptor(hid_t file);
/// The /runs column specs (name, type, unit, description, and with `roles_stored` role and kinds) in
/// file order, and the n_runs attribute (-1 when absent). Format 1 files store no role/kinds: pass
/// false, and their columns keep the ColumnSpec defaults. Throws StoreError naming `path` when a
/// column cannot be opened, or (roles_stored) has no valid role attribute or no kinds attribute.
std::vector<ColumnSpec> read_run_columns(hid_t file, const std::string& path, std::int64_t& n_runs,
                                         bool roles_stored);
/// Makes /runs/run_id the dimension scale of every other /runs dataset (netCDF readers such as
/// xarray then see one dimension, run_id, with the run ids as its coordinate); nothing when /runs
/// has no run_id column (designs.cpp).
void attach_run_scale(hid_t runs, const std::string& path);
/// Writes /designs/<block> for each of `designs` (none: no /designs) (designs.cpp).
void write_designs(hid_t file, const std::vector<DesignMeta>& designs, const std::string& path);
/// Causes of StoreErrors that re-reading cannot cure (the reader gives up at once on them).
inline constexpr const char* kBadColumnAttribute = "bad column attribute: ";

}  // namespace ks::store::detail
