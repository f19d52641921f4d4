// ResultsWriter: file creation and the /runs columns, rows and commits (see store.hpp, FORMAT.md).
// Histories, landscapes and encode_history: writer_histories.cpp; resume: writer_resume.cpp.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include "store/h5util.hpp"
#include "store/journal/format.hpp"
#include "store/journal/vfd.hpp"
#include "store/label_columns.hpp"
#include "store/runs_read.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"

namespace ks::store {
using namespace detail;

// ------------------------------------------------------------------------------------------------
// struct ResultsWriter::Impl: store/writer_impl.hpp (shared with writer_histories.cpp,
// writer_resume.cpp and optimizations.cpp)

namespace detail {

void validate_name(const std::string& path, const std::string& name, const std::string& what) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos)
    throw StoreError(path, "invalid " + what + " name '" + name + "' (empty, '.', '..' or contains '/')");
}

void set_format(hid_t fapl) { H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_V18); }

std::unique_ptr<ResultsWriter::Impl> open_writer_impl(const std::string& path, const StoreOptions& opt) {
  auto impl = std::make_unique<ResultsWriter::Impl>();
  impl->path = path;
  impl->opt = opt;
  Hid fapl(make_journal_fapl(opt.durable));
  set_format(fapl);
  H5Eclear2(H5E_DEFAULT);
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl);
  if (f < 0) {
    std::string cause = "cannot open for writing: ";
    std::string j = journal_last_error();
    cause += j.empty() ? h5_error_text() : j;
    H5Eclear2(H5E_DEFAULT);
    throw StoreError(path, cause);
  }
  impl->file = Hid(f);
  return impl;
}

}  // namespace detail

