// TableOut / TableIn: the column datasets of a table group (store/table_group.hpp).
#include "store/table_group.hpp"

#include <algorithm>

namespace ks::store::detail {

Hid replace_group(ResultsWriter::Impl& m, const char* name, const std::string& description) {
  m.usable();
  m.touched = true;
  if (link_exists(m.file, name)) {
    if (H5Ldelete(m.file, name, H5P_DEFAULT) < 0) m.fail(std::string("cannot replace /") + name);
    m.freed_space = true;
  }
  Hid g(H5Gcreate2(m.file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!g.ok()) m.fail(std::string("cannot create /") + name);
  write_str_attr(g, "description", description);
  return g;
}

void TableOut::f64_attr(hid_t obj, const char* name, const std::vector<double>& v) {
  hsize_t n = v.size();
  Hid space(n ? H5Screate_simple(1, &n, nullptr) : H5Screate(H5S_NULL));
  if (H5Aexists(obj, name) > 0) H5Adelete(obj, name);
  Hid a(H5Acreate2(obj, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT));
  if (!a.ok() || (n && H5Awrite(a, H5T_NATIVE_DOUBLE, v.data()) < 0)) m.fail("cannot write attribute " + where + "/" + name);
}

void TableOut::f64_attr(hid_t obj, const char* name, double v) {
  Hid space(H5Screate(H5S_SCALAR));
  if (H5Aexists(obj, name) > 0) H5Adelete(obj, name);
  Hid a(H5Acreate2(obj, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT));
  if (!a.ok() || H5Awrite(a, H5T_NATIVE_DOUBLE, &v) < 0) m.fail("cannot write attribute " + where + "/" + name);
}

void TableOut::f64(hid_t g, const std::string& name, const std::vector<double>& v, std::size_t cols,
                   const std::string& unit, const std::string& desc) {
  const std::size_t rows = cols ? (v.empty() ? 0 : v.size() / cols) : v.size();
  hsize_t dims[2] = {rows, cols};
  Hid space(H5Screate_simple(cols ? 2 : 1, dims, nullptr));
  Hid dcpl(H5Pcreate(H5P_DATASET_CREATE));
  if (v.size() >= 4096) {
    hsize_t chunk[2] = {std::min<hsize_t>(rows, 65536), cols};
    H5Pset_chunk(dcpl, cols ? 2 : 1, chunk);
    H5Pset_shuffle(dcpl);
    H5Pset_deflate(dcpl, 1);
  }
  Hid d(H5Dcreate2(g, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT));
  if (!d.ok() || (!v.empty() && H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0))
    m.fail("cannot write " + where + "/" + name);
  write_str_attr(d, "unit", unit);
  write_cf_units(d, unit, cols);
  write_str_attr(d, "description", desc);
}

void TableOut::i64(hid_t g, const std::string& name, const std::vector<std::int64_t>& v, const std::string& desc) {
  hsize_t n = v.size();
  Hid space(H5Screate_simple(1, &n, nullptr));
  Hid d(H5Dcreate2(g, name.c_str(), H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!d.ok() || (n && H5Dwrite(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0))
    m.fail("cannot write " + where + "/" + name);
  write_str_attr(d, "unit", "");
  write_str_attr(d, "description", desc);
}

void TableOut::str(hid_t g, const std::string& name, const std::vector<std::string>& v, const std::string& desc) {
  hsize_t n = v.size();
  Hid space(H5Screate_simple(1, &n, nullptr));
  Hid t(utf8_vlen_type());
  Hid d(H5Dcreate2(g, name.c_str(), t, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  std::vector<const char*> p;
  for (const auto& s : v) p.push_back(s.c_str());
  if (!d.ok() || (n && H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, p.data()) < 0))
    m.fail("cannot write " + where + "/" + name);
  write_str_attr(d, "unit", "");
  write_str_attr(d, "description", desc);
}

void TableOut::dimensions(hid_t g, const std::string& rows, const std::string& columns) {
  if (!name_netcdf_dimensions(g, rows, columns)) m.fail("cannot name the dimensions of " + where);
}

Hid TableOut::group(hid_t parent, const std::string& name) {
  Hid g(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!g.ok()) m.fail("cannot create " + where + "/" + name);
  return g;
}

std::optional<TableIn> TableIn::open(hid_t file, const std::string& path, const char* name,
                                     const char* count_column) {
  if (!link_exists(file, name)) return std::nullopt;
  const std::string where = std::string("/") + name;
  TableIn in(Hid(check(H5Gopen2(file, name, H5P_DEFAULT), path, "open " + where)), path, where);
  Hid d(check(H5Dopen2(in.g_, count_column, H5P_DEFAULT), path, "open " + where + "/" + count_column));
  Hid s(H5Dget_space(d));
  in.n_ = static_cast<std::size_t>(std::max<hssize_t>(0, H5Sget_simple_extent_npoints(s)));
  return in;
}

Hid TableIn::dataset(const char* name, std::size_t cols) const {
  Hid d(check(H5Dopen2(g_, name, H5P_DEFAULT), path_, "open " + where_ + "/" + name));
  Hid s(H5Dget_space(d));
  const hssize_t points = H5Sget_simple_extent_npoints(s);
  if (points < 0 || static_cast<std::size_t>(points) != n_ * cols)
    throw StoreError(path_, where_ + "/" + name + " holds " + std::to_string(points) + " values; expected " +
                                std::to_string(n_ * cols) + " (" + std::to_string(n_) + " rows)");
  return d;
}

std::vector<double> TableIn::f64(const char* name, std::size_t cols) const {
  Hid d = dataset(name, cols);
  std::vector<double> v(n_ * cols);
  if (!v.empty())
    check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path_, "read " + where_ + "/" + name);
  return v;
}

std::vector<std::int64_t> TableIn::i64(const char* name) const {
  Hid d = dataset(name, 1);
  std::vector<std::int64_t> v(n_);
  if (!v.empty())
    check(H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path_, "read " + where_ + "/" + name);
  return v;
}

std::vector<std::string> TableIn::str(const char* name) const {
  Hid d = dataset(name, 1);
  return read_vlen_strings(d, H5S_ALL, H5S_ALL, n_, path_, "read " + where_ + "/" + name);
}

double TableIn::attr_f64(const char* name, double fallback) const {
  if (!has_attr(g_, name)) return fallback;
  Hid a(check(H5Aopen(g_, name, H5P_DEFAULT), path_, "open " + where_ + "@" + name));
  double v = fallback;
  check(H5Aread(a, H5T_NATIVE_DOUBLE, &v), path_, "read " + where_ + "@" + name);
  return v;
}

std::int64_t TableIn::attr_i64(const char* name, std::int64_t fallback) const {
  return read_i64_attr(g_, name, fallback);
}

}  // namespace ks::store::detail
