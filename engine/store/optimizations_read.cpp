// ResultsReader::optimizations / read_optimization (see store.hpp, FORMAT.md).
#include "store/h5util.hpp"
#include "store/store.hpp"

namespace ks::store {
using namespace detail;

namespace {
struct In {
  const std::string& path;
  std::string where;

  std::vector<double> f64_attr_vec(hid_t obj, const char* name) const {
    std::vector<double> v;
    if (!has_attr(obj, name)) return v;
    Hid a(check(H5Aopen(obj, name, H5P_DEFAULT), path, "open attribute " + where + "/" + name));
    Hid s(H5Aget_space(a));
    const hssize_t n = H5Sget_simple_extent_npoints(s);
    if (n <= 0 || H5Sget_simple_extent_type(s) == H5S_NULL) return v;
    v.resize(static_cast<std::size_t>(n));
    check(H5Aread(a, H5T_NATIVE_DOUBLE, v.data()), path, "read attribute " + where + "/" + name);
    return v;
  }
  double f64_attr(hid_t obj, const char* name) const {
    auto v = f64_attr_vec(obj, name);
    return v.empty() ? std::numeric_limits<double>::quiet_NaN() : v.front();
  }
  /// A dataset's values and its column count (1 for 1-D).
  std::vector<double> f64(hid_t g, const std::string& name, std::size_t* cols = nullptr) const {
    Hid d(check(H5Dopen2(g, name.c_str(), H5P_DEFAULT), path, "open " + where + "/" + name));
    Hid s(H5Dget_space(d));
    hsize_t dims[2] = {0, 1};
    const int rank = H5Sget_simple_extent_dims(s, dims, nullptr);
    if (cols) *cols = rank == 2 ? dims[1] : 1;
    std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
    if (!v.empty()) check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path, "read " + where + "/" + name);
    return v;
  }
  std::vector<std::int64_t> i64(hid_t g, const std::string& name) const {
    Hid d(check(H5Dopen2(g, name.c_str(), H5P_DEFAULT), path, "open " + where + "/" + name));
    Hid s(H5Dget_space(d));
    std::vector<std::int64_t> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
    if (!v.empty()) check(H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path, "read " + where + "/" + name);
    return v;
  }
  std::vector<std::string> str(hid_t g, const std::string& name) const {
    Hid d(check(H5Dopen2(g, name.c_str(), H5P_DEFAULT), path, "open " + where + "/" + name));
    Hid s(H5Dget_space(d));
    const hssize_t n = H5Sget_simple_extent_npoints(s);
    return read_vlen_strings(d, H5S_ALL, H5S_ALL, n > 0 ? static_cast<std::size_t>(n) : 0, path,
                             "read " + where + "/" + name);
  }
};
}  // namespace

std::vector<std::string> ResultsReader::optimizations() const {
  QuietHdf5 quiet;
  std::vector<std::string> out;
  const hid_t f = static_cast<hid_t>(raw_file_id());
  if (!link_exists(f, "optimizations")) return out;
  Hid g(check(H5Gopen2(f, "optimizations", H5P_DEFAULT), raw_path(), "open /optimizations"));
  H5G_info_t info{};
  H5Gget_info(g, &info);
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t len = H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
    if (len < 0) continue;
    std::string name(static_cast<std::size_t>(len) + 1, '\0');
    H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size(), H5P_DEFAULT);
    name.resize(static_cast<std::size_t>(len));
    out.push_back(std::move(name));
  }
  return out;
}