namespace {

const char* type_word(CellType t) { return t == CellType::f64 ? "f64" : t == CellType::i64 ? "i64" : "str"; }

std::string join_labels(const std::vector<std::string>& labels) {
  std::string out;
  for (std::size_t i = 0; i < labels.size() && i < 12; ++i) out += (i ? ", " : "") + labels[i];
  return labels.size() > 12 ? out + ", ..." : out;
}

void fsync_path(const std::string& p, bool dir) {
  int fd = ::open(p.c_str(), (dir ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
  if (fd >= 0) { ::fsync(fd); ::close(fd); }
}

}  // namespace

void ResultsWriter::Impl::open_objects() {
  runs = Hid(check(H5Gopen2(file, "runs", H5P_DEFAULT), path, "open /runs"));
  histories = Hid(check(H5Gopen2(file, "histories", H5P_DEFAULT), path, "open /histories"));
  landscapes = Hid(check(H5Gopen2(file, "landscapes", H5P_DEFAULT), path, "open /landscapes"));
  done_dset = Hid(check(H5Dopen2(runs, "done", H5P_DEFAULT), path, "open /runs/done"));
  if (n_runs < 0) n_runs = H5Sget_simple_extent_npoints(Hid(H5Dget_space(done_dset)));  // no n_runs attribute
  open_histories();
  col_dsets.clear();
  encoders.clear();
  chunk_col.assign(columns.size(), -1);
  std::vector<hid_t> chunked;
  std::vector<std::size_t> sizes;
  hsize_t chunk_rows = 0;
  Hid dapl(H5Pcreate(H5P_DATASET_ACCESS));
  H5Pset_chunk_cache(dapl, 0, 0, 1.0);  // chunks are gathered and written by runs_chunks, never cached
  for (std::size_t i = 0; i < columns.size(); ++i) {
    const ColumnSpec& c = columns[i];
    col_dsets.emplace_back(check(H5Dopen2(runs, c.name.c_str(), dapl), path, "open /runs/" + c.name));
    encoders.emplace_back(c.type == CellType::str && !c.labels.empty() ? LabelEncoder(c.labels) : LabelEncoder());
    Hid dcpl(H5Dget_create_plist(col_dsets.back()));
    hsize_t rows = 0;
    if (H5Pget_layout(dcpl) != H5D_CHUNKED || H5Pget_chunk(dcpl, 1, &rows) != 1) continue;
    if (chunk_rows != 0 && rows != chunk_rows) throw StoreError(path, "/runs columns with different chunk sizes");
    chunk_rows = rows;
    chunk_col[i] = static_cast<int>(chunked.size());
    chunked.push_back(col_dsets.back());
    sizes.push_back(H5Tget_size(Hid(H5Dget_type(col_dsets.back()))));
  }
  runs_chunks.clear();
  if (!chunked.empty()) runs_chunks.open(std::move(chunked), std::move(sizes), chunk_rows, static_cast<hsize_t>(n_runs), path);
}

void ResultsWriter::Impl::count_chunk_done() {
  chunk_done.clear();
  if (!runs_chunks.active()) return;
  const hsize_t cr = runs_chunks.chunk_rows();
  chunk_done.assign(static_cast<std::size_t>((static_cast<hsize_t>(n_runs) + cr - 1) / cr), 0);
  for (std::size_t id = 0; id < done.size(); ++id)
    if (done[id]) ++chunk_done[id / cr];
}

std::unique_ptr<ResultsWriter> ResultsWriter::create(const std::string& path, const StoreMeta& meta,
                                                     const std::vector<ColumnSpec>& columns, std::int64_t n_runs,
                                                     const StoreOptions& options) {
  QuietHdf5 quiet;
  namespace fs = std::filesystem;
  if (n_runs < 0) throw StoreError(path, "negative number of runs");
  std::set<std::string> seen;
  for (auto& c : columns) {
    validate_name(path, c.name, "column");
    if (c.name == "done") throw StoreError(path, "column name 'done' is reserved for /runs/done");
    if (!seen.insert(c.name).second) throw StoreError(path, "duplicate column '" + c.name + "'");
    if (c.type == CellType::str && !c.labels.empty() && !enum_storable(c.labels))
      throw StoreError(path, "column '" + c.name + "': its labels must be 1 to 65534 distinct, non-empty names");
  }
  struct stat st{};
  const bool replaces = ::stat(path.c_str(), &st) == 0;
  if (replaces) {
    if (S_ISDIR(st.st_mode)) throw StoreError(path, "is a directory");
    if (!options.overwrite) throw StoreError(path, "file exists (pass overwrite to replace it)");
  }
  fs::path p(path);
  std::string dir = p.parent_path().empty() ? std::string(".") : p.parent_path().string();
  static std::atomic<unsigned> counter{0};
  journal::remove_orphans(path);  // a killed creation's temporary file (its process is gone)
  const std::string tmp = (fs::path(dir) / ("." + p.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                                            "-" + std::to_string(counter++)))
                              .string();
  {  // a clear errno-based cause for unwritable or missing directories
    int fd = ::open(tmp.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0644);
    if (fd < 0) {
      int e = errno;
      throw StoreError(path, "cannot create a file in directory '" + dir + "': " + std::strerror(e));
    }
    ::close(fd);
  }
  try {
    Hid fcpl(H5Pcreate(H5P_FILE_CREATE));
    H5Pset_istore_k(fcpl, 32);  // chunk B-tree nodes of 64 entries (the history datasets' many chunks)
    Hid fapl(H5Pcreate(H5P_FILE_ACCESS));
    set_format(fapl);
    Hid f(check(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, fcpl, fapl), path, "cannot create " + tmp));
    try {
      build_skeleton(f, path, meta, columns, n_runs);
    } catch (const StoreError& e) {
      throw StoreError(path, e.cause());
    }
    if (H5Fclose(f.release()) < 0) throw StoreError(path, "cannot write " + tmp + ": " + h5_error_text());
    if (options.durable) fsync_path(tmp, false);  // against power loss only: a killed process loses nothing
    if (replaces && options.overwrite) {
      auto impl = open_aside(path, tmp, options);  // writer_aside.cpp
      impl->columns = columns;
      impl->n_runs = n_runs;
      impl->done.assign(static_cast<std::size_t>(n_runs), false);
      impl->open_objects();
      impl->count_chunk_done();
      impl->touched = true;
      impl->content = n_runs == 0;  // complete as created: placed at its first commit
      return std::unique_ptr<ResultsWriter>(new ResultsWriter(std::move(impl)));
    }
    if (!options.overwrite && ::stat(path.c_str(), &st) == 0)
      throw StoreError(path, "file exists (pass overwrite to replace it)");
    // The writer lock, held while the new file is put into place: the journal of a file we replace
    // (or an orphan) must never touch the new file, and only the lock's holder deletes a journal.
    const std::string jp = journal_path(path);
    const int lock = journal::acquire_lock(jp, [](int) { return true; });
    if (lock < 0) throw StoreError(path, journal_last_error());
    struct Unlock {
      int fd;
      ~Unlock() { ::close(fd); }
    } unlock{lock};
    ::unlink(jp.c_str());
    if (options.overwrite) {
      if (::rename(tmp.c_str(), path.c_str()) != 0)
        throw StoreError(path, std::string("cannot rename temporary file into place: ") + std::strerror(errno));
    } else {
      if (::link(tmp.c_str(), path.c_str()) != 0) {  // atomic "create if absent"
        int e = errno;
        if (e == EEXIST) throw StoreError(path, "file exists (pass overwrite to replace it)");
        if (::stat(path.c_str(), &st) == 0) throw StoreError(path, "file exists (pass overwrite to replace it)");
        if (::rename(tmp.c_str(), path.c_str()) != 0)  // file systems without hard links
          throw StoreError(path, std::string("cannot move temporary file into place: ") + std::strerror(errno));
      }
      ::unlink(tmp.c_str());
    }
    if (options.durable) fsync_path(dir, true);
  } catch (...) {
    ::unlink(tmp.c_str());
    throw;
  }
  auto impl = open_writer_impl(path, options);
  impl->columns = columns;
  impl->n_runs = n_runs;
  impl->done.assign(static_cast<std::size_t>(n_runs), false);
  impl->open_objects();
  impl->count_chunk_done();
  impl->touched = true;
  return std::unique_ptr<ResultsWriter>(new ResultsWriter(std::move(impl)));
}


ResultsWriter::ResultsWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ResultsWriter::~ResultsWriter() {
  if (!impl_ || impl_->closed) return;
  try {
    close();
  } catch (...) {
  }
}

const std::string& ResultsWriter::path() const { return impl_->path; }
const std::vector<ColumnSpec>& ResultsWriter::columns() const { return impl_->columns; }
std::int64_t ResultsWriter::n_runs() const { return impl_->n_runs; }
bool ResultsWriter::is_done(std::int64_t id) const {
  return id >= 0 && id < impl_->n_runs && impl_->done[static_cast<std::size_t>(id)];
}
std::size_t ResultsWriter::pending() const { return impl_->pending.size() + impl_->unflagged.size(); }

std::vector<Record> ResultsWriter::read_rows(std::int64_t first, std::int64_t count) {
  QuietHdf5 quiet;
  impl_->usable();
  if (first < 0 || count < 0) throw StoreError(impl_->path, "negative row range");
  first = std::min(first, impl_->n_runs);
  count = std::min(count, impl_->n_runs - first);
  impl_->write_rows();
  impl_->runs_chunks.write_partial();
  return read_runs_rows(impl_->file, impl_->path, impl_->columns,
                        {static_cast<hsize_t>(first), static_cast<hsize_t>(count)});
}


void ResultsWriter::write_run(std::int64_t run_id, const Record& record, const RunHistory& history, int level) {
  write_run(run_id, record, encode_history(history, level));
}

void ResultsWriter::write_run(std::int64_t run_id, const Record& record, const EncodedHistory& history) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  m.touched = true;
  m.content = true;
  if (run_id < 0 || run_id >= m.n_runs)
    throw StoreError(m.path, "run id " + std::to_string(run_id) + " outside 0.." + std::to_string(m.n_runs - 1));
  if (record.cells.size() != m.columns.size())
    throw StoreError(m.path, "run " + std::to_string(run_id) + ": record has " + std::to_string(record.cells.size()) +
                                 " cells, schema has " + std::to_string(m.columns.size()) + " columns");
  for (std::size_t i = 0; i < m.columns.size(); ++i) {
    const auto want = m.columns[i].type;
    const bool ok = (want == CellType::f64 && std::holds_alternative<double>(record.cells[i])) ||
                    (want == CellType::i64 && std::holds_alternative<std::int64_t>(record.cells[i])) ||
                    (want == CellType::str && std::holds_alternative<std::string>(record.cells[i]));
    if (!ok)
      throw StoreError(m.path, "run " + std::to_string(run_id) + ": cell '" + m.columns[i].name +
                                   "' does not hold a " + type_word(want));
    std::uint16_t code = 0;
    if (!m.columns[i].labels.empty() && !m.encoders[i].encode(std::get<std::string>(record.cells[i]), code))
      throw StoreError(m.path, "run " + std::to_string(run_id) + ": column '" + m.columns[i].name + "' holds '" +
                                   std::get<std::string>(record.cells[i]) + "', not one of its labels (" +
                                   join_labels(m.columns[i].labels) + ")");
  }
  m.write_history(run_id, history);
  m.pending[run_id] = record;
  m.mark_done(run_id);
  // rows go to the datasets in batches as they come (uncommitted, invisible until the next commit),
  // so that the commit at the end of a sweep, which nothing overlaps, has little left to write
  if (m.pending.size() >= Impl::kRowBatch) m.write_rows();
  const bool by_count = m.opt.flush_every_runs > 0 && m.pending.size() + m.unflagged.size() >= m.opt.flush_every_runs;
  const bool by_bytes = m.uncommitted_bytes >= Impl::kMaxUncommittedBytes;
  const bool by_time =
      m.opt.flush_every_seconds > 0 &&
      std::chrono::duration<double>(std::chrono::steady_clock::now() - m.last_flush).count() >= m.opt.flush_every_seconds;
  if (by_count || by_bytes || by_time) m.do_flush();
}

