"""End-to-end tests of `kinesweep run` under hostile conditions: studies that would exhaust memory
(refused within a memory cap), the caller's run limit, signals before the sweep and during
optimisation blocks, a full disk, a dt too coarse for the path, paths and directories.

usage: /usr/bin/python3 test_cli_guards.py KINESWEEP_BINARY STUDIES_DIR
"""
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import h5py

from e2e_common import Histories, TempDirTest, history, runs_column

KS = None
STUDIES = None

TRAJ = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n"


def run(*args, **kw):
    return subprocess.run([KS, *args], capture_output=True, text=True, **kw)


# The sanitizers kinesweep was built with (tests/CMakeLists.txt sets KINESWEEP_SANITIZE from the CMake
# option of that name). These reserve terabytes of address space for their shadow memory at start-up,
# so a binary built with them cannot run under an address-space cap.
SHADOW_SANITIZERS = {"address", "hwaddress", "memory", "thread", "leak"}
SANITIZED = set(os.environ.get("KINESWEEP_SANITIZE", "").replace(" ", "").split(",")) & SHADOW_SANITIZERS


def run_capped(args, address_space):
    """Run kinesweep with its address space capped (so materialising what it refuses would fail; not
    under a shadow-memory sanitizer, where the peak resident memory the callers check is the guard);
    returns (exit code, stderr, peak resident set size in bytes)."""
    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))
    with tempfile.TemporaryFile("w+") as err:
        p = subprocess.Popen([KS, *args], stdout=subprocess.DEVNULL, stderr=err,
                             preexec_fn=None if SANITIZED else cap)
        _, status, usage = os.wait4(p.pid, 0)
        p.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        return p.returncode, err.read(), usage.ru_maxrss * 1024


def leftovers(directory):
    """Hidden temporary files a writer may leave (.NAME.tmp-PID-N)."""
    return [n for n in os.listdir(directory) if ".tmp-" in n]


class Resources(TempDirTest):
    CAP = 400 * 2**20   # address space: one 4e7-value axis alone would need 1.6 GB
    RSS = 100 * 2**20   # the peak resident memory allowed for a refusal

    def test_five_axes_of_4e7_values_are_refused_within_the_cap(self):
        axes = "".join(f"{k} = {{ from = 0.001, to = 1, count = 40000000 }}\n"
                       for k in ("q0_1", "q0_2", "q0_3", "lambda", "tol"))
        study = self.write("huge.toml", "[[block]]\nname = \"b\"\nkind = \"ik\"\n[block.axes]\n" + axes)
        code, err, rss = run_capped(["run", study, "-o", os.path.join(self.dir, "huge.h5")], self.CAP)
        self.assertEqual(code, 2, err)
        self.assertIn(f"{study}:1:1: error: too many runs", err)
        self.assertLess(rss, self.RSS)
        self.assertEqual(os.listdir(self.dir), ["huge.toml"])

    def test_3000_s_segments_at_the_default_dt_are_refused_within_the_cap(self):
        study = self.write("long.toml", "[task]\nvertices = [[0.9, 0.3], [1.1, 0.3], [1.1, 0.5], [0.9, 0.5], [0.9, 0.3]]\n"
                                        "durations = [3000, 3000, 3000, 3000]\n" + TRAJ)
        for extra in ([], ["--dry-run"]):
            with self.subTest(extra=extra):
                code, err, rss = run_capped(["run", study, "-o", os.path.join(self.dir, "long.h5"), *extra], self.CAP)
                self.assertEqual(code, 2, err)
                self.assertIn(f"{study}:3:13: error: the default dt = 0.001 gives 12000001 samples", err)
                self.assertLess(rss, self.RSS)

    def test_the_caller_sets_the_run_limit_and_a_study_only_lowers_it(self):
        body = TRAJ + "[block.axes]\nk = { from = 0, to = 1, count = 1100 }\n"
        study = self.write("s.toml", body)
        out = os.path.join(self.dir, "s.h5")
        r = run("run", study, "-o", out, "--max-runs", "1000", "--dry-run")
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("expected at most 1000 runs (the caller's limit: kinesweep run --max-runs N", r.stderr)
        self.assertIn("--max-runs", r.stderr)
        self.assertEqual(run("run", study, "-o", out, "--max-runs", "1100", "--dry-run").returncode, 0)
        raised = self.write("raised.toml", "[study]\nmax_runs = 9223372036854775807\n" + body)
        r = run("run", raised, "-o", out, "--dry-run")
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(f"{raised}:2:12: error:", r.stderr)
        self.assertIn("a study may only lower the limit", r.stderr)

    def test_a_file_larger_than_the_free_space_is_not_started(self):
        # 2e6 rows need more than the free space of any small test disk: refused before creating.
        study = self.write("big.toml", BIG_STUDY)
        with Tmpfs(self, "1m") as mnt:
            out = os.path.join(mnt, "big.h5")
            r = run("run", study, "-o", out, "-q")
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn("bytes free; expected more free space", r.stderr)
            self.assertEqual(os.listdir(mnt), [])


