// ResultsReader (see store.hpp, FORMAT.md).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "store/checked_read_vfd.hpp"
#include "store/h5util.hpp"
#include "store/journal/vfd.hpp"
#include "store/reader_impl.hpp"
#include "store/runs_read.hpp"
#include "store/store.hpp"

namespace ks::store {
using namespace detail;

namespace {
/// The UTF-8 text of scalar dataset `name` in `group` ("" when it holds a null string).
std::string read_text_dataset(hid_t group, const char* name, const std::string& path) {
  const std::string what = std::string("/study/") + name;
  Hid d(check(H5Dopen2(group, name, H5P_DEFAULT), path, "open " + what));
  return read_vlen_strings(d, H5S_ALL, H5S_ALL, 1, path, "read " + what)[0];
}
}  // namespace

void ResultsReader::Impl::load() {
  hid_t f = file;
  meta.format = read_str_attr(f, "format");
  if (meta.format != kFormatName)
    throw StoreError(path, "not a kinesweep results file (attribute format = '" + meta.format + "')");
  meta.format_version = read_i64_attr(f, "format_version", -1);
  meta.engine_version = read_str_attr(f, "engine_version");
  if (meta.format_version < kOldestReadableFormatVersion || meta.format_version > kFormatVersion)
    throw StoreError(path, "unsupported format_version " + std::to_string(meta.format_version) +
                               " (written by kinesweep " + meta.engine_version + "; this kinesweep reads " +
                               std::to_string(kOldestReadableFormatVersion) + " to " +
                               std::to_string(kFormatVersion) + ")");
  meta.study_sha256 = read_str_attr(f, "study_sha256");
  meta.created = read_str_attr(f, "created");
  meta.study_name = read_str_attr(f, "study_name");
  meta.histories = read_str_attr(f, "histories");
  Hid study(check(H5Gopen2(f, "study", H5P_DEFAULT), path, "open /study"));
  meta.study_path = read_str_attr(study, "path");
  meta.study_text = read_text_dataset(study, "text", path);
  if (H5Lexists(study, "robot", H5P_DEFAULT) > 0) {
    meta.robot_text = read_text_dataset(study, "robot", path);
    Hid d(check(H5Dopen2(study, "robot", H5P_DEFAULT), path, "open /study/robot"));
    meta.robot_path = read_str_attr(d, "path");
  }
  columns = read_run_columns(f, path, n_runs, meta.format_version >= 2);
  if (meta.format_version == 1 && v1_roles) v1_roles(columns);
  meta.kinds = read_kind_meta(f, path);
  if (n_runs < 0) {
    Hid d(check(H5Dopen2(f, "runs/done", H5P_DEFAULT), path, "open /runs/done"));
    n_runs = H5Sget_simple_extent_npoints(Hid(H5Dget_space(d)));
  }
}

namespace {
/// True when `before`, the consistency stamp taken before a failed open, is that of a file without a
/// journal (no writer) and the file is still as it was: the failure is the file's, not a writer's commit
/// landing under the read.
bool unchanged_without_writer(const std::string& path, const std::string& before) {
  return before.rfind("static:", 0) == 0 && consistency_stamp(path) == before;
}
}  // namespace

ResultsReader::ResultsReader(const std::string& path, V1ColumnRoles v1_roles) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->v1_roles = std::move(v1_roles);
  refresh();
}