namespace detail {
/// A file-space selection of the given rows (sorted, unique ids) as a union of hyperslabs, one per
/// range of consecutive ids (one range when runs arrive in order): HDF5 handles that at a small
/// fraction of the cost of a point selection of the same rows.
Hid select_rows(hid_t dset, const std::vector<hsize_t>& ids) {
  Hid fs(H5Dget_space(dset));
  H5S_seloper_t op = H5S_SELECT_SET;
  for (std::size_t i = 0; i < ids.size();) {
    std::size_t j = i + 1;
    while (j < ids.size() && ids[j] == ids[j - 1] + 1) ++j;
    const hsize_t first = ids[i], count = j - i;
    if (H5Sselect_hyperslab(fs, op, &first, nullptr, &count, nullptr) < 0) return Hid(-1);
    op = H5S_SELECT_OR;
    i = j;
  }
  return fs;
}
}  // namespace detail

void ResultsWriter::Impl::write_rows() {
  write_landscape_cells();
  write_history_index();
  if (pending.empty()) return;
  std::vector<hsize_t> ids;
  ids.reserve(pending.size());
  for (auto& [id, rec] : pending) ids.push_back(static_cast<hsize_t>(id));
  hsize_t k = ids.size();
  Hid mspace(H5Screate_simple(1, &k, nullptr));
  std::vector<unsigned char> bytes;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (chunk_col[c] >= 0) {  // gathered per chunk (runs_chunks), in the file's bytes
      const ColumnSpec& col = columns[c];
      const std::size_t size = col.type == CellType::str ? encoders[c].code_bytes() : 8;
      bytes.resize(ids.size() * size);
      unsigned char* out = bytes.data();
      for (auto& [id, rec] : pending) {
        const Cell& cell = rec.cells[c];
        if (col.type == CellType::f64) std::memcpy(out, &std::get<double>(cell), 8);
        else if (col.type == CellType::i64) std::memcpy(out, &std::get<std::int64_t>(cell), 8);
        else {
          std::uint16_t code = 0;
          encoders[c].encode(std::get<std::string>(cell), code);
          if (size == 1) *out = static_cast<unsigned char>(code);
          else std::memcpy(out, &code, 2);
        }
        out += size;
      }
      runs_chunks.set(static_cast<std::size_t>(chunk_col[c]), ids, bytes.data());
      continue;
    }
    Hid fs = select_rows(col_dsets[c], ids);
    if (fs.get() < 0) fail("select rows");
    herr_t rc = -1;
    switch (columns[c].type) {
      case CellType::f64: {
        std::vector<double> v;
        for (auto& [id, rec] : pending) v.push_back(std::get<double>(rec.cells[c]));
        rc = H5Dwrite(col_dsets[c], H5T_NATIVE_DOUBLE, mspace, fs, H5P_DEFAULT, v.data());
        break;
      }
      case CellType::i64: {
        std::vector<std::int64_t> v;
        for (auto& [id, rec] : pending) v.push_back(std::get<std::int64_t>(rec.cells[c]));
        rc = H5Dwrite(col_dsets[c], H5T_NATIVE_INT64, mspace, fs, H5P_DEFAULT, v.data());
        break;
      }
      case CellType::str: {
        if (!columns[c].labels.empty()) {  // codes, checked by write_run; written in the file's enum type
          std::vector<std::uint16_t> codes;
          codes.reserve(pending.size());
          for (auto& [id, rec] : pending) {
            std::uint16_t code = 0;
            encoders[c].encode(std::get<std::string>(rec.cells[c]), code);
            codes.push_back(code);
          }
          Hid ft(H5Dget_type(col_dsets[c]));
          Hid mt(H5Tget_native_type(ft, H5T_DIR_ASCEND));
          if (encoders[c].code_bytes() == 1) {
            std::vector<std::uint8_t> narrow(codes.begin(), codes.end());
            rc = H5Dwrite(col_dsets[c], mt, mspace, fs, H5P_DEFAULT, narrow.data());
          } else {
            rc = H5Dwrite(col_dsets[c], mt, mspace, fs, H5P_DEFAULT, codes.data());
          }
          break;
        }
        std::vector<const char*> v;
        for (auto& [id, rec] : pending) v.push_back(std::get<std::string>(rec.cells[c]).c_str());
        Hid t(utf8_vlen_type());
        Hid xfer(string_transfer(v.size()));
        if (!xfer.ok()) fail("cannot write column " + columns[c].name);
        rc = H5Dwrite(col_dsets[c], t, mspace, fs, xfer, v.data());
        break;
      }
    }
    if (rc < 0) fail("cannot write column " + columns[c].name);
  }
  if (runs_chunks.active()) {  // the chunks these rows completed: encoded and written once
    const hsize_t cr = runs_chunks.chunk_rows();
    std::vector<hsize_t> complete;
    for (hsize_t id : ids) {
      const hsize_t k = id / cr;
      const hsize_t rows = std::min(cr, static_cast<hsize_t>(n_runs) - k * cr);
      if ((complete.empty() || complete.back() != k) && chunk_done[static_cast<std::size_t>(k)] == rows)
        complete.push_back(k);
    }
    try {
      runs_chunks.write_complete(complete);
    } catch (const StoreError&) {
      fail("cannot write the chunks of /runs");
    }
  }
  std::size_t row_bytes = 1;  // the done flag, written at the commit
  for (std::size_t c = 0; c < columns.size(); ++c)  // a string: its heap reference; a label: its code
    row_bytes += columns[c].type != CellType::str ? 8 : columns[c].labels.empty() ? 16 : encoders[c].code_bytes();
  uncommitted_bytes += ids.size() * row_bytes;
  unflagged.insert(unflagged.end(), ids.begin(), ids.end());
  pending.clear();
}

