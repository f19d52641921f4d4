// ResultsWriter::write_verification / ResultsReader::read_verification: /verification, the grid
// studies of a file's best runs (see store.hpp, FORMAT.md).
#include <limits>

#include "store/h5util.hpp"
#include "store/reader_impl.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"

namespace ks::store {
using namespace detail;

namespace {
constexpr const char* kGroup = "verification";

/// Writes one dataset of the group (1-D, or rows x 3 for the per-grid figures).
struct Out {
  ResultsWriter::Impl& m;
  hid_t g;
  void f64(const char* name, const std::vector<double>& v, std::size_t cols, const std::string& unit,
           const std::string& desc) {
    const hsize_t dims[2] = {cols ? v.size() / cols : v.size(), cols};
    Hid space(H5Screate_simple(cols ? 2 : 1, dims, nullptr));
    Hid d(H5Dcreate2(g, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    if (!d.ok() || (!v.empty() && H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0))
      m.fail(std::string("cannot write /verification/") + name);
    write_str_attr(d, "unit", unit);
    write_cf_units(d, unit);
    write_str_attr(d, "description", desc);
  }
  void i64(const char* name, const std::vector<std::int64_t>& v, const std::string& desc) {
    const hsize_t n = v.size();
    Hid space(H5Screate_simple(1, &n, nullptr));
    Hid d(H5Dcreate2(g, name, H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    if (!d.ok() || (n && H5Dwrite(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0))
      m.fail(std::string("cannot write /verification/") + name);
    write_str_attr(d, "unit", "");
    write_str_attr(d, "description", desc);
  }
  void str(const char* name, const std::vector<std::string>& v, const std::string& desc) {
    const hsize_t n = v.size();
    Hid space(H5Screate_simple(1, &n, nullptr));
    Hid t(utf8_vlen_type());
    Hid d(H5Dcreate2(g, name, t, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    std::vector<const char*> p;
    for (const auto& s : v) p.push_back(s.c_str());
    if (!d.ok() || (n && H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, p.data()) < 0))
      m.fail(std::string("cannot write /verification/") + name);
    write_str_attr(d, "unit", "");
    write_str_attr(d, "description", desc);
  }
};

template <class F>
std::vector<double> per_grid(const std::vector<VerificationRow>& rows, F field) {
  std::vector<double> v;
  for (const auto& r : rows)
    for (double x : field(r)) v.push_back(x);
  return v;
}
}  // namespace

void ResultsWriter::write_verification(const VerificationTable& t) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  m.touched = true;
  if (link_exists(m.file, kGroup)) {
    if (H5Ldelete(m.file, kGroup, H5P_DEFAULT) < 0) m.fail("cannot replace /verification");
    m.freed_space = true;
  }
  Hid g(H5Gcreate2(m.file, kGroup, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!g.ok()) m.fail("cannot create /verification");
  write_str_attr(g, "description",
                 "grid convergence of the best runs: each row one quantity of one run computed at three grids "
                 "(1 finest, 3 the run as stored) and Roache's grid convergence index");
  {
    Hid space(H5Screate(H5S_SCALAR));
    Hid a(H5Acreate2(g, "safety_factor", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT));
    if (!a.ok() || H5Awrite(a, H5T_NATIVE_DOUBLE, &t.safety_factor) < 0) m.fail("cannot write /verification@safety_factor");
  }
  const auto& rows = t.rows;
  auto strings = [&](auto field) {
    std::vector<std::string> v;
    for (const auto& r : rows) v.push_back(field(r));
    return v;
  };
  auto numbers = [&](auto field) {
    std::vector<double> v;
    for (const auto& r : rows) v.push_back(field(r));
    return v;
  };
  Out o{m, g};
  std::vector<std::int64_t> run;
  for (const auto& r : rows) run.push_back(r.run);
  o.i64("run", run, "the run id (row of /runs)");
  o.str("block", strings([](auto& r) { return r.block; }), "the run's block");
  o.str("method", strings([](auto& r) { return r.method; }), "the run's method");
  o.str("group", strings([](auto& r) { return r.group; }), "what the run is the best of (column=value, ...)");
  o.str("quantity", strings([](auto& r) { return r.quantity; }), "the /runs metric verified");
  o.str("quantity_unit", strings([](auto& r) { return r.unit; }), "its unit (of value and extrapolated)");
  o.str("refinement", strings([](auto& r) { return r.refinement; }), "dt (dt, dt/2, dt/4) or knots (K, 2K, 4K)");
  o.f64("ratio", numbers([](auto& r) { return r.ratio; }), 0, "", "refinement ratio r between consecutive grids");
  o.f64("dt", per_grid(rows, [](auto& r) { return r.dt; }), 3, "s", "time step per grid (1 finest .. 3 as stored)");
  o.f64("knots", per_grid(rows, [](auto& r) { return r.knots; }), 3, "",
        "spline knots per grid (1 finest .. 3 as stored); NaN for methods without knots");
  o.f64("value", per_grid(rows, [](auto& r) { return r.value; }), 3, "",
        "the quantity per grid (1 finest .. 3 as stored; unit: quantity_unit); NaN when the run failed");
  {
    std::vector<std::string> s[3];
    for (const auto& r : rows)
      for (int k = 0; k < 3; ++k) s[k].push_back(r.status[static_cast<std::size_t>(k)]);
    o.str("status_1", s[0], "the run's status on grid 1 (finest)");
    o.str("status_2", s[1], "the run's status on grid 2");
    o.str("status_3", s[2], "the run's status on grid 3 (as stored)");
  }
  o.str("convergence", strings([](auto& r) { return r.convergence; }),
        "monotone | unchanged | oscillatory | divergent | not_enough");
  o.f64("order", numbers([](auto& r) { return r.order; }), 0, "", "observed order p (monotone only; else NaN)");
  o.f64("extrapolated", numbers([](auto& r) { return r.extrapolated; }), 0, "",
        "Richardson extrapolation of the grid-converged value (unit: quantity_unit; monotone, unchanged)");
  o.f64("gci_fine", numbers([](auto& r) { return r.gci_fine; }), 0, "",
        "grid convergence index of grid 1, relative (0.01 = 1 %)");
  o.f64("gci_coarse", numbers([](auto& r) { return r.gci_coarse; }), 0, "",
        "grid convergence index of grid 3, the run as stored, relative (0.01 = 1 %)");
  if (!name_netcdf_dimensions(g, "verification_row", "grid")) m.fail("cannot name the dimensions of /verification");
  m.do_flush();
}

VerificationTable ResultsReader::read_verification() const {
  QuietHdf5 quiet;
  VerificationTable t;
  const hid_t f = impl_->file;
  const std::string& path = impl_->path;
  if (!link_exists(f, kGroup)) return t;
  Hid g(check(H5Gopen2(f, kGroup, H5P_DEFAULT), path, "open /verification"));
  if (has_attr(g, "safety_factor")) {
    Hid a(check(H5Aopen(g, "safety_factor", H5P_DEFAULT), path, "open /verification@safety_factor"));
    check(H5Aread(a, H5T_NATIVE_DOUBLE, &t.safety_factor), path, "read /verification@safety_factor");
  }
  std::size_t n = 0;
  auto open = [&](const char* name, std::size_t cols) {
    Hid d(check(H5Dopen2(g, name, H5P_DEFAULT), path, std::string("open /verification/") + name));
    Hid s(H5Dget_space(d));
    const hssize_t points = H5Sget_simple_extent_npoints(s);
    if (points < 0 || static_cast<std::size_t>(points) != n * cols)
      throw StoreError(path, std::string("/verification/") + name + " holds " + std::to_string(points) +
                                 " values; expected " + std::to_string(n * cols) + " (" + std::to_string(n) + " rows)");
    return d;
  };
  std::vector<std::int64_t> run;
  {
    Hid d(check(H5Dopen2(g, "run", H5P_DEFAULT), path, "open /verification/run"));
    Hid s(H5Dget_space(d));
    n = static_cast<std::size_t>(std::max<hssize_t>(0, H5Sget_simple_extent_npoints(s)));
    run.resize(n);
    if (n) check(H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, run.data()), path, "read /verification/run");
  }
  auto f64 = [&](const char* name, std::size_t cols) {
    Hid d = open(name, cols);
    std::vector<double> v(n * cols);
    if (!v.empty())
      check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path,
            std::string("read /verification/") + name);
    return v;
  };
  auto str = [&](const char* name) {
    Hid d = open(name, 1);
    return read_vlen_strings(d, H5S_ALL, H5S_ALL, n, path, std::string("read /verification/") + name);
  };
  const auto block = str("block"), method = str("method"), group = str("group"), quantity = str("quantity"),
             unit = str("quantity_unit"), refinement = str("refinement"), convergence = str("convergence"),
             s1 = str("status_1"), s2 = str("status_2"), s3 = str("status_3");
  const auto ratio = f64("ratio", 1), dt = f64("dt", 3), knots = f64("knots", 3), value = f64("value", 3),
             order = f64("order", 1), extrapolated = f64("extrapolated", 1), gci_fine = f64("gci_fine", 1),
             gci_coarse = f64("gci_coarse", 1);
  for (std::size_t i = 0; i < n; ++i) {
    VerificationRow r;
    r.run = run[i], r.block = block[i], r.method = method[i], r.group = group[i], r.quantity = quantity[i];
    r.unit = unit[i], r.refinement = refinement[i], r.convergence = convergence[i];
    r.status = {s1[i], s2[i], s3[i]};
    r.ratio = ratio[i];
    for (std::size_t k = 0; k < 3; ++k) r.dt[k] = dt[3 * i + k], r.knots[k] = knots[3 * i + k], r.value[k] = value[3 * i + k];
    r.order = order[i], r.extrapolated = extrapolated[i], r.gci_fine = gci_fine[i], r.gci_coarse = gci_coarse[i];
    t.rows.push_back(std::move(r));
  }
  return t;
}

}  // namespace ks::store