class ResumeMemory(TempDirTest):
    def test_resume_of_a_2_million_run_file_stays_under_300_mb(self):
        # The done runs' rows are read back in pieces: memory for a done mask, not for the rows.
        study = self.write("big.toml", "[study]\nhistories = \"none\"\n[[block]]\nname = \"b\"\nkind = \"ik\"\n"
                                       "max_iter = 1\n[block.axes]\nq0_1 = { from = 0, to = 1, count = 2000 }\n"
                                       "q0_2 = { from = 0, to = 1, count = 1000 }\n")
        out = os.path.join(self.dir, "big.h5")
        self.assertEqual(run("run", study, "-o", out, "-q").returncode, 0)
        with tempfile.TemporaryFile("w+") as err, tempfile.TemporaryFile("w+") as log:
            p = subprocess.Popen([KS, "run", study, "-o", out, "-q", "--resume"], stdout=log, stderr=err)
            _, status, usage = os.wait4(p.pid, 0)
            err.seek(0)
            log.seek(0)
            self.assertEqual(os.waitstatus_to_exitcode(status), 0, err.read())
            self.assertIn("2000000 runs (0 computed now, 2000000 already in the file)", log.read())
        if not SANITIZED:  # AddressSanitizer's shadow memory and quarantine of freed blocks come on top
            self.assertLess(usage.ru_maxrss * 1024, 300 * 2**20)
        with h5py.File(out, "r") as f:  # the landscape rewritten from the rows read back
            grid = f["landscapes/b/iterations"][()]
            self.assertEqual(grid.shape, (2000, 1000))
            self.assertTrue((grid.ravel() == f["runs/iterations"][()]).all())


