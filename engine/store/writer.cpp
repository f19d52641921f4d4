// ResultsWriter and encode_history (see store.hpp, FORMAT.md).
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <libdeflate.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include "store/h5util.hpp"
#include "store/journal_vfd.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"


namespace ks::store {
using namespace detail;

std::string history_group_name(std::int64_t run_id, std::int64_t n_runs) {
  std::size_t width = 6;
  std::string last = std::to_string(n_runs > 0 ? n_runs - 1 : 0);
  width = std::max(width, last.size());
  std::string s = std::to_string(run_id);
  if (s.size() < width) s = std::string(width - s.size(), '0') + s;
  return s;
}

namespace {
/// HDF5's shuffle filter for 8-byte elements: byte j of element i goes to j * n + i.
void shuffle8(const double* src, std::size_t n, unsigned char* dst) {
  const unsigned char* s = reinterpret_cast<const unsigned char*>(src);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < 8; ++j) dst[j * n + i] = s[i * 8 + j];
}
/// The byte-shuffled array as one zlib stream, the format HDF5's deflate filter reads. The six
/// low-order byte planes of a history's doubles are close to noise (deflate gains ~4 % on them at
/// the price of most of its time), so they go into the stream as stored blocks, copied; only the two
/// high planes (sign, exponent, top of the mantissa: 2.5x and 50x smaller) are deflated, at `level`.
/// The stream: zlib header, stored blocks (BFINAL = 0, each ending on a byte boundary), libdeflate's
/// raw deflate of the high planes (its last block final), Adler-32 of all the bytes. Empty on failure.
std::vector<unsigned char> zlib_stream_high_planes(const unsigned char* shuffled, std::size_t n, int level);

/// One libdeflate compressor per thread and level (allocating one costs more than a small array).
libdeflate_compressor* compressor(int level) {
  struct Cache {
    std::array<libdeflate_compressor*, 10> c{};
    ~Cache() {
      for (auto* p : c)
        if (p) libdeflate_free_compressor(p);
    }
  };
  thread_local Cache cache;
  if (!cache.c[level]) cache.c[level] = libdeflate_alloc_compressor(level);
  return cache.c[level];
}

std::vector<unsigned char> zlib_stream_high_planes(const unsigned char* shuffled, std::size_t n, int level) {
  const std::size_t total = 8 * n, low = 6 * n;  // planes 0..5 stored, 6..7 deflated
  libdeflate_compressor* c = compressor(level);
  if (!c) return {};
  const std::size_t stored_blocks = (low + 65534) / 65535;
  std::vector<unsigned char> out(2 + low + 5 * stored_blocks + libdeflate_deflate_compress_bound(c, total - low) + 4);
  unsigned char* p = out.data();
  *p++ = 0x78;  // CMF: deflate, 32 KiB window
  *p++ = 0x01;  // FLG: no dictionary, (0x78 * 256 + 0x01) % 31 == 0
  for (std::size_t at = 0; at < low;) {
    const std::size_t len = std::min<std::size_t>(65535, low - at);
    *p++ = 0x00;  // BFINAL = 0, BTYPE = 00 (stored), then padding to the byte boundary
    *p++ = static_cast<unsigned char>(len & 0xff);
    *p++ = static_cast<unsigned char>(len >> 8);
    *p++ = static_cast<unsigned char>(~len & 0xff);
    *p++ = static_cast<unsigned char>((~len >> 8) & 0xff);
    std::memcpy(p, shuffled + at, len);
    p += len;
    at += len;
  }
  const std::size_t room = static_cast<std::size_t>(out.data() + out.size() - p) - 4;
  const std::size_t m = libdeflate_deflate_compress(c, shuffled + low, total - low, p, room);
  if (m == 0) return {};
  p += m;
  const std::uint32_t adler = libdeflate_adler32(1, shuffled, total);
  *p++ = static_cast<unsigned char>(adler >> 24);
  *p++ = static_cast<unsigned char>(adler >> 16);
  *p++ = static_cast<unsigned char>(adler >> 8);
  *p++ = static_cast<unsigned char>(adler);
  out.resize(static_cast<std::size_t>(p - out.data()));
  return out;
}
}  // namespace

