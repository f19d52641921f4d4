// ResultsWriter::open_for_resume (see store.hpp, FORMAT.md "Creation, overwrite, resume"), and the
// typed column reads by which a resumed sweep or a merge counts the runs a file already holds.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <vector>

#include "store/h5util.hpp"
#include "store/journal/format.hpp"
#include "store/journal/vfd.hpp"
#include "store/label_columns.hpp"
#include "store/runs_read.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"

namespace ks::store {
using namespace detail;

namespace {

/// The root attributes that decide whether a file can be resumed.
struct FormatStamp {
  std::string format, engine_version;
  std::int64_t version = -1;
};

FormatStamp read_format_stamp(hid_t file) {
  return {read_str_attr(file, "format"), read_str_attr(file, "engine_version"),
          read_i64_attr(file, "format_version", -1)};
}

/// Throws StoreError unless `s` is a kinesweep results file of a format this kinesweep resumes: one
/// whose layout it writes as it is (a format 3 file keeps its text columns as strings).
void require_resumable_format(const std::string& path, const FormatStamp& s) {
  if (s.format != kFormatName)
    throw StoreError(path, "not a kinesweep results file (attribute format != kinesweep-results)");
  if (s.version >= kOldestResumableFormatVersion && s.version <= kFormatVersion) return;
  const std::string v = "v" + std::to_string(kOldestResumableFormatVersion) + " to v" + std::to_string(kFormatVersion);
  std::string m = "results file format v" + std::to_string(s.version) + " (written by kinesweep " +
                  (s.engine_version.empty() ? std::string("?") : s.engine_version) + "); this kinesweep resumes " + v;
  if (s.version < kFormatVersion) m += ": rerun with --overwrite";
  else m += ": resume it with the kinesweep that wrote it, or rerun with --overwrite";
  throw StoreError(path, m);
}

/// Checks the format read-only, before anything opens the file for writing (which would touch it).
/// A file that does not open read-only is refused untouched unless the journal beside it acts on the
/// file (recovers it, or makes the writer's open refuse it untouched: the check after the recovering
/// open below catches the rest). A journal that holds nothing of the file (empty, cut within its
/// header) does not save a file that is no results file.
void check_format_read_only(const std::string& path) {
  Hid f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
  if (!f.ok()) {
    H5Eclear2(H5E_DEFAULT);
    if (journal_acts_on_open(path)) return;
    if (::access(path.c_str(), R_OK | W_OK) != 0) throw StoreError(path, std::string("cannot resume: ") + std::strerror(errno));
    struct stat fs{};
    const long long bytes = ::stat(path.c_str(), &fs) == 0 ? static_cast<long long>(fs.st_size) : -1;
    throw StoreError(path, "not a kinesweep results file (not an HDF5 file" +
                               (bytes >= 0 ? ", " + std::to_string(bytes) + " bytes" : std::string()) +
                               "); nothing was written");
  }
  const FormatStamp s = read_format_stamp(f);
  // Root attributes that do not read as a results file's while a journal acts on the file: the file
  // may have been changed after its writer stopped, which the recovering open reports as such.
  if (s.format != kFormatName && journal_acts_on_open(path)) return;
  require_resumable_format(path, s);
}

std::string lower(std::string s) {
  for (auto& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

}  // namespace

void require_resumable(const std::string& path, const StoreMeta& meta) {
  require_resumable_format(path, {meta.format, meta.engine_version, meta.format_version});
}

std::string ResultsWriter::recorded_histories() const {
  QuietHdf5 quiet;
  return read_str_attr(impl_->file, "histories");
}

ResultsWriter::Resumed ResultsWriter::open_for_resume(const std::string& path, const std::string& expected_sha256,
                                                      const StoreOptions& options) {
  QuietHdf5 quiet;
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) throw StoreError(path, std::string("cannot resume: ") + std::strerror(errno));
  if (!journal_has_pending_commit(path)) check_format_read_only(path);
  auto impl = open_writer_impl(path, options);
  journal::remove_orphans(path);  // a killed creation's or overwrite's temporary file (its process is gone)
  hid_t f = impl->file;
  require_resumable_format(path, read_format_stamp(f));
  const std::string sha = read_str_attr(f, "study_sha256");
  if (lower(sha) != lower(expected_sha256))
    throw StoreError(path, "study sha256 mismatch: the file was written for study " + sha +
                               ", the study given now has " + expected_sha256 + " (refusing to resume)");
  impl->columns = read_run_columns(f, path, impl->n_runs, true);
  impl->open_objects();
  if (impl->n_runs < 0) impl->n_runs = H5Sget_simple_extent_npoints(Hid(H5Dget_space(impl->done_dset)));
  impl->done.assign(static_cast<std::size_t>(impl->n_runs), false);
  {  // /runs/done into one bit per run, read in pieces (memory bounded whatever the run count)
    constexpr hsize_t kPiece = hsize_t{1} << 16;
    const hsize_t n = static_cast<hsize_t>(impl->n_runs);
    std::vector<std::uint8_t> piece(static_cast<std::size_t>(std::min(n, kPiece)));
    Hid fs(check(H5Dget_space(impl->done_dset), path, "read /runs/done"));
    for (hsize_t first = 0; first < n; first += kPiece) {
      hsize_t count = std::min(kPiece, n - first);
      Hid ms(check(H5Screate_simple(1, &count, nullptr), path, "read /runs/done"));
      check(H5Sselect_hyperslab(fs, H5S_SELECT_SET, &first, nullptr, &count, nullptr), path, "read /runs/done");
      check(H5Dread(impl->done_dset, H5T_NATIVE_UINT8, ms, fs, H5P_DEFAULT, piece.data()), path, "read /runs/done");
      for (hsize_t i = 0; i < count; ++i)
        if (piece[static_cast<std::size_t>(i)]) impl->done[static_cast<std::size_t>(first + i)] = true;
    }
  }
  impl->count_chunk_done();
  Resumed r;
  r.writer = std::unique_ptr<ResultsWriter>(new ResultsWriter(std::move(impl)));
  return r;
}

namespace {
/// The column named `name` of `m` (its index), or StoreError.
std::size_t column_of(const ResultsWriter::Impl& m, const std::string& name) {
  for (std::size_t c = 0; c < m.columns.size(); ++c)
    if (m.columns[c].name == name) return c;
  throw StoreError(m.path, "no /runs column '" + name + "'");
}
}  // namespace

std::vector<double> ResultsWriter::read_numbers(const std::string& column, std::int64_t first, std::int64_t count) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  const std::size_t c = column_of(m, column);
  if (m.columns[c].type == CellType::str) throw StoreError(m.path, "/runs column '" + column + "' holds text");
  first = std::clamp<std::int64_t>(first, 0, m.n_runs);
  count = std::clamp<std::int64_t>(count, 0, m.n_runs - first);
  m.write_rows();
  m.runs_chunks.write_partial();
  const RowSelection sel{static_cast<hsize_t>(first), static_cast<hsize_t>(count)};
  if (m.columns[c].type == CellType::f64) return read_runs_column<double>(m.file, m.path, column, H5T_NATIVE_DOUBLE, sel);
  const auto v = read_runs_column<std::int64_t>(m.file, m.path, column, H5T_NATIVE_INT64, sel);
  return std::vector<double>(v.begin(), v.end());
}

std::vector<std::uint16_t> ResultsWriter::read_codes(const std::string& column, std::int64_t first, std::int64_t count) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  const std::size_t c = column_of(m, column);
  if (m.columns[c].labels.empty()) throw StoreError(m.path, "/runs column '" + column + "' has no labels");
  first = std::clamp<std::int64_t>(first, 0, m.n_runs);
  count = std::clamp<std::int64_t>(count, 0, m.n_runs - first);
  m.write_rows();
  m.runs_chunks.write_partial();
  return read_label_codes(m.file, m.path, column, {static_cast<hsize_t>(first), static_cast<hsize_t>(count)});
}


}  // namespace ks::store
