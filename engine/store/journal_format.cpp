// The ksjournal redo journal on disk: its records, recovery after a crash, and the consistency stamp
// readers use (see journal_format.hpp, journal_vfd.hpp, FORMAT.md "Crash safety"). The HDF5 driver
// that writes it is journal_vfd.cpp.
#include "store/journal_format.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>

#include "store/journal_vfd.hpp"

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

std::vector<unsigned char> make_header(std::uint64_t dev, std::uint64_t ino, std::uint64_t committed,
                                       std::uint64_t seq, std::uint64_t session) {
  std::vector<unsigned char> h(kHeadSize);
  std::memcpy(h.data(), kHeadMagic, 8);
  put64(h.data() + 8, dev); put64(h.data() + 16, ino); put64(h.data() + 24, committed);
  put64(h.data() + 32, seq); put64(h.data() + 40, session);
  return h;
}

bool reset_journal(int jfd, std::uint64_t dev, std::uint64_t ino, std::uint64_t committed, std::uint64_t seq,
                   std::uint64_t session) {
  // Header first, then drop the old records: a kill in between leaves a header whose (old,
  // still valid) commit is replayed again, which is harmless.
  auto h = make_header(dev, ino, committed, seq, session);
  if (!write_all(jfd, h.data(), h.size(), 0)) return false;
  return ::ftruncate(jfd, static_cast<off_t>(kHeadSize)) == 0;
}

Parsed parse_journal(int jfd, std::uint64_t dev, std::uint64_t ino) {
  Parsed out;
  struct stat st{};
  if (::fstat(jfd, &st) != 0 || static_cast<std::size_t>(st.st_size) < kHeadSize) return out;
  std::vector<unsigned char> buf(static_cast<std::size_t>(st.st_size));
  if (!read_all(jfd, buf.data(), buf.size(), 0)) return out;
  if (std::memcmp(buf.data(), kHeadMagic, 8) != 0 || get64(buf.data() + 8) != dev ||
      get64(buf.data() + 16) != ino)
    return out;
  out.header_ok = true;
  out.committed = get64(buf.data() + 24);
  std::size_t pos = kHeadSize;
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

bool recover_locked(int fd, int jfd, std::uint64_t dev, std::uint64_t ino, bool* replayed) {
  *replayed = false;
  Parsed p = parse_journal(jfd, dev, ino);
  if (!p.header_ok) return true;  // no journal content, or a stale journal of another file
  struct stat st{};
  if (::fstat(fd, &st) != 0) return false;
  std::uint64_t size = static_cast<std::uint64_t>(st.st_size);
  if (p.commit_ok) {
    for (auto& [addr, bytes] : p.records)
      if (!write_all(fd, bytes.data(), bytes.size(), addr)) return false;
    if (size > p.new_size && ::ftruncate(fd, static_cast<off_t>(p.new_size)) != 0) return false;
    *replayed = true;
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

RecoverOutcome recover(const std::string& results_path) {
  const std::string jp = journal_path(results_path);
  int jfd = ::open(jp.c_str(), O_RDWR | O_CLOEXEC);
  if (jfd < 0) return errno == ENOENT ? RecoverOutcome::no_journal : RecoverOutcome::not_permitted;
  if (::flock(jfd, LOCK_EX | LOCK_NB) != 0) { ::close(jfd); return RecoverOutcome::writer_alive; }
  int fd = ::open(results_path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    ::close(jfd);
    if (errno == ENOENT) { ::unlink(jp.c_str()); return RecoverOutcome::clean; }  // orphan journal
    return RecoverOutcome::not_permitted;
  }
  struct stat st{};
  ::fstat(fd, &st);
  bool replayed = false;
  bool ok = recover_locked(fd, jfd, static_cast<std::uint64_t>(st.st_dev), static_cast<std::uint64_t>(st.st_ino),
                           &replayed);
  if (ok) ::unlink(jp.c_str());
  ::close(fd);
  ::close(jfd);
  if (!ok) return RecoverOutcome::not_permitted;
  return replayed ? RecoverOutcome::replayed : RecoverOutcome::clean;
}

std::string consistency_stamp(const std::string& results_path) {
  int jfd = ::open(journal_path(results_path).c_str(), O_RDONLY | O_CLOEXEC);
  if (jfd < 0) {  // no writer: the file's own size and mtime
    struct stat st{};
    if (::stat(results_path.c_str(), &st) != 0) return {};
    return "static:" + std::to_string(st.st_size) + ":" + std::to_string(st.st_mtim.tv_sec) + "." +
           std::to_string(st.st_mtim.tv_nsec);
  }
  std::string out;
  struct stat st{};
  if (::fstat(jfd, &st) == 0 && static_cast<std::size_t>(st.st_size) == kHeadSize) {
    std::vector<unsigned char> h(kHeadSize);
    if (read_all(jfd, h.data(), kHeadSize, 0) && std::memcmp(h.data(), kHeadMagic, 8) == 0)
      out = "journal:" + std::string(h.begin(), h.end());
  }
  ::close(jfd);
  return out;  // empty: a commit is in progress
}

bool journal_has_pending_commit(const std::string& results_path) {
  int jfd = ::open(journal_path(results_path).c_str(), O_RDONLY | O_CLOEXEC);
  if (jfd < 0) return false;
  struct stat st{};
  bool pending = false;
  if (::stat(results_path.c_str(), &st) == 0) {
    Parsed p = parse_journal(jfd, static_cast<std::uint64_t>(st.st_dev), static_cast<std::uint64_t>(st.st_ino));
    pending = p.commit_ok;
  }
  ::close(jfd);
  return pending;
}

}  // namespace ks::store::detail