void ResultsReader::refresh() {
  QuietHdf5 quiet;
  const std::string path = impl_->path;
  impl_->hist.reset();
  impl_->file.reset();
  if (::access(path.c_str(), F_OK) != 0) throw StoreError(path, "no such file");
  if (H5Fis_hdf5(path.c_str()) == 0)  // a readable file that is no HDF5 file at all (a study file, ...)
    throw StoreError(path, "not an HDF5 file (expected a kinesweep results file, as written by kinesweep run)");
  // Never writes: no lock, no replay, no truncation, no deletion (FORMAT.md, "Crash safety").
  // Open between two commits of a live writer: the same consistency stamp before and after.
  std::string last;
  for (int attempt = 0; attempt < 100; ++attempt) {
    if (attempt) ::usleep(attempt < 10 ? 2000 : 20000);
    const std::string before = consistency_stamp(path);
    if (before.empty()) { last = "no such file"; continue; }
    const ReadView view = read_view(path);
    if (view.kind == ReadView::refuse) {
      last = "its journal " + journal_path(path) + " holds a commit that does not match the file (" + view.why +
             "): the file was changed after its writer stopped; delete the journal to read the file as it is";
      if (consistency_stamp(path) == before) throw StoreError(path, "not read: " + last);
      continue;  // a live writer moved on meanwhile
    }
    Hid fapl(view.kind == ReadView::overlay ? make_journal_read_fapl() : make_checked_read_fapl());
    hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl);
    if (f < 0) {
      last = h5_error_text();
      if (view.kind == ReadView::overlay && !journal_last_error().empty()) last = journal_last_error();
      if (unchanged_without_writer(path, before)) break;  // a damaged file: reading again cannot cure it
      continue;
    }
    impl_->file = Hid(f);
    impl_->overlay = view.kind == ReadView::overlay;
    try {
      impl_->columns.clear();
      impl_->meta = StoreMeta{};
      impl_->load();
    } catch (const StoreError& e) {
      last = e.cause();
      impl_->file.reset();
      if (e.cause().rfind("not a kinesweep", 0) == 0 || e.cause().rfind("unsupported", 0) == 0 ||
          e.cause().rfind(kBadColumnAttribute, 0) == 0)
        throw;  // re-reading cannot cure these
      if (unchanged_without_writer(path, before)) break;
      continue;
    }
    impl_->stamp = before;
    // On the last try the open is kept anyway: unchanged_since_open() then tells the caller.
    if (consistency_stamp(path) == before || attempt == 99) return;
    impl_->file.reset();  // a commit happened meanwhile: open again
  }
  throw StoreError(path, "cannot open for reading: " + last);
}

bool ResultsReader::unchanged_since_open() const {
  return !impl_->stamp.empty() && consistency_stamp(impl_->path) == impl_->stamp;
}

ResultsReader::~ResultsReader() = default;

const StoreMeta& ResultsReader::meta() const { return impl_->meta; }
const std::vector<ColumnSpec>& ResultsReader::columns() const { return impl_->columns; }
std::int64_t ResultsReader::n_runs() const { return impl_->n_runs; }

std::vector<std::uint8_t> ResultsReader::done_mask(std::int64_t first, std::int64_t count) const {
  QuietHdf5 quiet;
  return read_runs_column<std::uint8_t>(impl_->file, impl_->path, "done", H5T_NATIVE_UINT8, impl_->range(first, count));
}
std::vector<double> ResultsReader::read_f64(const std::string& name, std::int64_t first, std::int64_t count) const {
  QuietHdf5 quiet;
  impl_->typed(name, CellType::f64);
  return read_runs_column<double>(impl_->file, impl_->path, name, H5T_NATIVE_DOUBLE, impl_->range(first, count));
}
std::vector<std::int64_t> ResultsReader::read_i64(const std::string& name, std::int64_t first,
                                                  std::int64_t count) const {
  QuietHdf5 quiet;
  impl_->typed(name, CellType::i64);
  return read_runs_column<std::int64_t>(impl_->file, impl_->path, name, H5T_NATIVE_INT64, impl_->range(first, count));
}
std::vector<std::string> ResultsReader::read_str(const std::string& name, std::int64_t first,
                                                 std::int64_t count) const {
  QuietHdf5 quiet;
  impl_->typed(name, CellType::str);
  return read_runs_strings(impl_->file, impl_->path, name, impl_->range(first, count));
}

std::vector<Cell> ResultsReader::read_column(const std::string& name) const {
  std::vector<Cell> out;
  switch (impl_->column(name).type) {
    case CellType::f64: for (double v : read_f64(name)) out.emplace_back(v); break;
    case CellType::i64: for (std::int64_t v : read_i64(name)) out.emplace_back(v); break;
    case CellType::str: for (auto& v : read_str(name)) out.emplace_back(std::move(v)); break;
  }
  return out;
}

std::vector<Record> ResultsReader::read_rows(std::int64_t first, std::int64_t count) const {
  QuietHdf5 quiet;
  return read_runs_rows(impl_->file, impl_->path, impl_->columns, impl_->range(first, count));
}
std::vector<Record> ResultsReader::read_rows(const std::vector<std::int64_t>& ids) const {
  QuietHdf5 quiet;
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (ids[i] < 0 || ids[i] >= impl_->n_runs || (i && ids[i] <= ids[i - 1]))
      throw StoreError(impl_->path, "run ids to read must ascend within 0.." + std::to_string(impl_->n_runs - 1));
  RowSelection sel;
  sel.ids = &ids;
  return read_runs_rows(impl_->file, impl_->path, impl_->columns, sel);
}