void ResultsWriter::Impl::do_flush() {
  write_rows();
  for (const LandscapeStream& s : landscape_streams)
    if (s.unwritten)  // its cells hold no fill: a commit now would expose bytes that are no values
      fail("landscape " + s.block + " would be committed with " + std::to_string(s.unwritten) +
           " cells not written (a dense landscape)");
  try {
    runs_chunks.write_partial();  // incomplete chunks raw, so the commit holds every row written
  } catch (const StoreError&) {
    fail("cannot write the chunks of /runs");
  }
  if (!unflagged.empty()) {
    // 1. the rows (and, already, the histories) are committed before the done flags ...
    if (H5Fflush(file, H5F_SCOPE_LOCAL) < 0) fail("flush (commit of rows) failed");
    // 2. ... so a concurrent reader that sees done = 1 sees the row.
    if (!std::is_sorted(unflagged.begin(), unflagged.end())) std::sort(unflagged.begin(), unflagged.end());
    unflagged.erase(std::unique(unflagged.begin(), unflagged.end()), unflagged.end());
    hsize_t k = unflagged.size();
    Hid mspace(H5Screate_simple(1, &k, nullptr));
    Hid fs = select_rows(done_dset, unflagged);
    if (fs.get() < 0) fail("select rows");
    std::vector<std::uint8_t> ones(k, 1);
    if (H5Dwrite(done_dset, H5T_NATIVE_UINT8, mspace, fs, H5P_DEFAULT, ones.data()) < 0)
      fail("cannot write /runs/done");
    unflagged.clear();
  }
  if (H5Fflush(file, H5F_SCOPE_LOCAL) < 0) fail("flush (commit) failed");
  if (!aside.empty() && content) place_aside();
  uncommitted_bytes = 0;
  for (auto& s : landscape_streams) s.fresh = false;  // committed: later writes to them are journaled
  last_flush = std::chrono::steady_clock::now();
}