EncodedHistory encode_history(const RunHistory& history, int level) {
  level = std::clamp(level, 0, 9);
  EncodedHistory out;
  out.arrays.reserve(history.arrays.size());
  std::vector<unsigned char> shuffled;
  for (const auto& a : history.arrays) {
    if (a.data.size() != a.rows * a.cols)
      throw StoreError("", "history array '" + a.name + "' has " + std::to_string(a.data.size()) +
                               " values, expected rows*cols = " + std::to_string(a.rows * a.cols));
    EncodedArray e;
    e.name = a.name; e.unit = a.unit; e.rows = a.rows; e.cols = a.cols; e.level = level;
    if (!a.data.empty()) {
      const std::size_t src = a.data.size() * sizeof(double);
      if (level == 0) {  // no filter: the chunk is the raw little-endian array
        e.bytes.resize(src);
        std::memcpy(e.bytes.data(), a.data.data(), src);
      } else {  // shuffle, then deflate (zlib format, as HDF5's deflate filter writes it)
        shuffled.resize(src);
        shuffle8(a.data.data(), a.data.size(), shuffled.data());
        e.bytes = zlib_stream_high_planes(shuffled.data(), a.data.size(), level);
        if (e.bytes.empty()) throw StoreError("", "libdeflate failed for history array '" + a.name + "'");
      }
    }
    out.arrays.push_back(std::move(e));
  }
  return out;
}

// ------------------------------------------------------------------------------------------------
// struct ResultsWriter::Impl: store/writer_impl.hpp (shared with optimizations.cpp)

namespace {

const char* type_word(CellType t) { return t == CellType::f64 ? "f64" : t == CellType::i64 ? "i64" : "str"; }

void validate_name(const std::string& path, const std::string& name, const std::string& what) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos)
    throw StoreError(path, "invalid " + what + " name '" + name + "' (empty, '.', '..' or contains '/')");
}

std::string now_iso8601() {
  std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

hid_t file_type_of(CellType t) {
  switch (t) {
    case CellType::f64: return H5Tcopy(H5T_IEEE_F64LE);
    case CellType::i64: return H5Tcopy(H5T_STD_I64LE);
    default: return utf8_vlen_type();
  }
}

/// A file-access property list for the store's on-disk format (see FORMAT.md: 1.8 object formats,
/// superblock v2, which has no "open for write" flag, so readers can open a file being written).
void set_format(hid_t fapl) { H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_V18); }