Record ResultsReader::read_record(std::int64_t run_id) const {
  if (run_id < 0 || run_id >= impl_->n_runs) throw StoreError(impl_->path, "run id out of range");
  return std::move(read_rows(run_id, 1).front());
}

namespace {
herr_t collect_names(hid_t, const char* name, const H5L_info_t*, void* data) {
  static_cast<std::vector<std::string>*>(data)->emplace_back(name);
  return 0;
}
}  // namespace

std::int64_t ResultsReader::raw_file_id() const { return impl_->file; }  // for optimizations_read.cpp
bool ResultsReader::bytes_are_committed_state() const { return !impl_->overlay; }
const std::string& ResultsReader::raw_path() const { return impl_->path; }

std::vector<std::string> ResultsReader::landscapes() const {
  QuietHdf5 quiet;
  std::vector<std::string> out;
  if (!link_exists(impl_->file, "landscapes")) return out;
  Hid g(check(H5Gopen2(impl_->file, "landscapes", H5P_DEFAULT), impl_->path, "open /landscapes"));
  H5Literate(g, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_names, &out);
  return out;
}

LandscapeSpec ResultsReader::read_landscape(const std::string& block, bool grids) const {
  QuietHdf5 quiet;
  LandscapeSpec spec;
  spec.block = block;
  const std::string gp = "landscapes/" + block;
  if (!link_exists(impl_->file, "landscapes") || !link_exists(impl_->file, gp))
    throw StoreError(impl_->path, "no landscape '" + block + "'");
  Hid g(check(H5Gopen2(impl_->file, gp.c_str(), H5P_DEFAULT), impl_->path, "open /" + gp));
  auto read_all = [&](const std::string& name) {
    Hid d(check(H5Dopen2(g, name.c_str(), H5P_DEFAULT), impl_->path, "open /" + gp + "/" + name));
    Hid s(H5Dget_space(d));
    std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
    if (!v.empty())
      check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), impl_->path, "read " + name);
    Hid type(H5Dget_type(d));
    if (H5Tget_class(type) == H5T_INTEGER)  // a grid of codes (format 5): -1 is no code
      for (double& x : v)
        if (x == -1.0) x = std::numeric_limits<double>::quiet_NaN();
    return std::make_pair(std::move(v), read_str_attr(d, "unit"));
  };
  auto read_axis = [&](const std::string& name) {
    Hid d(check(open_axis_dataset(g, name), impl_->path, "open /" + gp + "/" + axis_dataset_name(name)));
    Hid s(H5Dget_space(d));
    std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
    if (!v.empty())
      check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), impl_->path, "read " + name);
    LandscapeAxis a{name, read_str_attr(d, "unit"), std::move(v)};
    if (has_attr(d, "parameters"))  // a sampled dimension (format 5): its parameters along it
      for (auto& p : read_str_list_attr(d, "parameters")) a.coordinates.push_back(LandscapeAxis{p, "", {}});
    return a;
  };
  for (auto& name : read_str_list_attr(g, "axes")) {
    LandscapeAxis a = read_axis(name);
    for (LandscapeAxis& c : a.coordinates) c = read_axis(c.name);
    spec.axes.push_back(std::move(a));
  }
  // every metric grid holds one value per cell of the axes' grid
  std::uint64_t cells = 1;
  for (const auto& a : spec.axes)
    cells = a.values.empty() || cells <= UINT64_MAX / a.values.size() ? cells * a.values.size() : UINT64_MAX;
  for (auto& name : read_str_list_attr(g, "metrics")) {
    {
      Hid d(check(H5Dopen2(g, name.c_str(), H5P_DEFAULT), impl_->path, "open /" + gp + "/" + name));
      Hid s(H5Dget_space(d));
      const hssize_t n = H5Sget_simple_extent_npoints(s);
      if (n < 0 || static_cast<std::uint64_t>(n) != cells)
        throw StoreError(impl_->path, "/" + gp + "/" + name + " has " + std::to_string(n) + " cells; its axes make " +
                                          std::to_string(cells));
      if (!grids) {
        spec.metrics.push_back({name, read_str_attr(d, "unit"), read_str_attr(d, "description"), {}});
        continue;
      }
    }
    auto [v, unit] = read_all(name);
    Hid d(H5Dopen2(g, name.c_str(), H5P_DEFAULT));
    spec.metrics.push_back({name, unit, read_str_attr(d, "description"), std::move(v)});
  }
  return spec;
}

}  // namespace ks::store
