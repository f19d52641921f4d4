// The store's single-writer lock and recovery against readers, second writers and files changed
// after a crash: readers never modify a file or its journal; a writer replays or truncates only a
// journal that belongs to the file as it is. The writer's open is stopped at each of its steps by
// the driver's test pause points (KS_STORE_TEST_PAUSE, journal_format.hpp), the crash points by
// KS_STORE_TEST_CRASH (journal_vfd.cpp), both in store_writer_helper processes.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "store/store.hpp"
#include "store_checks.hpp"
#include "store_testgen.hpp"

namespace {
namespace fs = std::filesystem;
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;

constexpr std::int64_t kRuns = 60;

/// A store_writer_helper process writing kRuns runs into `path` (resuming it when it exists).
struct Helper {
  pid_t pid = -1;
  std::string err_path;
  Helper(const std::string& path, const std::string& err, const std::vector<std::pair<const char*, std::string>>& env,
         const std::vector<std::string>& extra = {})
      : err_path(err) {
    pid = fork();
    if (pid == 0) {
      for (auto& [k, v] : env) setenv(k, v.c_str(), 1);
      int devnull = open("/dev/null", O_WRONLY);
      dup2(devnull, 1);
      int e = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(e, 2);
      std::vector<std::string> args = {STORE_WRITER_HELPER, path, std::to_string(kRuns), "--flush-every", "4",
                                       "--no-shuffle"};
      args.insert(args.end(), extra.begin(), extra.end());
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
  }
  /// Waits until the process stops (true) or exits (false; *code = its exit code or -signal).
  bool wait_stop_or_exit(int* code) {
    int st = 0;
    waitpid(pid, &st, WUNTRACED);
    if (WIFSTOPPED(st)) return true;
    *code = WIFEXITED(st) ? WEXITSTATUS(st) : -WTERMSIG(st);
    return false;
  }
  int finish() {
    kill(pid, SIGCONT);
    int code = 0;
    while (wait_stop_or_exit(&code)) kill(pid, SIGCONT);
    return code;
  }
  std::string stderr_text() const { return slurp(err_path); }
};

/// A file's bytes and identity (empty, 0 when absent).
struct Snapshot {
  bool exists = false;
  std::string bytes;
  ino_t ino = 0;
  bool operator==(const Snapshot&) const = default;
};
Snapshot snap(const std::string& p) {
  Snapshot s;
  struct stat st{};
  if (::stat(p.c_str(), &st) != 0) return s;
  s.exists = true;
  s.bytes = slurp(p);
  s.ino = st.st_ino;
  return s;
}

/// The number of done runs, each checked against the generator (records only).
std::int64_t done_runs_checked(const std::string& path) {
  ResultsReader r(path);
  const auto done = r.done_mask();
  std::vector<std::vector<Cell>> cols;
  for (auto& c : r.columns()) cols.push_back(r.read_column(c.name));
  std::int64_t n = 0;
  for (std::int64_t id = 0; id < r.n_runs(); ++id) {
    if (!done[static_cast<std::size_t>(id)]) continue;
    ++n;
    const Record want = test_record(id);
    for (std::size_t c = 0; c < cols.size(); ++c) {
      const Cell& g = cols[c][static_cast<std::size_t>(id)];
      const bool same = std::holds_alternative<double>(g)
                            ? std::memcmp(&std::get<double>(g), &std::get<double>(want.cells[c]), 8) == 0
                            : g == want.cells[c];
      EXPECT_TRUE(same) << path << ": run " << id << " column " << c;
    }
  }
  return n;
}

/// A results file as a writer killed inside commit `commit` left it (phase: journal_half = before
/// the commit point, journal_done = committed in the journal, not applied), or a cleanly closed one.
void make_file(const std::string& path, const std::string& crash) {
  Helper h(path, path + ".make.err", crash.empty() ? std::vector<std::pair<const char*, std::string>>{}
                                                   : std::vector<std::pair<const char*, std::string>>{
                                                         {"KS_STORE_TEST_CRASH", crash}});
  int code = 0;
  ASSERT_FALSE(h.wait_stop_or_exit(&code));
  ASSERT_EQ(code, crash.empty() ? 0 : 86) << h.stderr_text();
}

// ------------------------------------------------------------------------------------------------
TEST(StoreLock, AReaderAndASecondWriterAtEveryStepOfAWritersOpen) {
  // Writer A is stopped at one step of its open; a reader opens the file (it must read it and
  // change no byte of the file or the journal); then writer B starts and stops once it is a
  // writer. Exactly one of A and B may become the writer: the one that holds the journal's lock.
  struct Case {
    std::string crash;  // how the file was left: "" closed cleanly, else a crash in the 3rd commit
    std::vector<std::string> a_holds, b_wins;  // steps at which A holds the lock / does not yet
  };
  const std::vector<Case> cases = {
      {"", {"journal_linked", "recovered", "ready"}, {"data_opened", "journal_created", "journal_created_locked"}},
      {"3:journal_done", {"journal_locked", "recovered", "ready"}, {"data_opened", "journal_opened"}},
      {"3:journal_half", {"journal_locked", "recovered", "ready"}, {"data_opened", "journal_opened"}},
  };
  TempDir td;
  int interleavings = 0;
  for (const Case& c : cases) {
    std::vector<std::pair<std::string, bool>> steps;
    for (auto& s : c.a_holds) steps.emplace_back(s, true);
    for (auto& s : c.b_wins) steps.emplace_back(s, false);
    for (auto& [step, a_holds] : steps) {
      const std::string how = c.crash.empty() ? std::string("clean") : c.crash.substr(2), tag = how + "/" + step;
      const std::string path = td.file(how + "_" + step + ".h5"), jp = path + ".journal";
      make_file(path, c.crash);
      const std::int64_t done_before = done_runs_checked(path);
      Helper a(path, path + ".a.err", {{"KS_STORE_TEST_PAUSE", step}});
      int code = 0;
      ASSERT_TRUE(a.wait_stop_or_exit(&code)) << tag << ": A did not reach the step, exit " << code << " "
                                              << a.stderr_text();
      const Snapshot file0 = snap(path), journal0 = snap(jp);
      EXPECT_GE(done_runs_checked(path), done_before) << tag;  // the reader reads the committed state
      EXPECT_EQ(snap(path), file0) << tag << ": the reader changed the file";
      EXPECT_EQ(snap(jp), journal0) << tag << ": the reader changed or removed the journal";
      Helper b(path, path + ".b.err", {{"KS_STORE_TEST_PAUSE", "ready"}});
      const bool b_writer = b.wait_stop_or_exit(&code);
      if (a_holds) {
        EXPECT_FALSE(b_writer) << tag << ": a second writer got in";
        if (!b_writer) {
          EXPECT_EQ(code, 1) << tag;
          EXPECT_NE(b.stderr_text().find("being written by another process"), std::string::npos) << b.stderr_text();
        }
        EXPECT_EQ(snap(path), file0) << tag << ": the refused writer changed the file";
        EXPECT_EQ(a.finish(), 0) << tag << " " << a.stderr_text();
        if (b_writer) {
          b.finish();
        }
      } else {
        EXPECT_TRUE(b_writer) << tag << ": B (exit " << code << ") " << b.stderr_text();
        const int a_code = a.finish();  // B holds the lock now: A must give up
        EXPECT_EQ(a_code, 1) << tag << ": two writers at once";
        EXPECT_NE(a.stderr_text().find("being written by another process"), std::string::npos) << a.stderr_text();
        if (b_writer) {
          EXPECT_EQ(b.finish(), 0) << tag << " " << b.stderr_text();
        }
      }
      EXPECT_FALSE(fs::exists(jp)) << tag;
      EXPECT_TRUE(opens_with_plain_hdf5(path)) << tag;
      EXPECT_EQ(done_runs_checked(path), kRuns) << tag;
      for (auto& e : fs::directory_iterator(td.dir))  // no temporary journal left behind
        EXPECT_EQ(e.path().string().find(".journal.new-"), std::string::npos) << e.path();
      ++interleavings;
    }
  }
  std::cout << "[ writer lock ] " << interleavings << " interleavings (reader + second writer at each step of "
            << "a writer's open, on clean, committed-unapplied and half-journaled files)" << std::endl;
}

// ------------------------------------------------------------------------------------------------
/// What another program might do to a file after its writer was killed.
enum class Change { hdf5_append, copy_over_in_place, byte_in_place };

void change_file(const std::string& path, Change how, const std::string& other) {
  if (how == Change::hdf5_append) {  // as h5py in append mode: HDF5's own driver, a new dataset
    hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    hsize_t n = 1000;
    hid_t s = H5Screate_simple(1, &n, nullptr);
    hid_t d = H5Dcreate2(f, "added_by_another_program", H5T_NATIVE_DOUBLE, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    std::vector<double> v(n, 1.5);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(d);
    H5Sclose(s);
    ASSERT_GE(H5Fclose(f), 0);
  } else if (how == Change::copy_over_in_place) {  // cp other path: same inode, other bytes
    const std::string bytes = slurp(other);
    int fd = ::open(path.c_str(), O_WRONLY | O_TRUNC);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::write(fd, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
    ::close(fd);
  } else {  // one byte rewritten in place, size unchanged
    int fd = ::open(path.c_str(), O_RDWR);
    ASSERT_GE(fd, 0);
    const off_t at = 48;  // just past the superblock: the root group's object header
    unsigned char b = 0;
    ASSERT_EQ(::pread(fd, &b, 1, at), 1);
    b ^= 0x5a;
    ASSERT_EQ(::pwrite(fd, &b, 1, at), 1);
    ::close(fd);
  }
}

TEST(StoreRecovery, AStaleJournalAfterAnExternalChangeLeavesTheFileUntouched) {
  TempDir td;
  const std::string other = td.file("other.h5");
  make_file(other, "");
  struct Case {
    std::string crash;
    Change how;
    const char* name;
  };
  const std::vector<Case> cases = {
      {"3:journal_done", Change::hdf5_append, "commit waiting, then an HDF5 append"},
      {"3:journal_done", Change::copy_over_in_place, "commit waiting, then another file copied over it"},
      {"3:journal_done", Change::byte_in_place, "commit waiting, then a byte rewritten in place"},
      {"5:journal_half", Change::hdf5_append, "half a commit journaled, then an HDF5 append"},
      {"5:journal_half", Change::byte_in_place, "half a commit journaled, then a byte rewritten in place"},
  };
  int k = 0;
  for (const Case& c : cases) {
    const std::string path = td.file("stale" + std::to_string(k++) + ".h5"), jp = path + ".journal";
    make_file(path, c.crash);
    change_file(path, c.how, other);
    const Snapshot file0 = snap(path), journal0 = snap(jp);
    ASSERT_TRUE(journal0.exists) << c.name;
    const bool pending = c.crash.find("journal_done") != std::string::npos;
    // a reader: reads the file as it is (nothing waits in the journal), or refuses and says why
    std::string reader_says;
    try {
      ResultsReader r(path);
      (void)r.done_mask();
    } catch (const StoreError& e) {
      reader_says = e.what();
    }
    if (pending) {
      EXPECT_NE(reader_says.find("does not match the file"), std::string::npos) << c.name << ": " << reader_says;
      EXPECT_NE(reader_says.find(jp), std::string::npos) << reader_says;
    } else if (c.how == Change::hdf5_append) {
      EXPECT_EQ(reader_says, "") << c.name;  // (a flipped byte may leave HDF5 unable to read the file)
    }
    EXPECT_EQ(snap(path), file0) << c.name << ": the reader changed the file";
    EXPECT_EQ(snap(jp), journal0) << c.name << ": the reader changed the journal";
    // a writer (resume): refuses, says what it found, writes nothing
    Helper w(path, path + ".w.err", {});
    int code = 0;
    ASSERT_FALSE(w.wait_stop_or_exit(&code));
    const std::string says = w.stderr_text();
    EXPECT_EQ(code, 1) << c.name << ": " << says;
    EXPECT_NE(says.find("does not match its journal"), std::string::npos) << c.name << ": " << says;
    EXPECT_NE(says.find("nothing was written"), std::string::npos) << says;
    EXPECT_EQ(std::count(says.begin(), says.end(), '\n'), 1) << "one line: " << says;
    EXPECT_EQ(snap(path), file0) << c.name << ": the refused writer changed the file";
    EXPECT_EQ(snap(jp), journal0) << c.name << ": the refused writer changed the journal";
    std::cout << "[ stale journal ] " << c.name << ": " << says;
    // the way out it names: without the journal the file is used as it is
    fs::remove(jp);
    if (c.how == Change::hdf5_append) {
      Helper again(path, path + ".again.err", {});
      ASSERT_FALSE(again.wait_stop_or_exit(&code));
      EXPECT_EQ(code, 0) << again.stderr_text();
      EXPECT_EQ(done_runs_checked(path), kRuns) << c.name;
    }
  }
}

TEST(StoreRecovery, ReadersChangeNoByteOfACrashedFile) {
  // Every way a writer can die inside a commit, and a reader after each: the file and the journal
  // keep their bytes; the reader sees the last committed state (from the journal when the commit
  // was not applied yet); the next writer then applies it and finishes.
  TempDir td;
  int checked = 0;
  std::int64_t most = 0;
  for (int commit : {2, 5, 9}) {
    std::int64_t done_half = -1;
    for (const std::string phase : {"journal_half", "journal_done", "apply_half"}) {
      const std::string path = td.file(phase + std::to_string(commit) + ".h5"), jp = path + ".journal";
      make_file(path, std::to_string(commit) + ":" + phase);
      const Snapshot file0 = snap(path), journal0 = snap(jp);
      const std::int64_t done = done_runs_checked(path);
      EXPECT_EQ(snap(path), file0) << phase << commit;
      EXPECT_EQ(snap(jp), journal0) << phase << commit;
      if (phase == "journal_half") done_half = done;
      else EXPECT_GE(done, done_half) << phase << commit << ": a commit complete in the journal is seen";
      most = std::max(most, done);
      Helper w(path, path + ".w.err", {});
      int code = 0;
      ASSERT_FALSE(w.wait_stop_or_exit(&code));
      EXPECT_EQ(code, 0) << w.stderr_text();
      EXPECT_FALSE(fs::exists(jp));
      EXPECT_EQ(done_runs_checked(path), kRuns);
      ++checked;
    }
  }
  EXPECT_GT(most, 0);
  std::cout << "[ read-only ] " << checked << " crashed files read with no byte changed (up to " << most
            << " done runs)" << std::endl;
}

}  // namespace

namespace {
/// The PID of a process that has ended (a child that exited and was reaped).
pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}
void touch(const std::string& path) { std::ofstream(path) << "partial"; }
}  // namespace

TEST(StoreRecovery, AWriterRemovesTheTemporaryFilesOfKilledProcessesOnly) {
  TempDir td;
  const std::string path = td.file("o.h5");
  const std::string dead = std::to_string(dead_pid()), live = std::to_string(::getpid());
  const std::vector<std::string> orphans = {".o.h5.tmp-" + dead + "-0", ".o.h5.tmp-" + dead + "-7",
                                            "o.h5.journal.new-" + dead + "-1"};
  const std::vector<std::string> kept = {".o.h5.tmp-" + live + "-3", "o.h5.journal.new-" + live + "-2",
                                         ".other.h5.tmp-" + dead + "-0", ".o.h5.tmp-x-1", "o.h5.tmp-" + dead + "-0"};
  for (const auto& n : orphans) touch(td.file(n));
  for (const auto& n : kept) touch(td.file(n));
  ResultsWriter::create(path, test_meta(), test_columns(), 3)->close();
  for (const auto& n : orphans) EXPECT_FALSE(fs::exists(td.file(n))) << n;
  for (const auto& n : kept) EXPECT_TRUE(fs::exists(td.file(n))) << n;
}
