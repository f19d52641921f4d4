// The "ksjournal" HDF5 virtual file driver: a redo journal under HDF5 (see journal_vfd.hpp, FORMAT.md).
//
// Invariant: between two commits the bytes of the results file below `committed` (its size at the
// last commit) are never modified. Writes below it go to an in-memory page overlay (and reads see
// the overlay); writes at or above it go straight to the file (they are beyond the committed EOA,
// so no committed structure points at them). A commit (the driver's flush callback, i.e. the end
// of every H5Fflush/H5Fclose) writes the overlay pages plus a checksummed trailer to the journal,
// then applies them to the file, then resets the journal. A kill before the trailer is complete
// leaves the file untouched below `committed` (recovery just truncates the appended bytes); a kill
// after it is replayed by the next writer's open (idempotent) once it has checked that the journal
// belongs to the file as it is. The journal's layout, recovery and the readers' consistency stamp:
// journal_format.cpp; the writer lock: journal_lock.cpp; the commit itself: commit.cpp.
#include "store/journal/heap_check.hpp"
#include "store/journal/vfd.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <random>
#include <vector>

#include "store/journal/format.hpp"
#include "store/journal/jfile.hpp"
#include "store/journal/pages.hpp"

namespace ks::store::detail {
namespace {

using namespace journal;  // the on-disk layout and its file I/O (journal_format.cpp)

/// The writers' open files by the address of their descriptor (what get_handle gives), for
/// poison_journal_file.
std::mutex g_open_mutex;
std::map<const int*, JFile*> g_open;

struct JFapl {
  int durable;
  int readonly;  // open_overlay()
};

/// The overlay's copy of page `pno` (read from the file on first use); nullptr on a read error or
/// when no memory is left.
unsigned char* page_for(JFile* f, std::uint64_t pno) {
  auto it = f->pages.find(pno);
  if (it != f->pages.end()) return it->second;
  unsigned char* pg = f->page_pool.get();
  if (!pg || !read_all(f->fd, pg, kPage, pno * kPage)) return nullptr;
  f->pages.emplace(pno, pg);
  return pg;
}

void* j_fapl_get(H5FD_t* file) {
  auto* f = reinterpret_cast<JFile*>(file);
  auto* fa = static_cast<JFapl*>(std::malloc(sizeof(JFapl)));
  fa->durable = f->durable ? 1 : 0;
  fa->readonly = f->readonly ? 1 : 0;
  return fa;
}
void* j_fapl_copy(const void* old) {
  auto* fa = static_cast<JFapl*>(std::malloc(sizeof(JFapl)));
  std::memcpy(fa, old, sizeof(JFapl));
  return fa;
}
herr_t j_fapl_free(void* fa) { std::free(fa); return 0; }

/// Read-only open of a file whose stopped writer left a complete, unapplied commit in the journal:
/// the commit's pages become the overlay, the commit's new size the committed size. Nothing is
/// written; the journal is read once and closed.
H5FD_t* open_overlay(JFile* f) {
  f->readonly = true;
  f->fd = ::open(f->path.c_str(), O_RDONLY | O_CLOEXEC);
  if (f->fd < 0) { set_error("cannot open " + f->path, errno); return nullptr; }
  const std::string jp = journal_path(f->path);
  int jfd = ::open(jp.c_str(), O_RDONLY | O_CLOEXEC);
  if (jfd < 0) { set_error("cannot open journal " + jp, errno); return nullptr; }
  Parsed p = parse_journal(jfd);
  ::close(jfd);
  struct stat st{};
  ::fstat(f->fd, &st);
  f->dev = static_cast<std::uint64_t>(st.st_dev);
  f->ino = static_cast<std::uint64_t>(st.st_ino);
  if (!p.commit_ok || p.dev != f->dev || p.ino != f->ino) {
    set_error("the journal " + jp + " holds no commit for this file any more", 0);
    return nullptr;
  }
  const std::string why = mismatch(p, f->fd);
  if (!why.empty()) { set_error("the journal " + jp + " does not match the file: " + why, 0); return nullptr; }
  f->eof = f->committed = p.new_size;
  for (auto& [addr, bytes] : p.records) {
    auto* pg = page_for(f, addr / kPage);
    if (!pg || addr % kPage != 0) { set_error("cannot read " + f->path, errno); return nullptr; }
    std::memcpy(pg, bytes.data(), bytes.size());
  }
  return &f->pub;
}

H5FD_t* j_open(const char* name, unsigned flags, hid_t fapl, haddr_t /*maxaddr*/) {
  bool durable = false, overlay = false;
  if (const void* info = H5Pget_driver_info(fapl)) {
    durable = static_cast<const JFapl*>(info)->durable != 0;
    overlay = static_cast<const JFapl*>(info)->readonly != 0;
  }
  if ((flags & (H5F_ACC_TRUNC | H5F_ACC_CREAT)) || overlay == ((flags & H5F_ACC_RDWR) != 0)) {
    set_error("ksjournal driver: writers open existing files read-write, readers read-only", 0);
    return nullptr;
  }
  auto* f = new JFile();
  std::memset(&f->pub, 0, sizeof(H5FD_t));
  f->path = name;
  f->durable = durable;
  if (overlay) {
    if (H5FD_t* h = open_overlay(f)) return h;
    if (f->fd >= 0) ::close(f->fd);
    delete f;
    return nullptr;
  }
  if (const char* c = std::getenv("KS_STORE_TEST_CRASH")) {
    std::string spec(c);
    auto colon = spec.find(':');
    if (colon != std::string::npos) {
      f->crash_commit = std::atol(spec.substr(0, colon).c_str());
      f->crash_phase = spec.substr(colon + 1);
    }
  }
  f->fd = ::open(name, O_RDWR | O_CLOEXEC);
  if (f->fd < 0) { set_error("cannot open " + f->path + " for writing", errno); delete f; return nullptr; }
  struct stat st{};
  ::fstat(f->fd, &st);
  f->dev = static_cast<std::uint64_t>(st.st_dev);
  f->ino = static_cast<std::uint64_t>(st.st_ino);
  f->session = (static_cast<std::uint64_t>(std::random_device{}()) << 32) ^ std::random_device{}() ^
               static_cast<std::uint64_t>(::getpid());
  pause_point("data_opened");
  const std::string jp = journal_path(name);
  // The lock first: a new journal becomes visible already locked, with a header describing the
  // file as it is (no journal: the file is at a committed state).
  f->jfd = acquire_lock(jp, [&](int jfd) {
    struct stat now{};
    return ::fstat(f->fd, &now) == 0 &&
           reset_journal(jfd, f->fd, f->dev, f->ino, static_cast<std::uint64_t>(now.st_size), 0, f->session);
  });
  if (f->jfd < 0) { ::close(f->fd); delete f; return nullptr; }
  std::string why;
  if (!recover_locked(f->fd, f->jfd, f->dev, f->ino, &why)) {
    if (why.empty()) set_error("cannot recover " + f->path + " from its journal", errno);
    else set_error(f->path + " does not match its journal " + jp + " (" + why + "): nothing was written (delete "
                   "the journal to use the file as it is)", 0);
    ::close(f->jfd); ::close(f->fd); delete f; return nullptr;
  }
  pause_point("recovered");
  ::fstat(f->fd, &st);
  f->eof = f->committed = static_cast<std::uint64_t>(st.st_size);
  if ((durable && ::fsync(f->fd) != 0) ||
      !reset_journal(f->jfd, f->fd, f->dev, f->ino, f->committed, 0, f->session) ||
      (durable && ::fsync(f->jfd) != 0)) {
    set_error("cannot write journal " + jp, errno);
    ::close(f->jfd); ::close(f->fd); delete f; return nullptr;
  }
  pause_point("ready");
  {
    std::lock_guard<std::mutex> lk(g_open_mutex);
    g_open[&f->fd] = f;
  }
  return &f->pub;
}

herr_t j_close(H5FD_t* file) {
  auto* f = reinterpret_cast<JFile*>(file);
  herr_t rc = 0;
  if (f->readonly) {
    ::close(f->fd);
    delete f;
    return 0;
  }
  {
    std::lock_guard<std::mutex> lk(g_open_mutex);
    g_open.erase(&f->fd);
  }
  if (f->abandoned) {  // the file keeps its last commit, the journal stays
    ::close(f->fd);
    ::close(f->jfd);
    delete f;
    return 0;
  }
  if (!commit(f)) { set_error("commit failed on close of " + f->path, errno); rc = -1; }
  if (rc == 0) ::unlink(journal_path(f->path).c_str());  // clean close, still locked: nothing to recover
  ::close(f->fd);
  ::close(f->jfd);  // releases the lock
  delete f;
  return rc;
}

int j_cmp(const H5FD_t* a, const H5FD_t* b) {
  auto* f1 = reinterpret_cast<const JFile*>(a);
  auto* f2 = reinterpret_cast<const JFile*>(b);
  if (f1->dev != f2->dev) return f1->dev < f2->dev ? -1 : 1;
  if (f1->ino != f2->ino) return f1->ino < f2->ino ? -1 : 1;
  return 0;
}

herr_t j_query(const H5FD_t*, unsigned long* flags) {
  *flags = H5FD_FEAT_AGGREGATE_METADATA | H5FD_FEAT_ACCUMULATE_METADATA | H5FD_FEAT_DATA_SIEVE |
           H5FD_FEAT_AGGREGATE_SMALLDATA;
  return 0;
}

haddr_t j_get_eoa(const H5FD_t* file, H5FD_mem_t) { return reinterpret_cast<const JFile*>(file)->eoa; }
herr_t j_set_eoa(H5FD_t* file, H5FD_mem_t, haddr_t addr) { reinterpret_cast<JFile*>(file)->eoa = addr; return 0; }
haddr_t j_get_eof(const H5FD_t* file, H5FD_mem_t) { return reinterpret_cast<const JFile*>(file)->eof; }
herr_t j_get_handle(H5FD_t* file, hid_t, void** handle) { *handle = &reinterpret_cast<JFile*>(file)->fd; return 0; }

herr_t j_read_pages(JFile* f, haddr_t addr, size_t size, unsigned char* out);

herr_t j_read(H5FD_t* file, H5FD_mem_t type, hid_t, haddr_t addr, size_t size, void* buffer) {
  auto* out = static_cast<unsigned char*>(buffer);
  if (j_read_pages(reinterpret_cast<JFile*>(file), addr, size, out) < 0) return -1;
  // A global heap collection read whole is checked before HDF5 parses it (store/journal/heap_check.hpp).
  auto* f = reinterpret_cast<JFile*>(file);
  const auto read = [f](unsigned char* to, std::size_t n, std::uint64_t at) { return j_read_pages(f, at, n, to) == 0; };
  const bool heap = type == H5FD_MEM_GHEAP || type == H5FD_MEM_DRAW;  // HDF5 reads global heaps as raw data
  return heap && !global_heap_collection_is_sound(out, size, addr, std::max<std::uint64_t>(f->eof, f->committed), read) ? -1 : 0;
}

herr_t j_read_pages(JFile* f, haddr_t addr, size_t size, unsigned char* out) {
  std::uint64_t a = addr;
  if (!f->gathered.empty() && addr + size > f->gathered_at && addr < f->gathered_at + f->gathered.size() &&
      !write_gathered(f)) {
    set_error("write to " + f->path + " failed", errno);
    f->poisoned = true;
    return -1;
  }
  while (size > 0) {
    if (a >= f->committed) {
      if (!read_all(f->fd, out, size, a)) return -1;
      return 0;
    }
    const std::uint64_t pno = a / kPage, in = a % kPage;
    std::size_t len = static_cast<std::size_t>(std::min<std::uint64_t>({size, kPage - in, f->committed - a}));
    auto it = f->pages.find(pno);
    if (it != f->pages.end()) std::memcpy(out, it->second + in, len);
    else if (!read_all(f->fd, out, len, a)) return -1;
    out += len; a += len; size -= len;
  }
  return 0;
}

herr_t j_write(H5FD_t* file, H5FD_mem_t, hid_t, haddr_t addr, size_t size, const void* buffer) {
  auto* f = reinterpret_cast<JFile*>(file);
  if (f->readonly) { set_error("write to " + f->path + " opened read-only", 0); return -1; }
  auto* in = static_cast<const unsigned char*>(buffer);
  std::uint64_t a = addr;
  while (size > 0) {
    if (a >= f->committed) {
      if (!write_past_committed(f, in, size, a)) {
        set_error("write to " + f->path + " failed", errno);
        f->poisoned = true;
        return -1;
      }
      f->eof = std::max<std::uint64_t>(f->eof, a + size);
      return 0;
    }
    const std::uint64_t pno = a / kPage, off = a % kPage;
    std::size_t len = static_cast<std::size_t>(std::min<std::uint64_t>({size, kPage - off, f->committed - a}));
    auto* pg = page_for(f, pno);
    if (!pg) { f->poisoned = true; return -1; }
    std::memcpy(pg + off, in, len);
    in += len; a += len; size -= len;
  }
  return 0;
}

herr_t j_flush(H5FD_t* file, hid_t, hbool_t) {
  auto* f = reinterpret_cast<JFile*>(file);
  if (f->readonly || f->abandoned) return 0;
  if (!commit(f)) { set_error("commit of " + f->path + " failed", errno); return -1; }
  return 0;
}

herr_t j_truncate(H5FD_t* file, hid_t, hbool_t) {
  auto* f = reinterpret_cast<JFile*>(file);
  if (f->readonly) return 0;
  if (!write_gathered(f)) {
    set_error("write to " + f->path + " failed", errno);
    f->poisoned = true;
    return -1;
  }
  // Grow to the EOA when needed; never shrink below the committed size (committed readers need it).
  const std::uint64_t want = std::max<std::uint64_t>(f->eoa, f->committed);
  if (want > f->eof) {
    if (::ftruncate(f->fd, static_cast<off_t>(want)) != 0) { set_error("ftruncate " + f->path, errno); return -1; }
    f->eof = want;
  } else if (want < f->eof) {
    if (::ftruncate(f->fd, static_cast<off_t>(want)) != 0) { set_error("ftruncate " + f->path, errno); return -1; }
    f->eof = want;
  }
  return 0;
}

herr_t j_lock(H5FD_t*, hbool_t) { return 0; }  // the journal lock is the writer lock; readers stay free
herr_t j_unlock(H5FD_t*) { return 0; }

H5FD_class_t make_class() {
  H5FD_class_t c;
  std::memset(&c, 0, sizeof(c));
  c.name = "ksjournal";
  c.maxaddr = static_cast<haddr_t>(1) << 62;
  c.fc_degree = H5F_CLOSE_WEAK;
  c.fapl_size = sizeof(JFapl);
  c.fapl_get = j_fapl_get;
  c.fapl_copy = j_fapl_copy;
  c.fapl_free = j_fapl_free;
  c.open = j_open;
  c.close = j_close;
  c.cmp = j_cmp;
  c.query = j_query;
  c.get_eoa = j_get_eoa;
  c.set_eoa = j_set_eoa;
  c.get_eof = j_get_eof;
  c.get_handle = j_get_handle;
  c.read = j_read;
  c.write = j_write;
  c.flush = j_flush;
  c.truncate = j_truncate;
  c.lock = j_lock;
  c.unlock = j_unlock;
  H5FD_mem_t map[H5FD_MEM_NTYPES] = H5FD_FLMAP_DICHOTOMY;
  std::memcpy(c.fl_map, map, sizeof(map));
  return c;
}

const H5FD_class_t g_class = make_class();

}  // namespace

hid_t journal_driver_id() {
  static std::mutex m;
  static hid_t id = -1;
  std::lock_guard<std::mutex> lk(m);
  if (id < 0 || H5Iis_valid(id) <= 0) id = H5FDregister(&g_class);
  return id;
}

hid_t make_journal_fapl(bool durable) {
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  JFapl fa{durable ? 1 : 0, 0};
  H5Pset_driver(fapl, journal_driver_id(), &fa);
  return fapl;
}

void abandon_journal_file(hid_t file) {
  void* handle = nullptr;
  if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0 || !handle) {
    H5Eclear2(H5E_DEFAULT);
    return;
  }
  std::lock_guard<std::mutex> lk(g_open_mutex);
  const auto it = g_open.find(static_cast<const int*>(handle));
  if (it != g_open.end()) it->second->abandoned = true;
}

void rename_journal_file(hid_t file, const std::string& new_path) {
  void* handle = nullptr;
  if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0 || !handle) {
    H5Eclear2(H5E_DEFAULT);
    return;
  }
  std::lock_guard<std::mutex> lk(g_open_mutex);
  const auto it = g_open.find(static_cast<const int*>(handle));
  if (it != g_open.end()) it->second->path = new_path;
}

hid_t make_journal_read_fapl() {
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  JFapl fa{0, 1};
  H5Pset_driver(fapl, journal_driver_id(), &fa);
  return fapl;
}

}  // namespace ks::store::detail
