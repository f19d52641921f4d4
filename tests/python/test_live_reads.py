"""Reading a results file while a sweep writes it: ksread's calls never raise and never go back in
time (each is one committed state: kinesweep.live), and a plain h5py read guarded by the stamp
check of FORMAT.md ("Reading while a sweep runs") gets a consistent snapshot.

usage: /usr/bin/python3 test_live_reads.py KINESWEEP_BINARY ANALYSIS_DIR
"""
import os
import signal
import subprocess
import sys
import time
import unittest

import h5py
import numpy as np

from e2e_common import TempDirTest

KS = None
READS = 100

# about 12,000 runs with every other sample of their histories: several seconds of commits (one a
# second, and at every block end) on one thread
STUDY = """
[study]
name = "live"
histories = "every=2"

[[block]]
name = "first"
kind = "trajectory"
[block.axes]
alpha1A = { from = -25, to = 35, step = 0.2 }   # deg
k = { from = 0, to = 1, step = 0.05 }

[[block]]
name = "second"
kind = "trajectory"
method = "local_unweighted"
[block.axes]
alpha1A = { from = -25, to = 35, step = 0.2 }   # deg
k = { from = 0, to = 1, step = 0.05 }
"""


class LiveReads(TempDirTest):
    def start_sweep(self):
        study = self.write("live.toml", STUDY)
        self.h5 = os.path.join(self.dir, "live.h5")
        return subprocess.Popen([KS, "run", study, "-o", self.h5, "-q", "--threads", "1"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)

    def test_ksread_reads_a_file_being_written_without_failing(self):
        from kinesweep import live as kslive
        from kinesweep import read as ksread
        reopened = []
        original = ksread.Results._reopen

        def counting_reopen(results):
            reopened.append(1)
            original(results)

        ksread.Results._reopen = counting_reopen
        sweep = self.start_sweep()
        try:
            while not os.path.exists(self.h5) and sweep.poll() is None:
                time.sleep(0.01)
            done_counts, during, failures, plain = [], 0, [], None
            for i in range(READS):
                running = sweep.poll() is None
                try:
                    with ksread.open_results(self.h5) as r:
                        runs = r.runs(["run_id", "E", "block"])
                        n = len(runs["run_id"])
                        self.assertTrue(np.all(np.diff(runs["run_id"]) > 0))
                        if n:  # the newest done run's history reads with it
                            self.assertGreater(len(r.history(int(runs["run_id"][-1]))["t"]), 0)
                        r.landscapes()
                except Exception as e:  # any failure of a read is what this test counts
                    failures.append(f"read {i}: {type(e).__name__}: {e}")
                    continue
                done_counts.append(n)
                during += running and sweep.poll() is None
                if i == READS // 2:
                    plain = self.plain_h5py_read(kslive)
            sweep.send_signal(signal.SIGINT)  # enough: it stops at the next run and commits (exit 130)
            _, err = sweep.communicate(timeout=300)
        finally:
            ksread.Results._reopen = original
            if sweep.poll() is None:
                sweep.kill()
                sweep.communicate()
        print(f"{READS} reads, {during} of them while the sweep ran, {len(reopened)} retried after a commit "
              f"landed under them; done runs seen: {done_counts[:3]} ... {done_counts[-3:]}")
        self.assertIn(sweep.returncode, (0, 130), err)
        self.assertEqual(failures, [])
        self.assertEqual(done_counts, sorted(done_counts), "a later read saw fewer done runs")
        self.assertGreaterEqual(during, 20, "too few reads happened while the sweep ran to show anything")
        self.assertIsNotNone(plain)
        with h5py.File(self.h5, "r") as f:
            self.assertLessEqual(plain, int(f["runs/done"][()].sum()))

    def plain_h5py_read(self, kslive):
        """FORMAT.md's recipe with h5py alone: read /runs/done first and keep the read only if the
        stamp did not move (kslive.stamp is its 10 lines); returns the done count."""
        for _ in range(1000):
            before = kslive.stamp(self.h5)
            if before is None:
                time.sleep(0.01)
                continue
            try:
                with h5py.File(self.h5, "r") as f:
                    done = f["runs/done"][()].astype(bool)
                    e = f["runs/E"][()][done]
            except OSError:
                continue
            if kslive.stamp(self.h5) == before:
                self.assertEqual(len(e), int(done.sum()))
                return int(done.sum())
        self.fail("no plain h5py read fitted between two commits")


if __name__ == "__main__":
    KS = sys.argv[1]
    sys.path.insert(0, sys.argv[2])
    unittest.main(argv=sys.argv[:1], verbosity=2)
