"""End-to-end tests of `kinesweep run`: bad input, thread-count independence, SIGKILL + resume,
SIGINT + resume, overwrite protection, reading with h5py.

usage: /usr/bin/python3 test_cli_run.py KINESWEEP_BINARY STUDIES_DIR
"""
import hashlib
import os
import random
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

import h5py
import numpy as np

from e2e_common import (SWEEP, TempDirTest, bitwise_equal, history, runs_column, runs_columns, runs_table,
                        same_histories, same_tables)

KS = None
STUDIES = None

def run(*args, **kw):
    return subprocess.run([KS, *args], capture_output=True, text=True, **kw)


class Base(TempDirTest):
    pass


class BadInput(Base):
    CASES = {
        "syntax": ("[study]\nname = \"x\n", 2),
        "unknown_key": ("[study]\nname = \"x\"\n[[block]]\nname = \"b\"\nkind = \"trajectory\"\nalpha1a = 3\n", 6),
        "wrong_type": ("[[block]]\nname = \"b\"\nkind = \"trajectory\"\nk = \"high\"\n", 4),
        "inverted_range": ("[[block]]\nname = \"b\"\nkind = \"trajectory\"\n[block.axes]\nk = { from = 1, to = 0, step = 0.1 }\n", 5),
        "empty_range": ("[[block]]\nname = \"b\"\nkind = \"trajectory\"\n[block.axes]\nk = { from = 0, to = 1, step = 0 }\n", 5),
        "unknown_method": ("[[block]]\nname = \"b\"\nkind = \"trajectory\"\nmethod = \"local_weigthed\"\n", 4),
        "unknown_preset": ("[[block]]\nname = \"b\"\nkind = \"trajectory\"\npreset = \"9z\"\n", 4),
        "too_many": ("[[block]]\nname = \"b\"\nkind = \"ik\"\n[block.axes]\nq0_1 = { from = 0, to = 1, count = 100000 }\nq0_2 = { from = 0, to = 1, count = 100000 }\n", None),
    }

    def test_each_bad_study_is_rejected_with_location_and_no_file(self):
        for name, (text, line) in self.CASES.items():
            with self.subTest(name):
                study = self.write(name + ".toml", text)
                out = os.path.join(self.dir, name + ".h5")
                r = run("run", study, "-o", out)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn(study + ":", r.stderr)
                if line is not None:
                    self.assertIn(f"{study}:{line}:", r.stderr)
                self.assertIn("expected", r.stderr)
                self.assertFalse(os.path.exists(out))

    def test_misspelled_key_gets_a_suggestion(self):
        study = self.write("s.toml", self.CASES["unknown_key"][0])
        r = run("run", study, "-o", os.path.join(self.dir, "s.h5"))
        self.assertIn("did you mean 'alpha1A'", r.stderr)

    def test_bad_histories_option(self):
        study = self.write("ok.toml", SWEEP)
        r = run("run", study, "-o", os.path.join(self.dir, "x.h5"), "--histories", "every=0")
        self.assertEqual(r.returncode, 2)


