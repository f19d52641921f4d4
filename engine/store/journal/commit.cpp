// The commit of a file open under the "ksjournal" driver (see vfd.cpp's header): the gathered
// appended bytes, the commit record to the journal, the pages applied to the file, the journal reset;
// and the crash-safety tests' hook into it.
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "store/journal/format.hpp"
#include "store/journal/jfile.hpp"

namespace ks::store::detail::journal {
namespace {

void maybe_crash(JFile* f, const char* phase) {
  if (f->commits == f->crash_commit && f->crash_phase == phase) ::_exit(86);
}

/// Empties the overlay (after a commit).
void clear_pages(JFile* f) {
  f->pages.clear();
  f->page_pool.reset();
}

bool commit_impl(JFile* f) {
  if (!write_gathered(f)) return false;  // appended data first: the commit's new size covers it
  struct stat st{};
  if (::fstat(f->fd, &st) != 0) return false;
  const std::uint64_t new_size = std::max<std::uint64_t>(f->eof, static_cast<std::uint64_t>(st.st_size));
  if (f->pages.empty() && new_size == f->committed) return true;
  if (f->durable && ::fdatasync(f->fd) != 0) return false;  // appended data before the commit record
  // The commit record (page records, then the tail) is written in pieces of at most kPiece bytes,
  // so a commit needs no second copy of its pages. `limit`: the "journal_half" crash test's cut.
  std::uint64_t records = 0, bytes = kTailSize;
  for (auto& [pno, pg] : f->pages)
    if (pno * kPage < f->committed) ++records, bytes += 16 + std::min<std::uint64_t>(kPage, f->committed - pno * kPage);
  ++f->commits;
  const bool half = f->commits == f->crash_commit && f->crash_phase == "journal_half";
  const std::uint64_t limit = half ? bytes / 2 : bytes;
  constexpr std::size_t kPiece = 1 << 20;
  std::vector<unsigned char> buf;
  buf.reserve(std::min<std::uint64_t>(bytes, kPiece + kPage + 16));
  std::uint64_t at = kHeadSize, written = 0;
  auto put = [&](const unsigned char* p, std::size_t n, bool last) {
    buf.insert(buf.end(), p, p + n);
    if (buf.size() < kPiece && !last) return true;
    const std::size_t keep = static_cast<std::size_t>(std::min<std::uint64_t>(buf.size(), limit - written));
    if (!write_all(f->jfd, buf.data(), keep, at)) return false;
    at += keep, written += keep;
    buf.clear();
    return true;
  };
  uLong crc = crc32(0L, Z_NULL, 0);
  for (auto& [pno, pg] : f->pages) {
    const std::uint64_t addr = pno * kPage;
    if (addr >= f->committed) continue;
    const std::uint64_t len = std::min<std::uint64_t>(kPage, f->committed - addr);  // never above committed
    unsigned char rh[16];
    put64(rh, addr); put64(rh + 8, len);
    crc = crc32(crc, rh, 16);
    crc = crc32(crc, pg, static_cast<uInt>(len));
    if (!put(rh, 16, false) || !put(pg, len, false)) return false;
  }
  unsigned char tail[kTailSize] = {};
  std::memcpy(tail, kTailMagic, 8);
  put64(tail + 8, records); put64(tail + 16, new_size);
  crc = crc32(crc, tail + 8, 16);
  const std::uint32_t c32 = static_cast<std::uint32_t>(crc);
  std::memcpy(tail + 24, &c32, 4);
  if (!put(tail, kTailSize, true)) return false;
  if (half) ::_exit(86);
  if (f->durable && ::fdatasync(f->jfd) != 0) return false;
  maybe_crash(f, "journal_done");
  // the commit point has passed: apply
  std::size_t applied = 0;
  for (auto& [pno, pg] : f->pages) {
    if (applied++ == f->pages.size() / 2) maybe_crash(f, "apply_half");
    const std::uint64_t addr = pno * kPage;
    if (addr >= f->committed) continue;
    const std::uint64_t len = std::min<std::uint64_t>(kPage, f->committed - addr);
    if (!write_all(f->fd, pg, len, addr)) return false;
  }
  if (f->durable && ::fdatasync(f->fd) != 0) return false;
  if (!reset_journal(f->jfd, f->fd, f->dev, f->ino, new_size, f->seq + 1, f->session)) return false;
  ++f->seq;
  f->committed = new_size;
  f->eof = new_size;
  clear_pages(f);
  return true;
}

}  // namespace

bool write_gathered(JFile* f) {
  if (f->gathered.empty()) return true;
  const bool ok = write_all(f->fd, f->gathered.data(), f->gathered.size(), f->gathered_at);
  f->gathered.clear();
  return ok;
}

bool write_past_committed(JFile* f, const unsigned char* in, std::size_t n, std::uint64_t a) {
  if (!f->gathered.empty() && a == f->gathered_at + f->gathered.size() && f->gathered.size() + n <= JFile::kGather) {
    f->gathered.insert(f->gathered.end(), in, in + n);
    return true;
  }
  if (!write_gathered(f)) return false;
  if (n >= JFile::kDirect) return write_all(f->fd, in, n, a);
  if (f->gathered.capacity() < JFile::kGather) f->gathered.reserve(JFile::kGather);
  f->gathered.assign(in, in + n);
  f->gathered_at = a;
  return true;
}

bool commit(JFile* f) {
  if (f->poisoned) return false;
  if (!commit_impl(f)) { f->poisoned = true; return false; }
  return true;
}

}  // namespace ks::store::detail::journal
