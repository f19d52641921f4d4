// The ksjournal redo journal on disk: its records, the check that it belongs to the file, recovery
// after a crash, and what readers use (how to open the file, the consistency stamp) (see format.hpp, vfd.hpp, FORMAT.md "Crash safety"). The HDF5 driver
// that writes it is vfd.cpp.
#include "store/journal/format.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>


namespace ks::store::detail {
namespace journal {

namespace {
thread_local std::string g_last_error;
}  // namespace

void set_error(const std::string& what, int err) {
  g_last_error = what + (err ? std::string(": ") + std::strerror(err) : std::string());
}

bool write_all(int fd, const void* buf, std::size_t n, std::uint64_t off) {
  auto p = static_cast<const unsigned char*>(buf);
  while (n > 0) {
    ssize_t w = ::pwrite(fd, p, n, static_cast<off_t>(off));
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (w == 0) { errno = EIO; return false; }
    p += w; n -= static_cast<std::size_t>(w); off += static_cast<std::uint64_t>(w);
  }
  return true;
}

bool read_all(int fd, void* buf, std::size_t n, std::uint64_t off) {
  auto p = static_cast<unsigned char*>(buf);
  while (n > 0) {
    ssize_t r = ::pread(fd, p, n, static_cast<off_t>(off));
    if (r < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (r == 0) { std::memset(p, 0, n); return true; }
    p += r; n -= static_cast<std::size_t>(r); off += static_cast<std::uint64_t>(r);
  }
  return true;
}

void put64(unsigned char* p, std::uint64_t v) { std::memcpy(p, &v, 8); }
std::uint64_t get64(const unsigned char* p) { std::uint64_t v; std::memcpy(&v, p, 8); return v; }

std::pair<std::uint64_t, std::uint64_t> first_page_range(std::uint64_t size) {
  return {0, std::min<std::uint64_t>(kPage, size)};
}

std::pair<std::uint64_t, std::uint64_t> last_page_range(std::uint64_t size) {
  if (size == 0) return {0, 0};
  const std::uint64_t at = (size - 1) / kPage * kPage;
  return {at, size - at};
}

namespace {
std::uint32_t crc_of(const unsigned char* p, std::size_t n) {
  return static_cast<std::uint32_t>(crc32(crc32(0L, Z_NULL, 0), p, static_cast<uInt>(n)));
}
bool crc_range(int fd, std::pair<std::uint64_t, std::uint64_t> r, std::uint32_t* out) {
  std::vector<unsigned char> b(static_cast<std::size_t>(r.second));
  if (!read_all(fd, b.data(), b.size(), r.first)) return false;
  *out = crc_of(b.data(), b.size());
  return true;
}
}  // namespace

bool fingerprint(int fd, std::uint64_t size, Fingerprint* out) {
  out->size = size;
  return crc_range(fd, first_page_range(size), &out->crc_first) && crc_range(fd, last_page_range(size), &out->crc_last);
}

bool reset_journal(int jfd, int fd, std::uint64_t dev, std::uint64_t ino, std::uint64_t committed,
                   std::uint64_t seq, std::uint64_t session) {
  Fingerprint fp;
  if (!fingerprint(fd, committed, &fp)) return false;
  unsigned char h[kHeadSize] = {};
  std::memcpy(h, kHeadMagic, 8);
  put64(h + 8, dev); put64(h + 16, ino); put64(h + 24, committed);
  put64(h + 32, seq); put64(h + 40, session);
  std::memcpy(h + 48, &fp.crc_first, 4);
  std::memcpy(h + 52, &fp.crc_last, 4);
  // Header first, then drop the old records: a kill in between leaves a header whose (old,
  // still valid) commit is replayed again, which is harmless.
  if (!write_all(jfd, h, kHeadSize, 0)) return false;
  return ::ftruncate(jfd, static_cast<off_t>(kHeadSize)) == 0;
}

Parsed parse_journal(int jfd) {
  Parsed out;
  struct stat st{};
  if (::fstat(jfd, &st) != 0 || static_cast<std::size_t>(st.st_size) < kHeadSizeV1) return out;
  std::vector<unsigned char> buf(static_cast<std::size_t>(st.st_size));
  if (!read_all(jfd, buf.data(), buf.size(), 0)) return out;
  std::size_t pos = 0;
  if (std::memcmp(buf.data(), kHeadMagic, 8) == 0 && buf.size() >= kHeadSize) {
    out.version = 2;
    std::memcpy(&out.crc_first, buf.data() + 48, 4);
    std::memcpy(&out.crc_last, buf.data() + 52, 4);
    pos = kHeadSize;
  } else if (std::memcmp(buf.data(), kHeadMagicV1, 8) == 0) {
    out.version = 1;
    pos = kHeadSizeV1;
  } else {
    return out;
  }
  out.dev = get64(buf.data() + 8);
  out.ino = get64(buf.data() + 16);
  out.committed = get64(buf.data() + 24);
  uLong crc = crc32(0L, Z_NULL, 0);
  std::uint64_t n = 0;
  while (pos + 16 <= buf.size()) {
    if (std::memcmp(buf.data() + pos, kTailMagic, 8) == 0) {
      if (pos + kTailSize > buf.size()) break;
      std::uint64_t nrec = get64(buf.data() + pos + 8), nsize = get64(buf.data() + pos + 16);
      std::uint32_t stored; std::memcpy(&stored, buf.data() + pos + 24, 4);
      crc = crc32(crc, buf.data() + pos + 8, 16);
      if (nrec == n && static_cast<std::uint32_t>(crc) == stored) {
        out.commit_ok = true;
        out.new_size = nsize;
      }
      break;
    }
    std::uint64_t addr = get64(buf.data() + pos), len = get64(buf.data() + pos + 8);
    if (len > kPage || pos + 16 + len > buf.size()) break;
    crc = crc32(crc, buf.data() + pos, static_cast<uInt>(16 + len));
    out.records.emplace_back(addr, std::vector<unsigned char>(buf.begin() + static_cast<long>(pos + 16),
                                                              buf.begin() + static_cast<long>(pos + 16 + len)));
    pos += 16 + len;
    ++n;
  }
  if (!out.commit_ok) out.records.clear();
  return out;
}

std::string mismatch(const Parsed& p, int fd) {
  struct stat st{};
  if (::fstat(fd, &st) != 0) return std::string("cannot stat the file: ") + std::strerror(errno);
  const std::uint64_t size = static_cast<std::uint64_t>(st.st_size);
  if (p.commit_ok && size != p.new_size)
    return "the file has " + std::to_string(size) + " bytes, the commit in the journal makes it " +
           std::to_string(p.new_size);
  if (!p.commit_ok && size < p.committed)
    return "the file has " + std::to_string(size) + " bytes, fewer than the " + std::to_string(p.committed) +
           " the journal committed";
  if (p.version < 2) return {};
  const std::pair<std::pair<std::uint64_t, std::uint64_t>, std::uint32_t> pages[2] = {
      {first_page_range(p.committed), p.crc_first}, {last_page_range(p.committed), p.crc_last}};
  for (auto& [range, expected] : pages) {
    std::uint32_t now = 0;
    if (!crc_range(fd, range, &now)) return std::string("cannot read the file: ") + std::strerror(errno);
    if (now == expected) continue;
    bool as_committed = false;  // or as the pending commit writes it
    if (p.commit_ok)
      for (auto& [addr, bytes] : p.records)
        if (addr == range.first && bytes.size() == range.second) as_committed = crc_of(bytes.data(), bytes.size()) == now;
    if (!as_committed)
      return "the bytes at offset " + std::to_string(range.first) + " differ from the state the journal was written for";
  }
  return {};
}

Plan recovery_plan(int fd, int jfd, std::uint64_t dev, std::uint64_t ino, std::string* why) {
  why->clear();
  Parsed p = parse_journal(jfd);
  if (p.version == 0) {
    // Empty, or shorter than a header and either zeros or the start of one (a writer stopped while
    // writing its header): nothing to recover. Anything else is not a kinesweep journal.
    struct stat js{};
    if (::fstat(jfd, &js) != 0) return Plan::refuse;
    const std::size_t n = static_cast<std::size_t>(js.st_size);
    if (n == 0) return Plan::nothing;
    if (n < kHeadSize) {
      unsigned char b[kHeadSize] = {};
      if (!read_all(jfd, b, n, 0)) return Plan::refuse;
      bool zeros = true;
      for (std::size_t i = 0; i < n; ++i) zeros = zeros && b[i] == 0;
      const std::size_t m = std::min<std::size_t>(n, 7);  // "KSJRNL0" of either version
      if (zeros || std::memcmp(b, kHeadMagic, m) == 0) return Plan::nothing;
    }
    *why = "the journal is not a kinesweep journal (no KSJRNL header)";
    return Plan::refuse;
  }
  if (p.dev != dev || p.ino != ino) {
    if (!p.commit_ok) return Plan::nothing;  // another file's journal with nothing committed: nothing of this file
    *why = "the journal holds a commit for another file (device/inode differ: the file was replaced after its "
           "writer stopped)";
    return Plan::refuse;
  }
  // Every results file is larger than an HDF5 superblock: a journal committing fewer bytes was not
  // written for this file (recovery would truncate it)
  if (p.committed < kMinCommittedSize) {
    *why = "the journal claims a committed size of " + std::to_string(p.committed) +
           " bytes, less than any results file (not a journal of this file)";
    return Plan::refuse;
  }
  if (p.version == 1) {
    *why = "the journal has a version 1 header (KSJRNL01, kinesweep before the fingerprint): nothing in it shows "
           "that it belongs to the file as it is; recover it with the kinesweep that wrote it";
    return Plan::refuse;
  }
  *why = mismatch(p, fd);
  if (!why->empty()) {
    *why += "; the file was changed after its writer stopped";
    return Plan::refuse;
  }
  struct stat st{};
  if (::fstat(fd, &st) != 0) return Plan::refuse;
  if (p.commit_ok || static_cast<std::uint64_t>(st.st_size) > p.committed) return Plan::recover;
  return Plan::nothing;
}

bool recover_locked(int fd, int jfd, std::uint64_t dev, std::uint64_t ino, std::string* why) {
  const Plan plan = recovery_plan(fd, jfd, dev, ino, why);
  if (plan == Plan::refuse) return false;
  if (plan == Plan::nothing) return true;
  const Parsed p = parse_journal(jfd);
  struct stat st{};
  if (::fstat(fd, &st) != 0) return false;
  const std::uint64_t size = static_cast<std::uint64_t>(st.st_size);
  if (p.commit_ok) {
    for (auto& [addr, bytes] : p.records)
      if (!write_all(fd, bytes.data(), bytes.size(), addr)) return false;
  } else if (size > p.committed) {
    // bytes appended after the last commit: nothing committed points at them
    if (::ftruncate(fd, static_cast<off_t>(p.committed)) != 0) return false;
  }
  return true;
}

}  // namespace journal

using namespace journal;

std::string journal_path(const std::string& results_path) { return results_path + ".journal"; }

std::string journal_last_error() { return g_last_error; }

ReadView read_view(const std::string& results_path) {
  const std::string jp = journal_path(results_path);
  int jfd = ::open(jp.c_str(), O_RDONLY | O_CLOEXEC);
  if (jfd < 0) return {};
  ReadView v;
  Parsed p = parse_journal(jfd);
  ::close(jfd);
  int fd = ::open(results_path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st{};
  if (fd < 0 || ::fstat(fd, &st) != 0) {
    if (fd >= 0) ::close(fd);
    return {};  // the open that follows reports it
  }
  if (p.version != 0 && p.commit_ok && p.dev == static_cast<std::uint64_t>(st.st_dev) &&
      p.ino == static_cast<std::uint64_t>(st.st_ino)) {
    v.why = mismatch(p, fd);
    v.kind = v.why.empty() ? ReadView::overlay : ReadView::refuse;
  }
  ::close(fd);
  return v;
}

std::string consistency_stamp(const std::string& results_path) {
  int jfd = ::open(journal_path(results_path).c_str(), O_RDONLY | O_CLOEXEC);
  if (jfd < 0) {  // no writer: the file's own size and mtime
    struct stat st{};
    if (::stat(results_path.c_str(), &st) != 0) return {};
    return "static:" + std::to_string(st.st_size) + ":" + std::to_string(st.st_mtim.tv_sec) + "." +
           std::to_string(st.st_mtim.tv_nsec);
  }
  // The header (commit sequence, session, committed size) and, past it, the journal's size and its
  // last bytes: records being written or a commit being applied change the stamp.
  std::string out = "journal:";
  struct stat st{};
  if (::fstat(jfd, &st) == 0) {
    const std::uint64_t size = static_cast<std::uint64_t>(st.st_size);
    std::vector<unsigned char> h(std::min<std::uint64_t>(size, kHeadSize));
    std::vector<unsigned char> t(size > kHeadSize ? std::min<std::uint64_t>(size - kHeadSize, kTailSize) : 0);
    if (read_all(jfd, h.data(), h.size(), 0) && read_all(jfd, t.data(), t.size(), size - t.size()))
      out += std::string(h.begin(), h.end()) + ":" + std::to_string(size) + ":" + std::string(t.begin(), t.end());
  }
  ::close(jfd);
  return out;
}

bool journal_has_pending_commit(const std::string& results_path) {
  return read_view(results_path).kind != ReadView::plain;
}

bool journal_acts_on_open(const std::string& results_path) {
  const int jfd = ::open(journal_path(results_path).c_str(), O_RDONLY | O_CLOEXEC);
  if (jfd < 0) return false;
  const int fd = ::open(results_path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st{};
  bool acts = true;  // a file that cannot be examined: the writer's open reports it
  if (fd >= 0 && ::fstat(fd, &st) == 0) {
    std::string why;
    acts = recovery_plan(fd, jfd, static_cast<std::uint64_t>(st.st_dev), static_cast<std::uint64_t>(st.st_ino),
                         &why) != Plan::nothing;
  }
  if (fd >= 0) ::close(fd);
  ::close(jfd);
  return acts;
}

}  // namespace ks::store::detail