class Outputs(Base):
    def test_existing_file_is_not_overwritten_without_flag(self):
        study = self.write("ok.toml", SWEEP)
        out = os.path.join(self.dir, "r.h5")
        self.assertEqual(run("run", study, "-o", out, "-q").returncode, 0)
        before = hashlib.sha256(open(out, "rb").read()).hexdigest()
        r = run("run", study, "-o", out, "-q")
        self.assertEqual(r.returncode, 1)
        self.assertIn("--overwrite", r.stderr)
        self.assertEqual(hashlib.sha256(open(out, "rb").read()).hexdigest(), before)
        self.assertEqual(run("run", study, "-o", out, "-q", "--overwrite").returncode, 0)

    def test_unwritable_directory_is_a_clear_error(self):
        study = self.write("ok.toml", SWEEP)
        blocker = self.write("not_a_dir", "x")
        r = run("run", study, "-o", os.path.join(blocker, "r.h5"), "-q")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("not_a_dir", r.stderr)

    def test_dry_run_writes_nothing(self):
        study = self.write("ok.toml", SWEEP)
        out = os.path.join(self.dir, "r.h5")
        r = run("run", study, "-o", out, "--dry-run")
        self.assertEqual(r.returncode, 0)
        self.assertIn("561 runs", r.stdout)   # 51 x 11
        self.assertIn("441 runs", r.stdout)   # 21 x 21
        self.assertIn("estimated size", r.stdout)
        self.assertFalse(os.path.exists(out))


    def test_output_must_be_named_as_hdf5(self):
        study = self.write("ok.toml", SWEEP)
        out = os.path.join(self.dir, "r.csv")
        r = run("run", study, "-o", out, "-q")
        self.assertEqual(r.returncode, 2)
        self.assertIn("expected a name ending in .h5", r.stderr)
        self.assertIn("--format csv", r.stderr)
        self.assertEqual(os.listdir(self.dir), ["ok.toml"])
        bad = self.write("bad.toml", SWEEP.replace('[study]\n', '[study]\noutput = "x.json"\n', 1))
        r = run("run", bad, "-q")
        self.assertEqual(r.returncode, 2)
        self.assertRegex(r.stderr, r"bad\.toml:\d+:\d+")
        self.assertIn("expected a name ending in .h5", r.stderr)

    def test_dry_run_names_the_output_and_estimates_the_size_within_2x(self):
        # The estimate is measured from sample runs written here; the real file's size (h5py-free: the
        # file system) must be within a factor 2, with and without histories.
        for histories in ("none", "every=10", "full"):
            with self.subTest(histories):
                study = self.write("ok.toml", SWEEP)
                out = os.path.join(self.dir, f"r_{histories}.h5")
                r = run("run", study, "-o", out, "--dry-run", "--histories", histories)
                self.assertEqual(r.returncode, 0, r.stderr)
                self.assertIn("output " + out, r.stdout)
                m = re.search(r"estimated size: ([\d.]+) (B|KiB|MiB|GiB)", r.stdout)
                self.assertIsNotNone(m, r.stdout)
                est = float(m.group(1)) * 1024 ** ["B", "KiB", "MiB", "GiB"].index(m.group(2))
                self.assertEqual(run("run", study, "-o", out, "-q", "--histories", histories).returncode, 0)
                real = os.path.getsize(out)
                self.assertLess(max(est / real, real / est), 2.0, f"estimated {est:.0f} B, file {real} B")


