#pragma once
// A group of column datasets that form one table (/verification, /sensitivity): each column a 1-D
// dataset of the table's rows (or rows x cols for per-grid figures) with unit and description
// attributes. TableOut writes them into a group the writer has just created; TableIn reads them
// back, checking each column's size against the row count.
#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "store/h5util.hpp"
#include "store/writer_impl.hpp"

namespace ks::store::detail {

/// The values of `field` over `rows`, in order: one column of a table group.
template <class Row, class F>
auto column_of(const std::vector<Row>& rows, F field) {
  std::vector<std::decay_t<decltype(field(rows.front()))>> v;
  v.reserve(rows.size());
  for (const Row& r : rows) v.push_back(field(r));
  return v;
}

/// Group `name` at the file's root with its `description` attribute, created empty: an existing one
/// is deleted first (its space marked freed). Fails the writer (m.fail) when HDF5 refuses.
Hid replace_group(ResultsWriter::Impl& m, const char* name, const std::string& description);

/// Writes datasets and attributes of the groups under `where` ("/verification", "/optimizations/x",
/// named in error messages); every failure fails the writer (m.fail).
struct TableOut {
  ResultsWriter::Impl& m;
  std::string where;
  /// `v`: rows (cols == 0: a 1-D dataset) or rows x cols values, row by row; chunked, shuffled and
  /// deflated from 4096 values on.
  void f64(hid_t g, const std::string& name, const std::vector<double>& v, std::size_t cols, const std::string& unit,
           const std::string& desc);
  void i64(hid_t g, const std::string& name, const std::vector<std::int64_t>& v, const std::string& desc);
  void str(hid_t g, const std::string& name, const std::vector<std::string>& v, const std::string& desc);
  /// An attribute of `obj` (a scalar, or a 1-D array; an empty one has a null dataspace), replaced
  /// when present.
  void f64_attr(hid_t obj, const char* name, double v);
  void f64_attr(hid_t obj, const char* name, const std::vector<double>& v);
  /// netCDF dimensions of the datasets of `g` (name_netcdf_dimensions).
  void dimensions(hid_t g, const std::string& rows, const std::string& columns = "");
  /// A new group `name` in `parent`.
  Hid group(hid_t parent, const std::string& name);
};

/// Reads the columns of a table group at the file's root; the row count is the length of the
/// column named when it is opened. Throws StoreError for a missing column or one of another size.
class TableIn {
 public:
  /// Group `name` ("verification") of `file` (at `path`), or nothing when the file has none.
  static std::optional<TableIn> open(hid_t file, const std::string& path, const char* name, const char* count_column);
  std::size_t rows() const { return n_; }
  hid_t group() const { return g_; }
  std::vector<double> f64(const char* name, std::size_t cols = 1) const;
  std::vector<std::int64_t> i64(const char* name) const;
  std::vector<std::string> str(const char* name) const;
  /// A scalar attribute of the group, or `fallback` when it has none.
  double attr_f64(const char* name, double fallback) const;
  std::int64_t attr_i64(const char* name, std::int64_t fallback) const;

 private:
  TableIn(Hid g, const std::string& path, const std::string& where) : g_(std::move(g)), path_(path), where_(where) {}
  Hid dataset(const char* name, std::size_t cols) const;
  Hid g_;
  std::string path_, where_;
  std::size_t n_ = 0;
};

}  // namespace ks::store::detail
