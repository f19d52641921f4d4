// The ksjournal writer lock and the test pause points of the writer's open (see journal_format.hpp,
// FORMAT.md "Crash safety"). The lock is the flock of the journal; nobody ever deletes a journal
// without holding it, and a journal is visible under its name only once it is locked.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "store/journal/format.hpp"

namespace ks::store::detail::journal {

void pause_point(const char* step) {
  const char* want = std::getenv("KS_STORE_TEST_PAUSE");
  if (want && std::strcmp(want, step) == 0) ::raise(SIGSTOP);
}

namespace {
std::atomic<unsigned> g_tmp_counter{0};

/// flock(LOCK_EX) without blocking for long: another writer holds it for its whole life, but
/// create(..., overwrite) or a writer that is about to unlink a journal holds it only for a moment.
bool lock_briefly(int jfd) {
  for (int tries = 0; tries < 20; ++tries) {
    if (::flock(jfd, LOCK_EX | LOCK_NB) == 0) return true;
    if (errno != EWOULDBLOCK && errno != EINTR) return false;
    ::usleep(50000);
  }
  return false;
}

/// True when `jfd` is the file the name `jp` points to now (not unlinked or replaced meanwhile).
bool still_named(int jfd, const std::string& jp) {
  struct stat a{}, b{};
  return ::fstat(jfd, &a) == 0 && ::stat(jp.c_str(), &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}
}  // namespace

namespace {
/// The PID in "PID-N" at the start of `rest`, or 0.
pid_t leading_pid(const std::string& rest) {
  pid_t pid = 0;
  std::size_t i = 0;
  for (; i < rest.size() && rest[i] >= '0' && rest[i] <= '9' && i < 9; ++i) pid = pid * 10 + (rest[i] - '0');
  return i > 0 && i < rest.size() && rest[i] == '-' ? pid : 0;
}
}  // namespace

void remove_orphans(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path p(name);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const std::string base = p.filename().string();
  const std::string prefixes[] = {"." + base + ".tmp-", base + ".new-"};
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string f = it->path().filename().string();
    for (const std::string& prefix : prefixes) {
      if (f.size() <= prefix.size() || f.compare(0, prefix.size(), prefix) != 0) continue;
      const pid_t pid = leading_pid(f.substr(prefix.size()));
      if (pid > 0 && ::kill(pid, 0) != 0 && errno == ESRCH) ::unlink(it->path().c_str());
    }
  }
}

int acquire_lock(const std::string& jp, const std::function<bool(int jfd)>& init) {
  const std::string busy = "results file is being written by another process (its journal " + jp + " is locked)";
  for (int round = 0; round < 100; ++round) {
    int jfd = ::open(jp.c_str(), O_RDWR | O_CLOEXEC);
    if (jfd >= 0) {  // a crashed writer's journal, or a live writer's
      pause_point("journal_opened");
      if (!lock_briefly(jfd)) {
        ::close(jfd);
        set_error(busy, 0);
        return -1;
      }
      pause_point("journal_locked");
      if (still_named(jfd, jp)) return jfd;
      ::close(jfd);  // its writer deleted it (a clean close) between our open and our lock: again
      continue;
    }
    if (errno != ENOENT) {
      set_error("cannot open journal " + jp, errno);
      return -1;
    }
    remove_orphans(jp);
    const std::string tmp = jp + ".new-" + std::to_string(::getpid()) + "-" + std::to_string(g_tmp_counter++);
    jfd = ::open(tmp.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (jfd < 0) {
      set_error("cannot create journal " + tmp, errno);
      return -1;
    }
    pause_point("journal_created");
    if (::flock(jfd, LOCK_EX | LOCK_NB) != 0 || !init(jfd)) {  // no one else knows this name yet
      set_error("cannot write journal " + tmp, errno);
      ::close(jfd);
      ::unlink(tmp.c_str());
      return -1;
    }
    pause_point("journal_created_locked");
    int rc = ::link(tmp.c_str(), jp.c_str());  // atomic "create if absent", already locked
    int e = errno;
    ::unlink(tmp.c_str());
    if (rc == 0) {
      pause_point("journal_linked");
      return jfd;
    }
    ::close(jfd);
    if (e == EEXIST) continue;  // another writer's journal appeared meanwhile: lock that one (or fail)
    // A file system without hard links: create the name exclusively, then lock it. Another writer
    // may open it before the lock; then it finds an empty journal and holds the lock, and this one
    // fails below: never two writers.
    jfd = ::open(jp.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (jfd < 0) {
      if (errno == EEXIST) continue;
      set_error("cannot create journal " + jp, errno);
      return -1;
    }
    if (!lock_briefly(jfd) || !still_named(jfd, jp)) {  // (a reader's shared lock may be held a moment)
      ::close(jfd);
      set_error(busy, 0);
      return -1;
    }
    if (!init(jfd)) {
      set_error("cannot write journal " + jp, errno);
      ::unlink(jp.c_str());  // ours, locked, and holding no commit: no partial header left behind
      ::close(jfd);
      return -1;
    }
    return jfd;
  }
  set_error(busy, 0);
  return -1;
}

}  // namespace ks::store::detail::journal
