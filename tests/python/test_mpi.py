"""End-to-end tests of distributed sweeps: `mpirun -np 2 kinesweep run` gives the single-process
file (every /runs column but wall_time bitwise, every history, every landscape); a rank killed with
SIGKILL mid-run loses nothing done, and `--resume` completes the study.

usage: /usr/bin/python3 test_mpi.py KINESWEEP_BINARY
"""
import glob
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import h5py
import numpy as np

import hashlib

from e2e_common import SWEEP as SWEEP_COMMON, TempDirTest, bitwise_equal, make_v1, runs_table, same_histories

KS = None
MPIRUN = ["mpirun", "--oversubscribe", "--allow-run-as-root", "--bind-to", "none", "-np", "2"]

SWEEP = SWEEP_COMMON.replace('name = "e2e"', 'name = "mpi_e2e"')

# Long enough (several seconds on 2 ranks) to kill a rank in the middle.
LONG = SWEEP.replace('name = "mpi_e2e"', 'name = "mpi_kill"').replace("step = 1 }", "step = 0.1 }")


def run(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True, timeout=600)


def mpirun(*args):
    return subprocess.run([*MPIRUN, KS, *args], capture_output=True, text=True, timeout=600)


def descendants(root):
    """pids of every process below `root` (by /proc/*/stat ppid)."""
    children = {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
                children.setdefault(ppid, []).append(int(d))
            except OSError:
                pass
    out, todo = [], [root]
    while todo:
        for c in children.get(todo.pop(), []):
            out.append(c)
            todo.append(c)
    return out


def start_with_rank1(test, study, out, *args):
    """mpirun of `kinesweep run STUDY -o OUT` (2 ranks, 1 thread each) once rank 1 has made its
    shard: (the mpirun process, rank 1's pid); the test fails when rank 1 does not show up."""
    p = subprocess.Popen([*MPIRUN, KS, "run", study, "-o", out, "-q", "--threads", "1", *args],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    victim, deadline = None, time.time() + 60
    while time.time() < deadline and p.poll() is None:
        victim = rank_pid(p.pid, 1)
        if victim and os.path.exists(out + ".rank1.h5"):
            break
        time.sleep(0.05)
    test.assertIsNotNone(victim, "rank 1 not found")
    return p, victim


def rank_pid(mpirun_pid, rank):
    for pid in descendants(mpirun_pid):
        try:
            with open(f"/proc/{pid}/environ", "rb") as f:
                env = f.read().split(b"\0")
            with open(f"/proc/{pid}/comm") as f:
                comm = f.read().strip()
        except OSError:
            continue
        if comm in ("kinesweep", "kinesweep-mpi") and f"OMPI_COMM_WORLD_RANK={rank}".encode() in env:
            return pid
    return None


class Base(TempDirTest):

    def assertSameFile(self, a, b):
        ta, tb = runs_table(a), runs_table(b)
        self.assertEqual(ta.keys(), tb.keys())
        for k in ta:
            self.assertTrue(bitwise_equal(ta[k], tb[k]), k)
        with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
            self.assertTrue(np.all(fb["runs"]["done"][()] == 1))
            same_histories(self, fa, fb)
            self.assertEqual(set(fa["landscapes"]), set(fb["landscapes"]))
            for l in fa["landscapes"]:
                self.assertEqual(set(fa["landscapes"][l]), set(fb["landscapes"][l]))
                for k in fa["landscapes"][l]:
                    self.assertTrue(bitwise_equal(fa["landscapes"][l][k][()], fb["landscapes"][l][k][()]), l + "/" + k)
            self.assertEqual(fa.attrs["study_sha256"], fb.attrs["study_sha256"])


class Merged(Base):
    def test_two_ranks_give_the_single_process_file(self):
        study = self.write("s.toml", SWEEP)
        ref, out = os.path.join(self.dir, "ref.h5"), os.path.join(self.dir, "mpi.h5")
        r = run("run", study, "-o", ref, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        r = mpirun("run", study, "-o", out, "-q", "--threads", "1")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("distributed: 2 ranks", r.stdout)
        self.assertIn("1002 runs (1002 computed now, 0 already in the file)", r.stdout)
        self.assertSameFile(ref, out)
        self.assertEqual(glob.glob(out + ".rank*"), [])  # shards deleted after the merge
        # the file exists: refused without --resume / --overwrite, replaced with --overwrite
        r = mpirun("run", study, "-o", out, "-q")
        self.assertEqual(r.returncode, 1)
        self.assertIn("--overwrite", r.stderr)
        r = mpirun("run", study, "-o", out, "-q", "--overwrite")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertSameFile(ref, out)
        # resuming a complete file computes nothing
        r = mpirun("run", study, "-o", out, "-q", "--resume")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("(0 computed now, 1002 already in the file)", r.stdout)
        self.assertSameFile(ref, out)
        # a results file of format version 1 is refused before any rank computes, and left as it was
        v1 = os.path.join(self.dir, "v1.h5")
        make_v1(out, v1)
        with h5py.File(v1, "r+") as f:
            f["runs"]["done"][:10] = 0
        before = hashlib.sha256(open(v1, "rb").read()).hexdigest()
        r = mpirun("run", study, "-o", v1, "-q", "--resume")
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertIn("format v1", r.stderr)
        self.assertEqual(hashlib.sha256(open(v1, "rb").read()).hexdigest(), before)
        self.assertEqual(glob.glob(v1 + ".rank*"), [])


# Three /runs chunks and a part (16384 rows each): shards hold whole chunks, which the merge copies
# as stored, and the tail's shared chunk, which it assembles row by row.
MANY = """[study]
name = "mpi_many"
histories = "none"
[[block]]
name = "grid"
kind = "trajectory"
[block.axes]
method = ["local_weighted"]
alpha1A = { from = -20, to = 30, count = 230 }
k = { from = 0, to = 1, count = 230 }
"""


class MergedByChunks(Base):
    def test_a_study_of_several_chunks_gives_the_single_process_file_and_summary(self):
        study = self.write("many.toml", MANY)
        ref, out = os.path.join(self.dir, "ref.h5"), os.path.join(self.dir, "mpi.h5")
        r0 = run("run", study, "-o", ref)
        self.assertEqual(r0.returncode, 0, r0.stderr)
        r = mpirun("run", study, "-o", out, "--threads", "1")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertSameFile(ref, out)
        with h5py.File(ref, "r") as fa, h5py.File(out, "r") as fb:  # chunk for chunk the same bytes
            for c in fa["runs"]:
                if c == "wall_time" or fa["runs"][c].chunks is None:
                    continue
                da, db = fa["runs"][c], fb["runs"][c]
                self.assertEqual(da.id.get_num_chunks(), db.id.get_num_chunks(), c)
                for i in range(da.id.get_num_chunks()):
                    off = da.id.get_chunk_info(i).chunk_offset
                    self.assertEqual(da.id.read_direct_chunk(off)[1], db.id.read_direct_chunk(off)[1], f"{c} {off}")
        # the run summary (status counts, best runs) is the single process's
        def summary(text):
            return [ln for ln in text.splitlines() if ln.startswith(("block ", "  best:"))]
        self.assertTrue(summary(r0.stdout))
        self.assertEqual(summary(r.stdout), summary(r0.stdout))


class KillOneRank(Base):
    def test_sigkill_of_one_rank_then_resume_completes_the_study(self):
        study = self.write("long.toml", LONG)
        ref, out = os.path.join(self.dir, "ref.h5"), os.path.join(self.dir, "killed.h5")
        r = run("run", study, "-o", ref, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        p, victim = start_with_rank1(self, study, out)
        # let rank 1 commit some runs (shards commit every 512 runs or 2 s): wait until its shard
        # shows done runs (a read that meets a commit under way raises or is retried)
        deadline = time.time() + 120
        while time.time() < deadline and p.poll() is None:
            try:
                with h5py.File(out + ".rank1.h5", "r") as f:
                    if int(f["runs"]["done"][()].sum()) > 0:
                        break
            except (OSError, KeyError):
                pass
            time.sleep(0.1)
        self.assertIsNone(p.poll(), "the job finished before the kill: make LONG longer")
        os.kill(victim, signal.SIGKILL)
        try:
            p.wait(timeout=60)
        except subprocess.TimeoutExpired:  # mpirun should abort the job by itself
            p.kill()
            p.wait()
        self.assertNotEqual(p.returncode, 0)
        self.assertFalse(os.path.exists(out))  # no merge happened
        shards = sorted(glob.glob(out + ".rank*.h5"))
        self.assertEqual([os.path.basename(s) for s in shards], ["killed.h5.rank0.h5", "killed.h5.rank1.h5"])

        r = mpirun("run", study, "-o", out, "-q", "--threads", "1")  # no silent restart over the shards
        self.assertEqual(r.returncode, 1)
        self.assertIn("--resume", r.stderr)

        r = mpirun("run", study, "-o", out, "-q", "--threads", "1", "--resume")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        m = re.search(r"(\d+) runs \((\d+) computed now, (\d+) already in the file\)", r.stdout)
        self.assertIsNotNone(m, r.stdout)
        total, now, before = map(int, m.groups())
        self.assertEqual(total, 501 * 11 + 441)
        self.assertGreater(before, 0)  # both ranks' committed runs were kept (rank 1's included)
        self.assertGreater(now, 0)
        self.assertSameFile(ref, out)
        self.assertEqual(glob.glob(out + ".rank*"), [])


def wait_for_done_runs(test, proc, path):
    """Wait until the results file or shard `path` shows committed runs (a read that meets a
    commit under way raises and is retried)."""
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        try:
            with h5py.File(path, "r") as f:
                if int(f["runs"]["done"][()].sum()) > 0:
                    return
        except (OSError, KeyError):
            pass
        time.sleep(0.1)
    test.fail(f"{path} showed no done run before the job ended: make LONG longer")


class ResumeAdoptsRecordedHistories(Base):
    """`mpirun ... --resume` without --histories writes the rest of the runs with the history policy
    the file (or its shards) records, as the same command without mpirun does. The files are begun
    with --histories every=3, not the study's every=5."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.shared = tempfile.TemporaryDirectory()
        cls.study = os.path.join(cls.shared.name, "long.toml")
        with open(cls.study, "w") as f:
            f.write(LONG)
        cls.ref = os.path.join(cls.shared.name, "ref.h5")
        t0 = time.time()
        r = run("run", cls.study, "-o", cls.ref, "-q", "--histories", "every=3", "--threads", "1")
        cls.ref_seconds = time.time() - t0
        assert r.returncode == 0, r.stderr

    @classmethod
    def tearDownClass(cls):
        cls.shared.cleanup()
        super().tearDownClass()

    def resume_and_compare(self, out):
        r = mpirun("run", self.study, "-o", out, "-q", "--threads", "1", "--resume")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        m = re.search(r"(\d+) computed now, (\d+) already in the file", r.stdout)
        self.assertIsNotNone(m, r.stdout)
        self.assertGreater(int(m.group(1)), 0)
        self.assertGreater(int(m.group(2)), 0)
        with h5py.File(out, "r") as f:
            self.assertEqual(f.attrs["histories"], "every=3")
        self.assertSameFile(self.ref, out)
        self.assertEqual(glob.glob(out + ".rank*"), [])

    def test_overwrite_killed_during_the_sweep_keeps_the_previous_file(self):
        # --overwrite under mpirun writes the merged file aside: a job killed before its merge leaves
        # the previous file byte for byte; a complete one replaces it
        small, other = self.write("small.toml", SWEEP), self.write("long.toml", LONG)
        out = os.path.join(self.dir, "kept.h5")
        self.assertEqual(run("run", small, "-o", out, "-q").returncode, 0)
        with open(out, "rb") as f:
            before = hashlib.sha256(f.read()).hexdigest()
        p, victim = start_with_rank1(self, other, out, "--overwrite")
        self.assertIsNone(p.poll(), "the job finished before the kill: make LONG longer")
        os.kill(victim, signal.SIGKILL)
        try:
            p.wait(timeout=60)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()
        self.assertNotEqual(p.returncode, 0)
        with open(out, "rb") as f:
            self.assertEqual(hashlib.sha256(f.read()).hexdigest(), before)
        r = mpirun("run", other, "-o", out, "-q", "--threads", "1", "--overwrite")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        with h5py.File(out, "r") as f:
            self.assertEqual(f.attrs["study_name"], "mpi_kill")
        self.assertEqual(glob.glob(out + ".rank*"), [])

    def test_a_file_begun_by_one_process(self):
        out = os.path.join(self.dir, "local.h5")
        p = subprocess.Popen([KS, "run", self.study, "-o", out, "-q", "--threads", "1", "--histories", "every=3"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        time.sleep(self.ref_seconds / 2)  # the writer holds the file: interrupt about half way
        p.send_signal(signal.SIGINT)
        stdout, stderr = p.communicate(timeout=120)
        self.assertEqual(p.returncode, 130, stdout + stderr)
        self.assertIn("--histories every=3", stdout)  # the printed resume command repeats the option
        self.resume_and_compare(out)

    def test_shards_begun_by_mpirun(self):
        out = os.path.join(self.dir, "mpi.h5")
        p = subprocess.Popen([*MPIRUN, KS, "run", self.study, "-o", out, "-q", "--threads", "1", "--histories",
                              "every=3"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wait_for_done_runs(self, p, out + ".rank1.h5")
        for rank in (0, 1):
            pid = rank_pid(p.pid, rank)
            if pid:
                os.kill(pid, signal.SIGTERM)
        p.wait(timeout=120)
        self.assertEqual(p.returncode, 130)
        self.assertFalse(os.path.exists(out))
        self.assertEqual(len(glob.glob(out + ".rank*.h5")), 2)
        self.resume_and_compare(out)


class FreeSpace(Base):
    def test_a_file_and_shards_larger_than_the_free_space_are_not_started(self):
        from test_cli_guards import BIG_STUDY, Tmpfs
        study = self.write("big.toml", BIG_STUDY)
        with Tmpfs(self, "1m") as mnt:
            out = os.path.join(mnt, "big.h5")
            r = mpirun("run", study, "-o", out, "-q")
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn("the file and its shards need", r.stderr)
            self.assertIn("bytes free; expected more free space", r.stderr)
            self.assertEqual(os.listdir(mnt), [])


class SignalBeforeTheSweep(Base):
    def test_sigterm_to_the_ranks_before_the_sweep_exits_130_with_nothing_written(self):
        study = self.write("s.toml", SWEEP)
        out = os.path.join(self.dir, "s.h5")
        env = dict(os.environ, KINESWEEP_TEST_PAUSE_BEFORE_SWEEP="1")
        p = subprocess.Popen([*MPIRUN, KS, "run", study, "-o", out, "-q"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=env)
        pids, deadline = [], time.time() + 60
        while time.time() < deadline and len(pids) < 2:
            pids = [pid for pid in (rank_pid(p.pid, 0), rank_pid(p.pid, 1)) if pid]
            time.sleep(0.05)
        self.assertEqual(len(pids), 2, "ranks not found")
        # both ranks validated the study and wait; their two lines may reach the pipe interleaved
        said = ""
        while said.count("paused before the sweep") < 2:
            line = p.stderr.readline()
            self.assertNotEqual(line, "", f"the ranks ended before pausing: {said!r}")
            said += line
        os.kill(pids[1], signal.SIGTERM)  # one rank's signal stops every rank
        os.kill(pids[0], signal.SIGTERM)
        _, stderr = p.communicate(timeout=120)
        self.assertEqual(p.returncode, 130, stderr)
        self.assertIn("nothing written", stderr)
        self.assertEqual(sorted(os.listdir(self.dir)), ["s.toml"])


class OptimizationBlocks(Base):
    def test_mpirun_runs_the_optimize_blocks_like_one_process(self):
        """[[optimize]] blocks run under mpirun (on rank 0, after the merge) and give the single
        process's /optimizations: every dataset and attribute but the wall times, bitwise."""
        from regression_hashes import hash_results
        study = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "studies", "optimize_polish.toml")
        ref, out = os.path.join(self.dir, "ref.h5"), os.path.join(self.dir, "mpi.h5")
        r = run("run", study, "-o", ref, "-q", "--histories", "none")
        self.assertEqual(r.returncode, 0, r.stderr)
        r = mpirun("run", study, "-o", out, "-q", "--histories", "none", "--threads", "1")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("distributed: 2 ranks", r.stdout)
        self.assertEqual(r.stdout.count("\noptimization "), 10, r.stdout)  # each block reported once, by rank 0
        a, b = hash_results(ref), hash_results(out)
        opt_a = {k: v for k, v in a.items() if k.startswith("optimizations/")}
        opt_b = {k: v for k, v in b.items() if k.startswith("optimizations/")}
        self.assertGreater(len(opt_a), 100)
        self.assertEqual(opt_a.keys(), opt_b.keys())
        for k in opt_a:
            self.assertEqual(opt_a[k], opt_b[k], k)
        self.assertSameFile(ref, out)


if __name__ == "__main__":
    KS = os.path.abspath(sys.argv[1])
    unittest.main(argv=[sys.argv[0], "-v"])
