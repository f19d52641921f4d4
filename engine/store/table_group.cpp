// TableOut / TableIn: the column datasets of a table group (store/table_group.hpp).
#include "store/table_group.hpp"

#include <algorithm>

namespace ks::store::detail {

Hid replace_group(ResultsWriter::Impl& m, const char* name) {
  if (link_exists(m.file, name)) {
    if (H5Ldelete(m.file, name, H5P_DEFAULT) < 0) m.fail(std::string("cannot replace /") + name);
    m.freed_space = true;
  }
  Hid g(H5Gcreate2(m.file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!g.ok()) m.fail(std::string("cannot create /") + name);
  return g;
}

void TableOut::f64(const char* name, const std::vector<double>& v, std::size_t cols, const std::string& unit,
                   const std::string& desc) {
  const hsize_t dims[2] = {cols ? v.size() / cols : v.size(), cols};
  Hid space(H5Screate_simple(cols ? 2 : 1, dims, nullptr));
  Hid d(H5Dcreate2(g, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!d.ok() || (!v.empty() && H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0))
    m.fail("cannot write " + group + "/" + name);
  write_str_attr(d, "unit", unit);
  write_cf_units(d, unit);
  write_str_attr(d, "description", desc);
}

void TableOut::i64(const char* name, const std::vector<std::int64_t>& v, const std::string& desc) {
  const hsize_t n = v.size();
  Hid space(H5Screate_simple(1, &n, nullptr));
  Hid d(H5Dcreate2(g, name, H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!d.ok() || (n && H5Dwrite(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0))
    m.fail("cannot write " + group + "/" + name);
  write_str_attr(d, "unit", "");
  write_str_attr(d, "description", desc);
}

void TableOut::str(const char* name, const std::vector<std::string>& v, const std::string& desc) {
  const hsize_t n = v.size();
  Hid space(H5Screate_simple(1, &n, nullptr));
  Hid t(utf8_vlen_type());
  Hid d(H5Dcreate2(g, name, t, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  std::vector<const char*> p;
  for (const auto& s : v) p.push_back(s.c_str());
  if (!d.ok() || (n && H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, p.data()) < 0))
    m.fail("cannot write " + group + "/" + name);
  write_str_attr(d, "unit", "");
  write_str_attr(d, "description", desc);
}

void TableOut::attr_f64(const char* name, double v) {
  Hid space(H5Screate(H5S_SCALAR));
  Hid a(H5Acreate2(g, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT));
  if (!a.ok() || H5Awrite(a, H5T_NATIVE_DOUBLE, &v) < 0) m.fail("cannot write " + group + "@" + name);
}

void TableOut::attr_i64(const char* name, std::int64_t v) { write_i64_attr(g, name, v); }

TableIn::TableIn(hid_t g_, const std::string& path_, const std::string& group_, const char* count_column)
    : g(g_), path(path_), group(group_) {
  Hid d(check(H5Dopen2(g, count_column, H5P_DEFAULT), path, "open " + group + "/" + count_column));
  Hid s(H5Dget_space(d));
  n = static_cast<std::size_t>(std::max<hssize_t>(0, H5Sget_simple_extent_npoints(s)));
}

Hid TableIn::open(const char* name, std::size_t cols) const {
  Hid d(check(H5Dopen2(g, name, H5P_DEFAULT), path, "open " + group + "/" + name));
  Hid s(H5Dget_space(d));
  const hssize_t points = H5Sget_simple_extent_npoints(s);
  if (points < 0 || static_cast<std::size_t>(points) != n * cols)
    throw StoreError(path, group + "/" + name + " holds " + std::to_string(points) + " values; expected " +
                               std::to_string(n * cols) + " (" + std::to_string(n) + " rows)");
  return d;
}

std::vector<double> TableIn::f64(const char* name, std::size_t cols) const {
  Hid d = open(name, cols);
  std::vector<double> v(n * cols);
  if (!v.empty())
    check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path, "read " + group + "/" + name);
  return v;
}

std::vector<std::int64_t> TableIn::i64(const char* name) const {
  Hid d = open(name, 1);
  std::vector<std::int64_t> v(n);
  if (!v.empty())
    check(H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path, "read " + group + "/" + name);
  return v;
}

std::vector<std::string> TableIn::str(const char* name) const {
  Hid d = open(name, 1);
  return read_vlen_strings(d, H5S_ALL, H5S_ALL, n, path, "read " + group + "/" + name);
}

double TableIn::attr_f64(const char* name, double fallback) const {
  if (!has_attr(g, name)) return fallback;
  Hid a(check(H5Aopen(g, name, H5P_DEFAULT), path, "open " + group + "@" + name));
  double v = fallback;
  check(H5Aread(a, H5T_NATIVE_DOUBLE, &v), path, "read " + group + "@" + name);
  return v;
}

std::int64_t TableIn::attr_i64(const char* name, std::int64_t fallback) const {
  return read_i64_attr(g, name, fallback);
}

}  // namespace ks::store::detail
