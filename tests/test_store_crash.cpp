// The HDF5 results store under SIGKILL at random moments, and a reader following a live writer.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include "store/store.hpp"
#include "store_checks.hpp"
#include "store_testgen.hpp"

namespace {
namespace fs = std::filesystem;
using namespace ks;
using namespace ks::store;
using namespace ks::store_test;


/// A store_writer_helper process with `args`; KS_STORE_TEST_CRASH = crash_env when not empty.
pid_t spawn_helper(const std::vector<std::string>& args, const std::string& crash_env = "") {
  pid_t pid = fork();
  if (pid == 0) {
    if (!crash_env.empty()) setenv("KS_STORE_TEST_CRASH", crash_env.c_str(), 1);
    int devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    std::vector<char*> argv;
    std::string exe = STORE_WRITER_HELPER;
    argv.push_back(exe.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

TEST(StoreCrash, ExitWithoutCloseKeepsExactlyTheFlushedRuns) {
  TempDir td;
  const std::string path = td.file("exit.h5");
  pid_t pid = fork();
  if (pid == 0) {
    StoreOptions opt;
    opt.flush_every_runs = 0;
    opt.flush_every_seconds = 0;
    auto w = make_writer(path, 50, opt);
    for (std::int64_t id = 0; id < 20; ++id) w->write_run(id, test_record(id), test_history(id));
    w->flush();
    for (std::int64_t id = 20; id < 50; ++id) w->write_run(id, test_record(id), test_history(id));
    _exit(0);  // dies with 30 unflushed runs (and HDF5's caches) in memory
  }
  int st = 0;
  waitpid(pid, &st, 0);
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  EXPECT_TRUE(opens_with_plain_hdf5(path));  // before any recovery
  ResultsReader r(path);
  auto d = r.done_mask();
  for (std::int64_t id = 0; id < 50; ++id) EXPECT_EQ(d[static_cast<std::size_t>(id)], id < 20 ? 1 : 0) << id;
  EXPECT_EQ(verify_done_runs(r), 20);
}

TEST(StoreCrash, SigkillAtRandomMomentsThenResume) {
  TempDir td;
  const std::string ref = td.file("ref.h5"), path = td.file("killed.h5");
  const std::int64_t n = 2000;
  {
    pid_t pid = spawn_helper({ref, std::to_string(n), "--no-shuffle", "--landscape"});
    int st = 0;
    waitpid(pid, &st, 0);
    ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  }
  std::mt19937 rng(20261123);
  const int iterations = 30;
  int kills_before_file = 0, kills_pending_commit = 0, kills_mid_epoch = 0, finished_early = 0;
  std::int64_t last_done = 0;
  std::vector<std::int64_t> done_counts;
  for (int it = 0; it < iterations; ++it) {
    if (it % 6 == 0) {  // start over now and then, so that some kills land during creation
      fs::remove(path);
      fs::remove(path + ".journal");
      last_done = 0;
    }
    const int flush_every = std::vector<int>{1, 2, 5, 16}[static_cast<std::size_t>(it % 4)];
    const int delay_us = std::vector<int>{0, 100, 300}[static_cast<std::size_t>(it % 3)];
    pid_t pid = spawn_helper({path, std::to_string(n), "--delay-us", std::to_string(delay_us), "--flush-every",
                              std::to_string(flush_every), "--landscape"});
    const int max_us = it % 6 == 0 ? 6000 : 150000;  // right after a fresh start: aim at the creation
    if (it % 6 != 0)  // otherwise aim at a writer that has its file (wait on its progress, however slow)
      while (!fs::exists(path)) {
        siginfo_t si{};  // (WNOWAIT: an exited writer stays to be reaped below)
        if (waitid(P_PID, static_cast<id_t>(pid), &si, WEXITED | WNOHANG | WNOWAIT) != 0 || si.si_pid != 0) break;
        std::this_thread::yield();
      }
    std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(500, max_us)(rng)));
    kill(pid, SIGKILL);
    int st = 0;
    waitpid(pid, &st, 0);
    if (!WIFSIGNALED(st)) ++finished_early;
    if (!fs::exists(path)) {  // killed while creating: no file, and no garbage at the final name
      ++kills_before_file;
      for (auto& e : fs::directory_iterator(td.dir))
        if (e.path().filename() != "ref.h5") fs::remove(e.path());  // stale temp files of the dead writer
      continue;
    }
    if (fs::exists(path + ".journal")) ++kills_mid_epoch;
    const bool pending = journal_has_commit(path);
    if (pending) {
      ++kills_pending_commit;
    } else {
      EXPECT_TRUE(opens_with_plain_hdf5(path)) << "iteration " << it << ": file does not open before recovery";
    }
    const std::string file_before = slurp(path), journal_before = slurp(path + ".journal");
    std::int64_t done = 0;
    {  // readers change nothing: a commit the writer did not apply is read from the journal
      ResultsReader r(path);
      done = verify_done_runs(r);
    }
    EXPECT_EQ(slurp(path), file_before) << "iteration " << it << ": a reader changed the file";
    EXPECT_EQ(slurp(path + ".journal"), journal_before) << "iteration " << it << ": a reader changed the journal";
    EXPECT_GE(done, last_done) << "iteration " << it << ": committed runs were lost";
    last_done = done;
    done_counts.push_back(done);
  }
  std::cout << "[ kill -9 ] " << iterations << " kills: " << kills_before_file << " before the file existed, "
            << kills_mid_epoch << " with a live journal, " << kills_pending_commit
            << " between journal commit and apply, " << finished_early
            << " finished before the kill; done runs after each kill:";
  for (auto d : done_counts) std::cout << ' ' << d;
  std::cout << std::endl;
  EXPECT_LT(finished_early, iterations / 2);  // the kills really hit running writers
  // finish: resume to the end, then the file equals the uninterrupted one
  pid_t pid = spawn_helper({path, std::to_string(n), "--landscape"});
  int st = 0;
  waitpid(pid, &st, 0);
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  ResultsReader a(ref), b(path);
  EXPECT_EQ(verify_done_runs(b), n);
  EXPECT_EQ(a.done_mask(), b.done_mask());
  for (auto& c : a.columns()) {
    auto x = a.read_column(c.name), y = b.read_column(c.name);
    for (std::size_t i = 0; i < x.size(); ++i) EXPECT_TRUE(same_cell(x[i], y[i])) << c.name << " row " << i;
  }
  for (std::int64_t id = 0; id < n; ++id) expect_same_history(b.read_history(id), a.read_history(id), id);
  EXPECT_EQ(b.landscapes(), a.landscapes());
}

TEST(StoreConcurrent, ReaderFollowsAWriterInAnotherProcess) {
  // The reader reads while the writer commits, as fast as it can; the writer also stops itself
  // after three flushes mid-sweep (--stop-after-runs), and the reader must then get a consistent
  // snapshot at once. The checks depend on the writer's progress only, never on timing.
  TempDir td;
  const std::string path = td.file("live.h5");
  const std::int64_t n = 1200;
  pid_t pid = spawn_helper({path, std::to_string(n), "--delay-us", "200", "--flush-every", "64",
                            "--stop-after-runs", "300,600,900"});
  std::unique_ptr<ResultsReader> r;
  int snapshots = 0, mid = 0, threw = 0, stale = 0, stale_wrong = 0, stops = 0;
  std::int64_t last = 0;
  int st = 0;
  for (;;) {
    const pid_t w = waitpid(pid, &st, WNOHANG | WUNTRACED);
    if (w == pid && !WIFSTOPPED(st)) break;
    const bool stopped = w == pid;  // the writer waits, at a committed state, until SIGCONT
    if (!stopped) std::this_thread::yield();
    std::string msg;
    std::int64_t done = 0;
    try {
      if (!r) {
        if (!fs::exists(path)) continue;
        r = std::make_unique<ResultsReader>(path);
      } else {
        r->refresh();
      }
      msg = check_snapshot(*r, &done, 9);  // histories: every 9th run and the newest ones
    } catch (const StoreError& e) {
      EXPECT_FALSE(stopped) << "a stopped writer's file must read: " << e.what();
      ++threw;  // metadata changed under this reader (HDF5 checksum/EOA checks): refresh and retry
      if (stopped) kill(pid, SIGCONT);
      continue;
    }
    const bool consistent = r->unchanged_since_open();
    if (stopped) {
      EXPECT_TRUE(consistent) << "nothing changes while the writer is stopped";
      ++stops;
      kill(pid, SIGCONT);
    }
    if (!consistent) {  // the writer committed during the reads: not one snapshot
      ++stale;
      if (!msg.empty()) ++stale_wrong;
      continue;
    }
    EXPECT_EQ(msg, "") << "a consistent snapshot with a wrong done run";
    EXPECT_GE(done, last);
    last = done;
    ++snapshots;
    if (done > 0 && done < n) ++mid;
  }
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  std::cout << "[ live reader ] " << snapshots << " consistent snapshots (" << mid << " mid-sweep, " << stops
            << " while the writer was stopped); discarded: " << threw << " threw, " << stale
            << " saw a commit during the reads (" << stale_wrong << " of them had missing/odd newest runs)"
            << std::endl;
  EXPECT_EQ(stops, 3);
  EXPECT_GE(mid, 3);
  ASSERT_TRUE(r);
  r->refresh();
  EXPECT_TRUE(r->unchanged_since_open());
  EXPECT_EQ(verify_done_runs(*r), n);
}

}  // namespace