bool journal_locked_by_other(const std::string& jp) {
  int fd = ::open(jp.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return false;
  bool locked = ::flock(fd, LOCK_EX | LOCK_NB) != 0;
  ::close(fd);
  return locked;
}

void fsync_path(const std::string& p, bool dir) {
  int fd = ::open(p.c_str(), (dir ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
  if (fd >= 0) { ::fsync(fd); ::close(fd); }
}

void build_skeleton(hid_t file, const std::string& path, const StoreMeta& meta,
                    const std::vector<ColumnSpec>& columns, std::int64_t n_runs) {
  write_str_attr(file, "format", kFormatName);
  write_i64_attr(file, "format_version", kFormatVersion);
  write_str_attr(file, "engine_version", meta.engine_version);
  write_str_attr(file, "study_sha256", meta.study_sha256);
  write_str_attr(file, "created", meta.created.empty() ? now_iso8601() : meta.created);
  write_str_attr(file, "study_name", meta.study_name);

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

  Hid runs(check(H5Gcreate2(file, "runs", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /runs"));
  std::vector<std::string> names;
  for (auto& c : columns) names.push_back(c.name);
  write_str_list_attr(runs, "columns", names);
  write_i64_attr(runs, "n_runs", n_runs);
  hsize_t n = static_cast<hsize_t>(n_runs);
  Hid space(H5Screate_simple(1, &n, nullptr));
  auto make = [&](const std::string& name, hid_t ftype, hid_t mtype, const void* fill, const std::string& unit,
                  const std::string& desc, const char* type_attr) {
    Hid dcpl(H5Pcreate(H5P_DATASET_CREATE));
    H5Pset_layout(dcpl, H5D_CONTIGUOUS);
    H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY);  // rows live at fixed addresses from creation on
    H5Pset_fill_time(dcpl, H5D_FILL_TIME_ALLOC);
    if (fill) H5Pset_fill_value(dcpl, mtype, fill);
    Hid d(check(H5Dcreate2(runs, name.c_str(), ftype, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), path,
                "create /runs/" + name));
    write_str_attr(d, "unit", unit);
    write_str_attr(d, "description", desc);
    write_str_attr(d, "type", type_attr);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::int64_t minus1 = -1;
  for (auto& c : columns) {
    Hid ft(file_type_of(c.type));
    switch (c.type) {
      case CellType::f64: make(c.name, ft, H5T_NATIVE_DOUBLE, &nan, c.unit, c.description, "f64"); break;
      case CellType::i64: make(c.name, ft, H5T_NATIVE_INT64, &minus1, c.unit, c.description, "i64"); break;
      case CellType::str: make(c.name, ft, ft, nullptr, c.unit, c.description, "str"); break;  // null = ""
    }
  }
  const std::uint8_t zero = 0;
  make("done", H5T_STD_U8LE, H5T_NATIVE_UINT8, &zero, "",
       "1: the run's row and history are committed; 0: not done (the row holds missing values, or values "
       "whose done flag was not committed before a crash; resume rewrites it)", "u8");

  Hid h(check(H5Gcreate2(file, "histories", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /histories"));
  Hid l(check(H5Gcreate2(file, "landscapes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /landscapes"));
}

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

}  // namespace

void ResultsWriter::Impl::open_objects() {
  runs = Hid(check(H5Gopen2(file, "runs", H5P_DEFAULT), path, "open /runs"));
  histories = Hid(check(H5Gopen2(file, "histories", H5P_DEFAULT), path, "open /histories"));
  landscapes = Hid(check(H5Gopen2(file, "landscapes", H5P_DEFAULT), path, "open /landscapes"));
  done_dset = Hid(check(H5Dopen2(runs, "done", H5P_DEFAULT), path, "open /runs/done"));
  col_dsets.clear();
  for (auto& c : columns)
    col_dsets.emplace_back(check(H5Dopen2(runs, c.name.c_str(), H5P_DEFAULT), path, "open /runs/" + c.name));
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
  }
  struct stat st{};
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw StoreError(path, "is a directory");
    if (!options.overwrite) throw StoreError(path, "file exists (pass overwrite to replace it)");
  }
  fs::path p(path);
  std::string dir = p.parent_path().empty() ? std::string(".") : p.parent_path().string();
  static std::atomic<unsigned> counter{0};
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
    H5Pset_istore_k(fcpl, 1);  // chunk B-tree nodes sized for one-chunk history arrays
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
    const std::string jp = journal_path(path);
    if (journal_locked_by_other(jp)) throw StoreError(path, "results file is being written by another process");
    ::unlink(jp.c_str());  // a journal of a file we replace (or an orphan) must never touch the new file
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
  impl->done.assign(static_cast<std::size_t>(n_runs), 0);
  impl->open_objects();
  return std::unique_ptr<ResultsWriter>(new ResultsWriter(std::move(impl)));
}

ResultsWriter::Resumed ResultsWriter::open_for_resume(const std::string& path, const std::string& expected_sha256,
                                                      const StoreOptions& options) {
  QuietHdf5 quiet;
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) throw StoreError(path, std::string("cannot resume: ") + std::strerror(errno));
  auto impl = open_writer_impl(path, options);
  hid_t f = impl->file;
  if (read_str_attr(f, "format") != kFormatName)
    throw StoreError(path, "not a kinesweep results file (attribute format != kinesweep-results)");
  if (read_i64_attr(f, "format_version", -1) != kFormatVersion)
    throw StoreError(path, "unsupported format_version " + std::to_string(read_i64_attr(f, "format_version", -1)));
  auto lower = [](std::string s) {
    for (auto& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return s;
  };
  const std::string sha = read_str_attr(f, "study_sha256");
  if (lower(sha) != lower(expected_sha256))
    throw StoreError(path, "study sha256 mismatch: the file was written for study " + sha +
                               ", the study given now has " + expected_sha256 + " (refusing to resume)");
  impl->columns = read_run_columns(f, path, impl->n_runs);
  impl->open_objects();
  if (impl->n_runs < 0) impl->n_runs = H5Sget_simple_extent_npoints(Hid(H5Dget_space(impl->done_dset)));
  impl->done.assign(static_cast<std::size_t>(impl->n_runs), 0);
  if (impl->n_runs > 0)
    check(H5Dread(impl->done_dset, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, impl->done.data()), path,
          "read /runs/done");
  Resumed r;
  for (std::int64_t i = 0; i < impl->n_runs; ++i)
    if (impl->done[static_cast<std::size_t>(i)]) r.done.push_back(i);
  r.writer = std::unique_ptr<ResultsWriter>(new ResultsWriter(std::move(impl)));
  return r;
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
  return id >= 0 && id < impl_->n_runs && impl_->done[static_cast<std::size_t>(id)] != 0;
}
std::size_t ResultsWriter::pending() const { return impl_->pending.size() + impl_->unflagged.size(); }

void ResultsWriter::Impl::write_history(std::int64_t id, const EncodedHistory& h) {
  const std::string gname = history_group_name(id, n_runs);
  if (link_exists(histories, gname) && H5Ldelete(histories, gname.c_str(), H5P_DEFAULT) < 0)
    fail("cannot replace /histories/" + gname);
  Hid g(H5Gcreate2(histories, gname.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!g.ok()) fail("cannot create /histories/" + gname);
  std::vector<std::string> names;
  for (const auto& a : h.arrays) {
    validate_name(path, a.name, "history array");
    if (std::find(names.begin(), names.end(), a.name) != names.end())
      throw StoreError(path, "duplicate history array '" + a.name + "' in run " + std::to_string(id));
    names.push_back(a.name);
    hsize_t dims[2] = {a.rows, a.cols};
    Hid space(H5Screate_simple(2, dims, nullptr));
    Hid dcpl(H5Pcreate(H5P_DATASET_CREATE));
    const bool empty = a.rows == 0 || a.cols == 0;
    if (!empty) {
      H5Pset_chunk(dcpl, 2, dims);  // one chunk = the whole array
      if (a.level > 0) {            // the pipeline encode_history ran: shuffle, then deflate
        H5Pset_shuffle(dcpl);
        H5Pset_deflate(dcpl, static_cast<unsigned>(a.level));
      }
    }
    Hid d(H5Dcreate2(g, a.name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT));
    if (!d.ok()) fail("cannot create /histories/" + gname + "/" + a.name);
    if (!empty) {
      hsize_t offset[2] = {0, 0};
      if (H5Dwrite_chunk(d, H5P_DEFAULT, 0, offset, a.bytes.size(), a.bytes.data()) < 0)
        fail("cannot write /histories/" + gname + "/" + a.name);
    }
    write_str_attr(d, "unit", a.unit);
  }
  write_str_list_attr(g, "arrays", names);
}

void ResultsWriter::write_run(std::int64_t run_id, const Record& record, const RunHistory& history, int level) {
  write_run(run_id, record, encode_history(history, level));
}

void ResultsWriter::write_run(std::int64_t run_id, const Record& record, const EncodedHistory& history) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
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
  }
  if (!history.arrays.empty()) m.write_history(run_id, history);
  m.pending[run_id] = record;
  m.done[static_cast<std::size_t>(run_id)] = 1;
  // rows go to the datasets in batches as they come (uncommitted, invisible until the next commit),
  // so that the commit at the end of a sweep, which nothing overlaps, has little left to write
  if (m.pending.size() >= Impl::kRowBatch) m.write_rows();
  const bool by_count = m.opt.flush_every_runs > 0 && m.pending.size() + m.unflagged.size() >= m.opt.flush_every_runs;
  const bool by_time =
      m.opt.flush_every_seconds > 0 &&
      std::chrono::duration<double>(std::chrono::steady_clock::now() - m.last_flush).count() >= m.opt.flush_every_seconds;
  if (by_count || by_time) m.do_flush();
}

namespace {
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
}  // namespace

void ResultsWriter::Impl::write_rows() {
  if (pending.empty()) return;
  std::vector<hsize_t> ids;
  ids.reserve(pending.size());
  for (auto& [id, rec] : pending) ids.push_back(static_cast<hsize_t>(id));
  hsize_t k = ids.size();
  Hid mspace(H5Screate_simple(1, &k, nullptr));
  for (std::size_t c = 0; c < columns.size(); ++c) {
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
        std::vector<const char*> v;
        for (auto& [id, rec] : pending) v.push_back(std::get<std::string>(rec.cells[c]).c_str());
        Hid t(utf8_vlen_type());
        rc = H5Dwrite(col_dsets[c], t, mspace, fs, H5P_DEFAULT, v.data());
        break;
      }
    }
    if (rc < 0) fail("cannot write column " + columns[c].name);
  }
  unflagged.insert(unflagged.end(), ids.begin(), ids.end());
  pending.clear();
}

void ResultsWriter::Impl::do_flush() {
  write_rows();
  if (!unflagged.empty()) {
    // 1. the rows (and, already, the histories) are committed before the done flags ...
    if (H5Fflush(file, H5F_SCOPE_LOCAL) < 0) fail("flush (commit of rows) failed");
    // 2. ... so a concurrent reader that sees done = 1 sees the row.
    std::sort(unflagged.begin(), unflagged.end());
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
  last_flush = std::chrono::steady_clock::now();
}

void ResultsWriter::flush() {
  QuietHdf5 quiet;
  impl_->usable();
  impl_->do_flush();
}

void ResultsWriter::write_landscape(const LandscapeSpec& spec) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  validate_name(m.path, spec.block, "landscape block");
  std::size_t cells = 1;
  std::vector<hsize_t> dims;
  std::set<std::string> names;
  std::vector<std::string> axis_names, metric_names;
  for (auto& a : spec.axes) {
    validate_name(m.path, a.name, "landscape axis");
    if (!names.insert(a.name).second) throw StoreError(m.path, "landscape " + spec.block + ": duplicate name " + a.name);
    dims.push_back(a.values.size());
    cells *= a.values.size();
    axis_names.push_back(a.name);
  }
  for (auto& mt : spec.metrics) {
    validate_name(m.path, mt.name, "landscape metric");
    if (!names.insert(mt.name).second) throw StoreError(m.path, "landscape " + spec.block + ": duplicate name " + mt.name);
    if (mt.grid.size() != cells)
      throw StoreError(m.path, "landscape " + spec.block + ": metric " + mt.name + " has " +
                                   std::to_string(mt.grid.size()) + " values, the axes span " + std::to_string(cells));
    metric_names.push_back(mt.name);
  }
  if (link_exists(m.landscapes, spec.block) && H5Ldelete(m.landscapes, spec.block.c_str(), H5P_DEFAULT) < 0)
    m.fail("cannot replace /landscapes/" + spec.block);
  Hid g(H5Gcreate2(m.landscapes, spec.block.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!g.ok()) m.fail("cannot create /landscapes/" + spec.block);
  write_str_list_attr(g, "axes", axis_names);
  write_str_list_attr(g, "metrics", metric_names);
  for (auto& a : spec.axes) {
    hsize_t n = a.values.size();
    Hid space(H5Screate_simple(1, &n, nullptr));
    Hid d(H5Dcreate2(g, a.name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    if (!d.ok() || (n > 0 && H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.values.data()) < 0))
      m.fail("cannot write landscape axis " + a.name);
    write_str_attr(d, "unit", a.unit);
    write_str_attr(d, "kind", "axis");
  }
  for (auto& mt : spec.metrics) {
    Hid space(dims.empty() ? H5Screate(H5S_SCALAR)
                           : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr));
    Hid d(H5Dcreate2(g, mt.name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    if (!d.ok() ||
        (cells > 0 && H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, mt.grid.data()) < 0))
      m.fail("cannot write landscape metric " + mt.name);
    write_str_attr(d, "unit", mt.unit);
    write_str_attr(d, "description", mt.description);
    write_str_attr(d, "kind", "metric");
    write_str_list_attr(d, "axes", axis_names);
  }
  m.do_flush();
}

void ResultsWriter::close() {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  if (m.closed) return;
  if (m.broken) {
    m.closed = true;
    // the driver refuses to commit after an I/O error; the file keeps its last committed state
    m.col_dsets.clear();
    m.done_dset.reset(); m.runs.reset(); m.histories.reset(); m.landscapes.reset();
    H5Fclose(m.file.release());
    H5Eclear2(H5E_DEFAULT);
    return;
  }
  m.do_flush();
  m.col_dsets.clear();
  m.done_dset.reset(); m.runs.reset(); m.histories.reset(); m.landscapes.reset();
  m.closed = true;
  if (H5Fclose(m.file.release()) < 0) {
    std::string cause = "close failed: " + h5_error_text();
    throw StoreError(m.path, cause);
  }
}

}  // namespace ks::store