void ResultsWriter::flush() {
  QuietHdf5 quiet;
  impl_->usable();
  impl_->do_flush();
}


void ResultsWriter::close() {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  if (m.closed) return;
  if (m.broken) {
    m.closed = true;
    // the driver refuses to commit after an I/O error; the file keeps its last committed state
    m.runs_chunks.clear();
    m.col_dsets.clear();
    m.landscape_streams.clear();
    m.hist.close_handles();
    m.done_dset.reset(); m.runs.reset(); m.histories.reset(); m.landscapes.reset();
    H5Fclose(m.file.release());
    H5Eclear2(H5E_DEFAULT);
    if (!m.aside.empty()) m.drop_aside();  // nothing of it was placed: the previous file stays
    return;
  }
  m.trim_histories();
  if (m.touched) write_str_attr(m.file, "closed", now_iso8601());  // the end of the last session that wrote it
  m.content = true;  // closed: the file is complete as it is (placed by this last commit)
  m.do_flush();
  m.runs_chunks.clear();
  m.col_dsets.clear();
  m.landscape_streams.clear();
  m.hist.close_handles();
  m.done_dset.reset(); m.runs.reset(); m.histories.reset(); m.landscapes.reset();
  m.closed = true;
  if (H5Fclose(m.file.release()) < 0) {
    std::string cause = "close failed: " + h5_error_text();
    throw StoreError(m.path, cause);
  }
}

}  // namespace ks::store