OptimizationRecord ResultsReader::read_optimization(const std::string& name) const {
  QuietHdf5 quiet;
  const hid_t f = static_cast<hid_t>(raw_file_id());
  const std::string& path = raw_path();
  const std::string gp = "optimizations/" + name;
  if (name.empty() || name.find('/') != std::string::npos || !link_exists(f, "optimizations") || !link_exists(f, gp))
    throw StoreError(path, "no optimization '" + name + "'");
  In in{path, "/" + gp};
  Hid g(check(H5Gopen2(f, gp.c_str(), H5P_DEFAULT), path, "open /" + gp));
  OptimizationRecord r;
  r.name = name;
  r.kind = read_str_attr(g, "kind");
  r.preset = read_str_attr(g, "preset");
  r.objective = read_str_attr(g, "objective");
  r.settings = read_str_attr(g, "settings");
  r.variables = read_str_list_attr(g, "variables");
  r.units = read_str_list_attr(g, "units");
  r.lower = in.f64_attr_vec(g, "lower");
  r.upper = in.f64_attr_vec(g, "upper");
  r.best_objective = in.f64_attr(g, "best_objective");
  r.best_x = in.f64_attr_vec(g, "best_x");
  r.best_status = read_str_attr(g, "best_status");
  r.best_stage = read_str_attr(g, "best_stage");
  r.wall_time_s = in.f64_attr(g, "wall_time");
  r.seed = read_i64_attr(g, "seed", 0);
  for (const auto& k : read_str_list_attr(g, "references"))
    r.reference.emplace_back(k, in.f64_attr(g, ("reference_" + k).c_str()));
  {
    Hid e(check(H5Gopen2(g, "evaluations", H5P_DEFAULT), path, "open /" + gp + "/evaluations"));
    in.where = "/" + gp + "/evaluations";
    r.x = in.f64(e, "x");
    r.value = in.f64(e, "objective");
    r.constraint = in.f64(e, "constraint");
    r.stage = in.str(e, "stage");
    r.status = in.str(e, "status");
    r.start = in.i64(e, "start");
  }
  {
    Hid s(check(H5Gopen2(g, "stages", H5P_DEFAULT), path, "open /" + gp + "/stages"));
    in.where = "/" + gp + "/stages";
    const auto name_ = in.str(s, "name"), alg = in.str(s, "algorithm"), res = in.str(s, "result"),
               st = in.str(s, "best_status");
    const auto wall = in.f64(s, "wall_time"), best = in.f64(s, "best_objective"), bx = in.f64(s, "best_x");
    const auto ev = in.i64(s, "evaluations");
    const std::size_t d = r.variables.size();
    for (std::size_t i = 0; i < name_.size(); ++i) {
      OptimizationStage x;
      x.name = name_[i]; x.algorithm = alg[i]; x.result = res[i]; x.best_status = st[i];
      x.wall_time_s = wall[i]; x.best_objective = best[i]; x.evaluations = ev[i];
      if (bx.size() >= (i + 1) * d) x.best_x.assign(bx.begin() + i * d, bx.begin() + (i + 1) * d);
      r.stages.push_back(std::move(x));
    }
  }
  {
    Hid l(check(H5Gopen2(g, "local", H5P_DEFAULT), path, "open /" + gp + "/local"));
    in.where = "/" + gp + "/local";
    r.local_from = in.f64(l, "from");
    r.local_to = in.f64(l, "to");
    r.local_value = in.f64(l, "objective");
  }
  {
    Hid b(check(H5Gopen2(g, "best", H5P_DEFAULT), path, "open /" + gp + "/best"));
    in.where = "/" + gp + "/best";
    for (const auto& k : read_str_list_attr(b, "metrics")) r.best_metrics.emplace_back(k, in.f64_attr(b, k.c_str()));
    Hid h(check(H5Gopen2(b, "history", H5P_DEFAULT), path, "open /" + gp + "/best/history"));
    in.where = "/" + gp + "/best/history";
    for (const auto& a : read_str_list_attr(h, "arrays")) {
      HistoryArray arr;
      arr.name = a;
      arr.data = in.f64(h, a, &arr.cols);
      arr.rows = arr.cols ? arr.data.size() / arr.cols : 0;
      Hid d(check(H5Dopen2(h, a.c_str(), H5P_DEFAULT), path, "open " + in.where + "/" + a));
      arr.unit = read_str_attr(d, "unit");
      r.history.arrays.push_back(std::move(arr));
    }
  }
  return r;
}

}  // namespace ks::store
