// The overwrite of an existing results file: the new file written aside, under its temporary name
// with its own journal, and renamed over the previous one at its first commit of runs (see
// writer_impl.hpp, Impl::aside; FORMAT.md "Creation, overwrite, resume").
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "store/journal/format.hpp"
#include "store/journal/vfd.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"

namespace ks::store {
using namespace detail;

namespace detail {

std::unique_ptr<ResultsWriter::Impl> open_aside(const std::string& path, const std::string& tmp,
                                                const StoreOptions& options) {
  const int lock = journal::acquire_lock(journal_path(path), [](int) { return true; });
  if (lock < 0) throw StoreError(path, journal_last_error());
  std::unique_ptr<ResultsWriter::Impl> impl;
  try {
    impl = open_writer_impl(tmp, options);
  } catch (...) {
    ::close(lock);
    throw;
  }
  impl->path = path;
  impl->aside = tmp;
  impl->place_lock = lock;
  return impl;
}

}  // namespace detail

void ResultsWriter::Impl::place_aside() {
  // The journal first (it replaces the previous file's, whose lock this writer holds), then the file:
  // a kill in between leaves the previous file with a journal of another file holding no commit,
  // which the next writer replaces.
  const std::string jp = journal_path(path), aside_jp = journal_path(aside);
  if (::rename(aside_jp.c_str(), jp.c_str()) != 0) fail("cannot rename journal " + aside_jp + " to " + jp);
  if (::rename(aside.c_str(), path.c_str()) != 0) {
    const int e = errno;
    ::rename(jp.c_str(), aside_jp.c_str());
    errno = e;
    fail("cannot rename " + aside + " over " + path + ": " + std::strerror(e));
  }
  rename_journal_file(file, path);
  if (opt.durable) {  // the renames, against power loss
    const std::string dir = std::filesystem::path(path).parent_path().string();
    const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) ::fsync(fd), ::close(fd);
  }
  ::close(place_lock);
  place_lock = -1;
  aside.clear();
}

void ResultsWriter::Impl::drop_aside() {
  ::unlink(journal_path(aside).c_str());
  ::unlink(aside.c_str());
  if (place_lock >= 0) ::close(place_lock);
  place_lock = -1;
  aside.clear();
}

}  // namespace ks::store
