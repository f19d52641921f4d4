"""SIGTERM and SIGINT during a path-global run: the optimiser checks the stop flag at every objective
evaluation, so the run in flight ends at once (the process exits 130 well within a hang limit, not
after the run's own end), the interrupted run is not written as done, and `run --resume` computes it:
the resumed file equals, run for run, the file of an uninterrupted run of the study.

usage: /usr/bin/python3 test_stop_global.py KINESWEEP_BINARY
"""
import os
import re
import signal
import subprocess
import sys
import time
import unittest

import h5py
import numpy as np

from e2e_common import TempDirTest

KS = None

# A local run (done at once), then a global run on the seed's arm slow enough (160 knots, a tight
# tolerance, 0.25 ms samples: over a thousand evaluations, above 10 s of computing) to be in flight
# when the signal comes.
STUDY = """
[study]
name = "stop_global"
histories = "none"

[task]
dt = 0.00025

[[block]]
name = "local"
kind = "trajectory"
alpha1A = -23.75

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
global_start = "vertex"
alpha1A = -23.75
vertex_alpha = [13.30, 17.28, -12.44, -16.12]
opt_tolerance = 1e-15
max_evaluations = 100000
knots = 160
"""

HANG_LIMIT_S = 5  # a hang check, not a speed claim: the global run alone takes longer


def run(*args, timeout=600):
    return subprocess.run([KS, *args], capture_output=True, text=True, timeout=timeout)


def done_count(out):
    q = run("query", out, "--limit", "1")
    m = re.search(r"(\d+) of (\d+) runs done", q.stdout + q.stderr)
    return (int(m.group(1)), int(m.group(2))) if m else (0, 0)


class StopDuringGlobalRun(TempDirTest):
    def stop_with(self, sig):
        study = self.write("s.toml", STUDY)
        out = os.path.join(self.dir, f"s{int(sig)}.h5")
        p = subprocess.Popen([KS, "run", study, "-o", out, "-q", "--threads", "1", "--no-verify-best"], stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, text=True)
        deadline = time.time() + 120  # the file created (the sweep started), then the global run under way
        while time.time() < deadline and p.poll() is None and done_count(out)[1] != 2:
            time.sleep(0.05)
        time.sleep(1.0)
        self.assertIsNone(p.poll(), "the study ended before the signal")
        sent = time.monotonic()
        p.send_signal(sig)
        try:
            p.wait(timeout=HANG_LIMIT_S)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()
            p.stderr.close()
            self.fail(f"still running {HANG_LIMIT_S} s after the signal")
        waited = time.monotonic() - sent
        err = p.stderr.read()
        p.stderr.close()
        self.assertEqual(p.returncode, 130, err)
        self.assertLess(waited, HANG_LIMIT_S)
        self.assertEqual(done_count(out), (1, 2))  # the interrupted global run is not done
        with h5py.File(out, "r") as f:  # never a stored status
            self.assertNotIn("interrupted", h5py.check_enum_dtype(f["runs"]["status"].dtype) or {})
        return study, out

    def test_sigterm_then_resume_equals_an_uninterrupted_run(self):
        study, out = self.stop_with(signal.SIGTERM)
        r = run("run", study, "-o", out, "--resume", "--threads", "1", "--no-verify-best")
        self.assertEqual(r.returncode, 0, r.stderr)
        m = re.search(r"(\d+) runs \((\d+) computed now, (\d+) already in the file\)", r.stdout + r.stderr)
        self.assertIsNotNone(m, r.stdout + r.stderr)
        self.assertEqual((m.group(1), m.group(2), m.group(3)), ("2", "1", "1"))
        whole = os.path.join(self.dir, "whole.h5")
        r = run("run", study, "-o", whole, "-q", "--threads", "1", "--no-verify-best")
        self.assertEqual(r.returncode, 0, r.stderr)
        with h5py.File(out, "r") as a, h5py.File(whole, "r") as b:
            for name in ("status", "E", "max_tracking_error", "opt_objective", "opt_evaluations"):
                x, y = a["runs"][name][()], b["runs"][name][()]
                if x.dtype.kind == "f":
                    self.assertTrue(np.array_equal(x, y, equal_nan=True), name)
                else:
                    self.assertTrue(np.array_equal(x, y), name)

    def test_sigint_stops_too(self):
        self.stop_with(signal.SIGINT)


if __name__ == "__main__":
    KS = os.path.abspath(sys.argv[1])
    unittest.main(argv=sys.argv[:1])
