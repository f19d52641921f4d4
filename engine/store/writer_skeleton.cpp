// ResultsWriter::create's first step: a new results file's skeleton (FORMAT.md): the root
// attributes, /study, the /runs columns with their attributes and dimension scale, /kinds,
// /designs, and the empty /histories and /landscapes groups.
#include <unistd.h>

#include <ctime>
#include <limits>

#include "store/h5util.hpp"
#include "store/label_columns.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"

namespace ks::store::detail {

std::string& engine_commit() {
  static std::string commit;
  return commit;
}

std::string now_iso8601() {
  std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

namespace {

hid_t file_type_of(CellType t) {
  switch (t) {
    case CellType::f64: return H5Tcopy(H5T_IEEE_F64LE);
    case CellType::i64: return H5Tcopy(H5T_STD_I64LE);
    default: return utf8_vlen_type();
  }
}

}  // namespace

void build_skeleton(hid_t file, const std::string& path, const StoreMeta& meta,
                    const std::vector<ColumnSpec>& columns, std::int64_t n_runs) {
  write_str_attr(file, "Conventions", kConventions);
  write_str_attr(file, "format", kFormatName);
  write_i64_attr(file, "format_version", kFormatVersion);
  write_str_attr(file, "engine_version", meta.engine_version);
  if (!engine_commit().empty()) write_str_attr(file, "engine_commit", engine_commit());
  write_str_attr(file, "study_sha256", meta.study_sha256);
  write_str_attr(file, "created", meta.created.empty() ? now_iso8601() : meta.created);
  write_str_attr(file, "study_name", meta.study_name);
  if (!meta.histories.empty()) write_str_attr(file, "histories", meta.histories);
  if (!meta.command_line.empty()) write_str_attr(file, "command_line", meta.command_line);
  char host[256] = {};
  if (meta.host.empty() && ::gethostname(host, sizeof host - 1) != 0) host[0] = 0;
  write_str_attr(file, "host", meta.host.empty() ? std::string(host) : meta.host);

  Hid study(check(H5Gcreate2(file, "study", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /study"));
  write_str_attr(study, "path", meta.study_path);
  {
    Hid type(utf8_vlen_type());
    Hid space(H5Screate(H5S_SCALAR));
    Hid d(check(H5Dcreate2(study, "text", type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path,
                "create /study/text"));
    const char* p = meta.study_text.c_str();
    check(H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &p), path, "write /study/text");
  }
  if (!meta.robot_text.empty()) {  // the URDF the runs used, so the file is complete without it
    Hid type(utf8_vlen_type());
    Hid space(H5Screate(H5S_SCALAR));
    Hid d(check(H5Dcreate2(study, "robot", type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path,
                "create /study/robot"));
    const char* p = meta.robot_text.c_str();
    check(H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &p), path, "write /study/robot");
    write_str_attr(d, "path", meta.robot_path);
  }

  Hid runs(check(H5Gcreate2(file, "runs", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /runs"));
  std::vector<std::string> names;
  for (auto& c : columns) names.push_back(c.name);
  write_str_list_attr(runs, "columns", names);
  write_i64_attr(runs, "n_runs", n_runs);
  hsize_t n = static_cast<hsize_t>(n_runs);
  Hid space(H5Screate_simple(1, &n, nullptr));
  auto make = [&](const ColumnSpec& c, hid_t ftype, hid_t mtype, const void* fill, const char* type_attr) {
    Hid dcpl(H5Pcreate(H5P_DATASET_CREATE));
    if (H5Tis_variable_str(ftype) > 0 || n == 0) {  // heap references: nothing to compress
      H5Pset_layout(dcpl, H5D_CONTIGUOUS);
      H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY);  // rows live at fixed addresses from creation on
      H5Pset_fill_time(dcpl, H5D_FILL_TIME_ALLOC);
    } else {  // chunks of kRunsChunkRows rows, shuffled and deflated (or raw: runs_chunks.hpp)
      const hsize_t rows = std::min<hsize_t>(n, kRunsChunkRows);
      H5Pset_chunk(dcpl, 1, &rows);
      H5Pset_shuffle(dcpl);
      H5Pset_deflate(dcpl, 1);
      H5Pset_fill_time(dcpl, H5D_FILL_TIME_IFSET);
    }
    if (fill) H5Pset_fill_value(dcpl, H5Tget_class(ftype) == H5T_ENUM ? ftype : mtype, fill);
    Hid d(check(H5Dcreate2(runs, c.name.c_str(), ftype, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), path,
                "create /runs/" + c.name));
    write_str_attr(d, "unit", c.unit);
    write_cf_units(d, c.unit);
    write_str_attr(d, "description", c.description);
    write_str_attr(d, "type", type_attr);
    write_str_attr(d, "role", std::string(to_string(c.role)));
    write_str_attr(d, "kinds", c.kinds);
    if (!c.display_name.empty()) write_str_attr(d, "display_name", c.display_name);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::int64_t minus1 = -1;
  for (auto& c : columns) {
    if (c.type == CellType::str && !c.labels.empty()) {  // few distinct values: an enum (missing: no member)
      Hid ft(check(enum_file_type(c.labels), path, "enum type of /runs/" + c.name));
      // committed (named) in the root group: netCDF-4 readers map only named types
      check(H5Tcommit2(file, enum_type_name(c.name).c_str(), ft, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path,
            "commit the enum type of /runs/" + c.name);
      const std::uint16_t missing = enum_file_missing(c.labels.size());
      make(c, ft, H5T_NATIVE_UINT16, &missing, "str");
      Hid d(check(H5Dopen2(runs, c.name.c_str(), H5P_DEFAULT), path, "open /runs/" + c.name));
      write_enum_attributes(d, c.labels, path);
      continue;
    }
    Hid ft(file_type_of(c.type));
    switch (c.type) {
      case CellType::f64: make(c, ft, H5T_NATIVE_DOUBLE, &nan, "f64"); break;
      case CellType::i64: {  // -1: missing, which CF readers learn from _FillValue
        make(c, ft, H5T_NATIVE_INT64, &minus1, "i64");
        if (c.name == "run_id") break;  // a coordinate: no fill value (CF), never missing in a run's row
        Hid d(check(H5Dopen2(runs, c.name.c_str(), H5P_DEFAULT), path, "open /runs/" + c.name));
        write_i64_attr(d, "_FillValue", minus1);
        break;
      }
      case CellType::str: make(c, ft, ft, nullptr, "str"); break;  // null = ""
    }
  }
  const std::uint8_t zero = 0;
  const ColumnSpec done{"done", CellType::i64 /* stored as u8: the arguments below */, "",
                        "1: the run's row and history are committed; 0: not done (the row holds missing values, or "
                        "values whose done flag was not committed before a crash; resume rewrites it)",
                        Role::bookkeeping, ""};
  make(done, H5T_STD_U8LE, H5T_NATIVE_UINT8, &zero, "u8");
  attach_run_scale(runs, path);

  if (!meta.kinds.empty()) {
    Hid kinds(check(H5Gcreate2(file, "kinds", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /kinds"));
    for (const KindMeta& k : meta.kinds) {
      Hid g(check(H5Gcreate2(kinds, k.name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path,
                  "create /kinds/" + k.name));
      for (const auto& [attr, values] : k.lists) write_str_list_attr(g, attr.c_str(), values);
    }
  }
  write_designs(file, meta.designs, path);
  Hid h(check(H5Gcreate2(file, "histories", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /histories"));
  Hid l(check(H5Gcreate2(file, "landscapes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /landscapes"));
}

}  // namespace ks::store::detail

namespace ks::store {
void set_engine_commit(std::string commit) { detail::engine_commit() = std::move(commit); }
}  // namespace ks::store
