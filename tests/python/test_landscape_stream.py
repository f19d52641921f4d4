"""Landscapes are written with the runs' rows: a sweep stopped half-way leaves a file whose landscape
holds exactly its done runs (NaN elsewhere) and plots; resuming it gives the landscape of an
uninterrupted sweep, bit for bit. Checked against the /runs table (h5py) of the same file.

usage: /usr/bin/python3 test_landscape_stream.py KINESWEEP_BINARY ANALYSIS_DIR
"""
import os
import signal
import subprocess
import sys
import time
import unittest

import h5py
import numpy as np

from e2e_common import TempDirTest, bitwise_equal, runs_column

KS = ANALYSIS = None

STUDY = """
[study]
name = "stream"
histories = "every=2"

[[block]]
name = "local"
kind = "trajectory"
[block.axes]
alpha1A = { from = -25, to = 35, step = 0.1 }   # deg
k = { from = 0, to = 1, step = 0.05 }
"""


def done_count(path):
    sys.path.insert(0, ANALYSIS)
    from kinesweep import read as ksread
    try:
        with ksread.open_results(path) as r:
            return len(r.runs(["run_id"])["run_id"])
    except (OSError, FileNotFoundError, KeyError):
        return 0


def landscape(path):
    with h5py.File(path, "r") as f:
        g = f["landscapes/local"]
        return {m: g[m][()] for m in g.attrs["metrics"]}


class LandscapeStream(TempDirTest):
    def test_an_interrupted_sweep_has_the_landscape_of_its_done_runs_and_resumes_to_the_full_one(self):
        study = self.write("stream.toml", STUDY)
        out = os.path.join(self.dir, "stream.h5")
        run = [KS, "run", study, "-o", out, "-q", "--threads", "1"]
        sweep = subprocess.Popen(run, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        try:
            deadline = time.monotonic() + 120
            while sweep.poll() is None and done_count(out) < 1500 and time.monotonic() < deadline:
                time.sleep(0.05)
            sweep.send_signal(signal.SIGINT)
            _, err = sweep.communicate(timeout=120)
        finally:
            if sweep.poll() is None:
                sweep.kill()
        self.assertEqual(sweep.returncode, 130, err)

        with h5py.File(out, "r") as f:
            done = f["runs/done"][()].astype(bool)
            E = f["runs/E"][()]
            status = runs_column(f["runs/status"])
        n = len(done)
        self.assertTrue(0 < done.sum() < n, f"{done.sum()} of {n} runs done: the stop came too late or too early")
        grid = landscape(out)
        self.assertEqual(grid["E"].shape, (601, 21))
        flat_E, flat_ok = grid["E"].reshape(-1), grid["ok"].reshape(-1)
        self.assertTrue(bitwise_equal(flat_E[done], E[done]))  # a run's cell is its index in the block
        self.assertTrue(np.array_equal(flat_ok[done], (status[done] == "ok").astype(float)))
        self.assertTrue(np.all(np.isnan(flat_E[~done])) and np.all(np.isnan(flat_ok[~done])))

        png = os.path.join(self.dir, "partial.png")
        r = subprocess.run(["/usr/bin/python3", "-m", "kinesweep.plot_landscape", out, "-o", png],
                           capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=ANALYSIS))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertGreater(os.path.getsize(png), 1000)

        r = subprocess.run(run + ["--resume"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        fresh = os.path.join(self.dir, "fresh.h5")
        r = subprocess.run([KS, "run", study, "-o", fresh, "-q", "--histories", "none"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        resumed, want = landscape(out), landscape(fresh)
        self.assertEqual(resumed.keys(), want.keys())
        for m in want:
            self.assertTrue(bitwise_equal(resumed[m], want[m]), m)


if __name__ == "__main__":
    KS, ANALYSIS = sys.argv[1], sys.argv[2]
    unittest.main(argv=sys.argv[:1], verbosity=2)