class HistoryMemory(TempDirTest):
    """A run whose full history would not fit in a bounded memory is refused before anything is
    written, with the coarsest history policy that fits; that policy runs under 300 MB."""
    LONG = ("[study]\nname = \"long\"\nhistories = \"full\"\n[task]\nvertices = [[1.5, 0.5], [1.5, 1.5], [1.5, 0.5]]\n"
            "durations = [3000, 3000]\n[[block]]\nname = \"one\"\nkind = \"trajectory\"\nmethod = \"local_weighted\"\n"
            "[block.axes]\nalpha1A = [10]\n")

    @staticmethod
    def smallest_fitting_stride(samples, values):
        # rows kept: every stride-th sample and the last; about 4 copies of 8-byte values in memory
        stride = 1
        while ((samples + stride - 1) // stride + 1) * values * 8 * 4 > 64 * 2**20:
            stride += 1
        return stride

    def test_a_6e6_sample_full_history_is_refused_and_the_suggested_policy_runs(self):
        study = self.write("long.toml", self.LONG)
        out = os.path.join(self.dir, "long.h5")
        samples = 6000 * 1000 + 1  # 6000 s at dt = 1 ms
        values = 1 + 3 * 4 + 2 + 1  # t, q qd qdd tau of 3 joints, x, alpha
        stride = self.smallest_fitting_stride(samples, values)
        for extra in ([], ["--dry-run"]):
            r = run("run", study, "-o", out, "-q", *extra)
            self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
            self.assertIn(f"block 'one': with histories = full", r.stderr)
            self.assertIn(f"keeps {samples + 1} history rows of {values} values", r.stderr)
            self.assertIn(f'use histories = "every={stride}" or coarser', r.stderr)
            self.assertEqual(sorted(os.listdir(self.dir)), ["long.toml"])
        r = run("run", study, "-o", out, "-q", "--histories", f"every={stride - 1}")
        self.assertEqual(r.returncode, 1, r.stderr)
        with tempfile.TemporaryFile("w+") as err:
            p = subprocess.Popen([KS, "run", study, "-o", out, "-q", "--histories", f"every={stride}"],
                                 stdout=subprocess.DEVNULL, stderr=err)
            _, status, usage = os.wait4(p.pid, 0)
            err.seek(0)
            self.assertEqual(os.waitstatus_to_exitcode(status), 0, err.read())
        if not SANITIZED:
            self.assertLess(usage.ru_maxrss * 1024, 300 * 2**20)
        with h5py.File(out, "r") as f:
            self.assertEqual(runs_column(f["runs/status"])[0], "ok")
            t = history(f, 0)["t"]
            # every stride-th sample from the first, and the last one
            self.assertEqual(len(t), (samples + stride - 1) // stride + (1 if (samples - 1) % stride else 0))
            self.assertEqual(t[-1, 0], 6000.0)


# 2e6 IK runs: their /runs rows alone need more than the free space of a small test disk.
BIG_STUDY = ("[[block]]\nname = \"b\"\nkind = \"ik\"\n[block.axes]\n"
             "q0_1 = { from = 0, to = 1, count = 2000 }\nq0_2 = { from = 0, to = 1, count = 1000 }\n")


class Tmpfs:
    """A small tmpfs mounted for one test (the test is skipped where mounting is not permitted)."""

    def __init__(self, test, size):
        self.test, self.size = test, size
        self.dir = tempfile.mkdtemp(prefix="ks_tmpfs_")

    def __enter__(self):
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={self.size}", "tmpfs", self.dir],
                           capture_output=True, text=True)
        if r.returncode != 0:
            os.rmdir(self.dir)
            self.test.skipTest("cannot mount a tmpfs here: " + r.stderr.strip())
        return self.dir

    def resize(self, size):
        subprocess.run(["mount", "-o", f"remount,size={size}", self.dir], check=True)

    def __exit__(self, *exc):
        subprocess.run(["umount", self.dir], check=False)
        os.rmdir(self.dir)


class FullDisk(TempDirTest):
    def test_a_full_disk_ends_in_one_line_exit_1_and_the_run_resumes(self):
        study = os.path.join(STUDIES, "thesis_table4.toml")
        disk = Tmpfs(self, "2m")
        with disk as mnt:
            out = os.path.join(mnt, "t4.h5")
            r = run("run", study, "-o", out, "-q", "--histories", "full")
            self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
            lines = r.stderr.strip().splitlines()
            self.assertEqual(len(lines), 1, r.stderr)
            self.assertIn("No space left on device", lines[0])
            self.assertEqual(leftovers(mnt), [])
            disk.resize("64m")
            r = run("run", study, "-o", out, "-q", "--histories", "full", "--resume")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(leftovers(mnt), [])
            with h5py.File(out, "r") as f:
                self.assertTrue(all(f["runs"]["done"][()] == 1))
                self.assertEqual(Histories(f).count(), 21)


class Signals(TempDirTest):
    def paused(self, study, out, sig, *extra):
        env = dict(os.environ, KINESWEEP_TEST_PAUSE_BEFORE_SWEEP="1")
        p = subprocess.Popen([KS, "run", study, "-o", out, "-q", *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, env=env)
        self.assertIn("paused before the sweep", p.stderr.readline())
        p.send_signal(sig)
        stdout, stderr = p.communicate(timeout=60)
        return p.returncode, stdout, stderr

    def test_a_signal_before_the_sweep_leaves_nothing_behind(self):
        study = self.write("s.toml", TRAJ + "[block.axes]\nk = { from = 0, to = 1, count = 11 }\n")
        for sig in (signal.SIGINT, signal.SIGTERM):
            with self.subTest(sig=sig):
                out = os.path.join(self.dir, "s.h5")
                code, _, stderr = self.paused(study, out, sig)
                self.assertEqual(code, 130, stderr)
                self.assertIn("nothing written", stderr)
                self.assertEqual(sorted(os.listdir(self.dir)), ["s.toml"])

    def test_a_signal_before_a_resume_changes_nothing(self):
        study = self.write("s.toml", TRAJ + "[block.axes]\nk = { from = 0, to = 1, count = 11 }\n")
        out = os.path.join(self.dir, "s.h5")
        self.assertEqual(run("run", study, "-o", out, "-q").returncode, 0)
        with open(out, "rb") as f:
            before = f.read()
        code, _, stderr = self.paused(study, out, signal.SIGINT, "--resume")
        self.assertEqual(code, 130, stderr)
        with open(out, "rb") as f:
            self.assertEqual(f.read(), before)

    def test_sigint_stops_an_optimisation_block_which_keeps_its_evaluations(self):
        study = self.write("o.toml", """
[study]
name = "opt_stop"
histories = "none"
[robot]
inertia = "thesis_m11"
[[optimize]]
name = "h1"
preset = "1h"
variables = { alpha1A = [-30, 10], k = [0, 1] }
[optimize.global]
algorithm = "GN_ESCH"
population = 10
max_evals = 1000000
""")
        out = os.path.join(self.dir, "o.h5")
        p = subprocess.Popen([KS, "run", study, "-o", out, "-q"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
        while not os.path.exists(out) and p.poll() is None:
            time.sleep(0.05)
        time.sleep(2.0)  # well into the global stage (a million evaluations take many minutes)
        p.send_signal(signal.SIGINT)
        stdout, stderr = p.communicate(timeout=120)
        self.assertEqual(p.returncode, 130, stderr)
        self.assertIn("resume with: ", stdout)
        with h5py.File(out, "r") as f:
            n = len(f["optimizations"]["h1"]["evaluations"]["status"])
            self.assertGreater(n, 0)
            self.assertLess(n, 1000000)


class Sampling(TempDirTest):
    def test_a_swept_dt_too_coarse_for_the_path_ends_undersampled(self):
        study = self.write("dt.toml", "[study]\nhistories = \"none\"\n" + TRAJ + "[block.axes]\ndt = [0.001, 0.2]\n")
        out = os.path.join(self.dir, "dt.h5")
        r = run("run", study, "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        with h5py.File(out, "r") as f:
            self.assertEqual(runs_column(f["runs"]["status"]).tolist(), ["ok", "undersampled"])
        self.assertIn("undersampled", run("schema").stdout)


class Paths(TempDirTest):
    def test_a_directory_is_not_a_study(self):
        r = run("run", STUDIES, "--dry-run")
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("is a directory; expected a study file (TOML), e.g. ", r.stderr)

    def test_a_directory_as_the_output_is_refused_in_one_line(self):
        study = self.write("s.toml", TRAJ)
        os.mkdir(os.path.join(self.dir, "d.h5"))
        for extra in ([], ["--resume"], ["--overwrite"]):
            with self.subTest(extra=extra):
                r = run("run", study, "-o", os.path.join(self.dir, "d.h5"), "-q", *extra)
                self.assertEqual(r.returncode, 1, r.stderr)
                self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
                self.assertIn("is a directory", r.stderr)

    def test_control_characters_in_the_output_path_are_refused(self):
        study = self.write("s.toml", TRAJ)
        r = run("run", study, "-o", os.path.join(self.dir, "a\nb.h5"))
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("contains a control character", r.stderr)
        self.assertEqual(os.listdir(self.dir), ["s.toml"])


if __name__ == "__main__":
    KS, STUDIES = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"])
