// Replacing a results file by another one built beside it (see store.hpp, FORMAT.md "Creation,
// overwrite, resume").
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "store/journal/format.hpp"
#include "store/journal/vfd.hpp"
#include "store/store.hpp"

namespace ks::store {
using namespace detail;

namespace {
void fsync_dir(const std::string& dir) {
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}
std::string dir_of(const std::string& path) {
  const std::filesystem::path p(path);
  return p.parent_path().empty() ? std::string(".") : p.parent_path().string();
}
}  // namespace

std::string staging_path(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  journal::remove_orphans(path);  // the staged files of killed processes
  const std::filesystem::path p(path);
  return (std::filesystem::path(dir_of(path)) / ("." + p.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                                                 "-staged-" + std::to_string(counter++) + ".h5"))
      .string();
}

void replace_results_file(const std::string& from, const std::string& path, const StoreOptions& options) {
  // The writer lock of `path`, as create() takes it: a live writer of the old file refuses the
  // replacement, and the journal of the old file (a crashed writer's) must never touch the new one.
  const std::string jp = journal_path(path);
  const int lock = journal::acquire_lock(jp, [](int) { return true; });
  if (lock < 0) throw StoreError(path, journal_last_error() + " (not replaced)");
  struct Unlock {
    int fd;
    ~Unlock() { ::close(fd); }
  } unlock{lock};
  if (options.durable) {
    int fd = ::open(from.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd >= 0) ::fsync(fd), ::close(fd);
  }
  ::unlink(jp.c_str());
  if (::rename(from.c_str(), path.c_str()) != 0)
    throw StoreError(path, "cannot rename " + from + " into place: " + std::strerror(errno));
  if (options.durable) fsync_dir(dir_of(path));
}

void remove_results_file(const std::string& path) {
  ::unlink(journal_path(path).c_str());
  ::unlink(path.c_str());
}

}  // namespace ks::store