class Reproducibility(Base):
    def test_results_identical_whatever_the_thread_count(self):
        study = self.write("ok.toml", SWEEP)
        a, b = os.path.join(self.dir, "t1.h5"), os.path.join(self.dir, "t2.h5")
        self.assertEqual(run("run", study, "-o", a, "--threads", "1", "-q").returncode, 0)
        self.assertEqual(run("run", study, "-o", b, "--threads", "2", "-q").returncode, 0)
        self.assertTrue(same_tables(runs_table(a), runs_table(b)))
        with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
            for run_id in (0, 300, 700):
                ha, hb = history(fa, run_id), history(fb, run_id)
                self.assertEqual(list(ha), list(hb))
                for k in ha:
                    self.assertTrue(np.array_equal(ha[k], hb[k]))
            self.assertEqual(fa.attrs["study_sha256"], hashlib.sha256(SWEEP.encode()).hexdigest())

    def test_pandas_style_load_and_study_inside(self):
        study = self.write("ok.toml", SWEEP)
        out = os.path.join(self.dir, "r.h5")
        self.assertEqual(run("run", study, "-o", out, "-q").returncode, 0)
        with h5py.File(out, "r") as f:
            self.assertEqual({len(f["runs"][k]) for k in f["runs"]}, {561 + 441})
            table = runs_columns(f)
            text = f["study"]["text"][()]
            self.assertEqual(text.decode() if isinstance(text, bytes) else text, SWEEP)
            self.assertIn("engine_version", f.attrs)
            self.assertEqual(f.attrs["command_line"], " ".join([KS, "run", study, "-o", out, "-q"]))
            self.assertEqual(f.attrs["host"], socket.gethostname())
            # the commit the binary was built from: a commit of this checkout (git's own answer), and
            # the session's start and end
            here = os.path.dirname(os.path.abspath(__file__))
            if subprocess.run(["git", "-C", here, "rev-parse", "HEAD"], capture_output=True).returncode == 0:
                commit = f.attrs["engine_commit"]
                self.assertRegex(commit, r"^[0-9a-f]{40}(-dirty)?$")
                known = subprocess.run(["git", "-C", here, "cat-file", "-e", commit[:40] + "^{commit}"])
                self.assertEqual(known.returncode, 0, commit)
            self.assertLessEqual(f.attrs["created"], f.attrs["closed"])  # ISO 8601 UTC: ordered as text
            self.assertRegex(f.attrs["closed"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
            self.assertTrue(all(s in ("ok", "diverged", "singular", "unreachable_start", "off_path") for s in table["status"][:561]))
            E = table["E"][:561]
            ok = table["status"][:561] == "ok"
            self.assertTrue(np.all(np.isfinite(E[ok])))
            land = f["landscapes"]["weighted"]
            self.assertEqual(land["E"].shape, (51, 11))
            self.assertEqual(land["converged"].shape if "converged" in land else (51, 11), (51, 11))
            self.assertEqual(f["landscapes"]["newton_basin"]["converged"].shape, (21, 21))


class BestRuns(Base):
    def test_summary_and_info_name_the_same_best_runs_as_h5py_ranks_them(self):
        """One ranking rule: the lowest objective among the good runs, ties by the second metric, then
        run id (trajectory: E among ok; ik: iterations among converged, then error) - recomputed here
        with h5py, and equal to what `run` prints and what `info` lists."""
        study = self.write("s.toml", SWEEP)
        out = os.path.join(self.dir, "s.h5")
        r = run("run", study, "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        printed = [int(m) for m in re.findall(r"best: run (\d+)", r.stdout)]
        info = run("info", out)
        self.assertEqual(info.returncode, 0, info.stderr)
        listed = [int(m) for m in re.findall(r"^  \S+\s+run\s+(\d+)  ", info.stdout, re.M)]
        with h5py.File(out, "r") as f:
            runs = f["runs"]
            block, status = runs_column(runs["block"]), runs_column(runs["status"])
            expected = []
            for name, good, key, tie in (("weighted", "ok", "E", None),
                                         ("newton_basin", "converged", "iterations", "error")):
                ids = np.nonzero((block == name) & (status == good))[0]
                k = runs[key][()][ids].astype(float)
                t = runs[tie][()][ids] if tie else np.zeros(len(ids))
                order = sorted(range(len(ids)), key=lambda i: (k[i], t[i], ids[i]))
                expected += [int(ids[i]) for i in order[:3]]
        self.assertEqual(printed, expected)
        self.assertEqual(listed, expected)


class CrashAndResume(Base):
    def reference(self, study):
        ref = os.path.join(self.dir, "ref.h5")
        self.assertEqual(run("run", study, "-o", ref, "-q").returncode, 0)
        return runs_table(ref)

    def test_sigkill_then_resume_gives_the_uninterrupted_table(self):
        # Full histories; kills early, at random moments, and around the end of the uninterrupted
        # run's time (the final commit). Each time the file opens, its done runs' rows and histories
        # are the uninterrupted run's, and resume completes it to /runs and histories bitwise equal.
        study = self.write("ok.toml", SWEEP)
        ref_path = os.path.join(self.dir, "ref.h5")
        t0 = time.perf_counter()
        self.assertEqual(run("run", study, "-o", ref_path, "-q", "--histories", "full").returncode, 0)
        took = time.perf_counter() - t0
        ref = runs_table(ref_path)
        rng = random.Random(11)
        delays = [0.15, 0.4, 0.8] + [took * rng.uniform(0.2, 0.95) for _ in range(2)] + [took * f for f in (0.97, 0.995, 1.0)]
        for i, delay in enumerate(delays):
            out = os.path.join(self.dir, f"k{i}.h5")
            p = subprocess.Popen([KS, "run", study, "-o", out, "-q", "--histories", "full"],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(delay)
            p.send_signal(signal.SIGKILL)
            p.wait()
            journal = out + ".journal"
            applying = os.path.exists(journal) and os.path.getsize(journal) > 56  # killed inside a commit's
            if os.path.exists(out) and not applying:  # replay (FORMAT.md): plain HDF5 waits for a writer
                with h5py.File(out, "r") as f, h5py.File(ref_path, "r") as fr:
                    done = f["runs"]["done"][()].astype(bool)
                    for k in ("E", "iterations", "alpha1A"):
                        x, y = f["runs"][k][()][done], ref[k][done]
                        self.assertTrue(np.array_equal(x.view(np.uint64) if x.dtype.kind == "f" else x,
                                                       y.view(np.uint64) if y.dtype.kind == "f" else y))
                    for run_id in np.flatnonzero(done)[::37]:
                        got, want = history(f, int(run_id)), history(fr, int(run_id))
                        self.assertEqual(list(got), list(want), f"kill {i}, run {run_id}")
                        for k in want:
                            self.assertTrue(bitwise_equal(got[k], want[k]), f"kill {i}, run {run_id} {k}")
            r = run("run", study, "-o", out, "--resume", "-q", "--histories", "full")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertTrue(same_tables(runs_table(out), ref))
            with h5py.File(out, "r") as f, h5py.File(ref_path, "r") as fr:
                same_histories(self, f, fr)

    def test_sigint_finishes_in_flight_runs_and_says_how_to_resume(self):
        study = self.write("ok.toml", SWEEP)
        ref = self.reference(study)
        out = os.path.join(self.dir, "int.h5")
        p = subprocess.Popen([KS, "run", study, "-o", out, "-q", "--histories", "full", "--threads", "1"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        # The handlers are installed before anything is created: signal once the results file (or its
        # hidden temporary .int.h5.tmp-PID-N) exists, not after a guessed start-up time.
        while p.poll() is None and not any(n == "int.h5" or n.startswith(".int.h5.tmp-") for n in os.listdir(self.dir)):
            time.sleep(0.01)
        p.send_signal(signal.SIGINT)
        stdout, _ = p.communicate()
        if p.returncode == 130:
            # The hint is a command that works as printed (the binary as it was invoked).
            hint = [line for line in stdout.splitlines() if line.startswith("resume with: ")]
            self.assertEqual(len(hint), 1, stdout)
            self.assertIn(KS, hint[0])
            r = subprocess.run(["bash", "-c", hint[0][len("resume with: "):] + " -q"], capture_output=True, text=True)
        else:
            self.assertEqual(p.returncode, 0)  # finished before the signal arrived
            r = run("run", study, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(same_tables(runs_table(out), ref))

    def test_resume_refuses_a_different_study(self):
        study = self.write("ok.toml", SWEEP)
        out = os.path.join(self.dir, "r.h5")
        self.assertEqual(run("run", study, "-o", out, "-q").returncode, 0)
        # another robot: none of the file's runs is a run of this study (an edit that keeps the robot,
        # task and settings reuses the file's runs instead: test_resume_edited.py)
        other = self.write("other.toml", SWEEP + "\n[robot]\nm = [5.0, 2.0, 1.5]\n")
        r = run("run", other, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("the robot changed", r.stderr)


class ShippedStudies(Base):
    def test_table4_main_job(self):
        out = os.path.join(self.dir, "t4.h5")
        r = run("run", os.path.join(STUDIES, "thesis_table4.toml"), "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("thesis vs kinesweep", r.stdout)
        for case in ("1a", "2h", "5c"):
            self.assertIn("\n" + case + " ", r.stdout)
        with h5py.File(out, "r") as f:
            self.assertEqual(len(f["runs"]["E"]), 21)

    def test_every_shipped_study_dry_runs(self):
        for name in sorted(os.listdir(STUDIES)):
            if name.endswith(".toml"):
                with self.subTest(name):
                    r = run("run", os.path.join(STUDIES, name), "--dry-run")
                    self.assertEqual(r.returncode, 0, r.stderr)


if __name__ == "__main__":
    KS, STUDIES = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"])
