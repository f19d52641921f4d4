"""End-to-end tests of normalised objectives and trade_off sweeps (seed 002 Eqs. 7.1, 7.6): the
references an [[optimize]] block stores equal the metrics of a plain run of the same design in the
same file, the best value is the normalised formula of the stored best metrics, and
kinesweep.plot_trade_off draws what h5py reads (normalised best points, the non-dominated ones).

usage: /usr/bin/python3 test_trade_off.py KINESWEEP_BINARY REPO_ROOT
"""
import json
import os
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import ANALYSIS_ENV, StudyFileTest, analysis_command

KS = None

# The seed's arm: a plain run at the optimisation's start (k = 0.4, alpha1A = 0) and a trade-off sweep
# of f1 (maximised as 1/f1) against E over three weights, normalised there.
STUDY = """
[study]
name = "trade_off_e2e"
histories = "none"

[[block]]
name = "start"
kind = "trajectory"
method = "local_weighted"
k = 0.4
alpha1A = 0

[[optimize]]
name = "place"
kind = "trajectory"
method = "local_weighted"
variables = { k = { from = 0, to = 1, start = 0.4 }, alpha1A = [-30, 30] }
objective = { "1/min_manipulability" = 1, E = 1 }
reference = "start"
trade_off = { from = 0, to = 1, step = 0.5 }
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 30
"""


class TradeOff(StudyFileTest):
    NAME = "trade_off_e2e"
    STUDY = STUDY

    @classmethod
    def setUpClass(cls):
        cls.KS = KS
        super().setUpClass()

    def test_references_are_the_plain_run_and_the_best_is_the_formula(self):
        f1_0, e_0 = self.runs["min_manipulability"][0], self.runs["E"][0]
        with h5py.File(self.h5, "r") as f:
            names = sorted(f["optimizations"])
            self.assertEqual(names, ["place_k0", "place_k0.5", "place_k1"])
            for n in names:
                a, b = f["optimizations"][n].attrs, f["optimizations"][n]["best"].attrs
                k = float(a["reference_trade_off_k"])
                self.assertEqual(float(a["reference_min_manipulability_0"]), f1_0)
                self.assertEqual(float(a["reference_E_0"]), e_0)
                self.assertEqual(float(a["reference_k_0"]), 0.4)
                want = k * f1_0 / b["min_manipulability"] + (1 - k) * b["E"] / e_0
                self.assertAlmostEqual(float(a["best_objective"]), want, delta=1e-12 * want)
                self.assertLessEqual(float(a["best_objective"]), 1.0 + 1e-12)  # never worse than the start

    def test_plot_draws_the_normalised_best_points(self):
        out = os.path.join(self.tmp.name, "front.png")
        p = subprocess.run(analysis_command("plot_trade_off", self.h5, "-o", out, "--print-data",
                                            "--mark", "1.5,0.8:published"),
                           capture_output=True, text=True, env=ANALYSIS_ENV)
        self.assertEqual(p.returncode, 0, p.stderr)
        d = json.loads(p.stdout)
        self.assertTrue(os.path.getsize(out) > 0)
        self.assertEqual(d["metrics"], ["min_manipulability", "E"])
        self.assertEqual(d["senses"], ["max", "min"])
        self.assertEqual(d["k"], [0.0, 0.5, 1.0])
        with h5py.File(self.h5, "r") as f:
            for i, n in enumerate(["place_k0", "place_k0.5", "place_k1"]):
                b = f["optimizations"][n]["best"].attrs
                self.assertAlmostEqual(d["normalised"][i][0], b["min_manipulability"] / self.runs["min_manipulability"][0], places=12)
                self.assertAlmostEqual(d["normalised"][i][1], b["E"] / self.runs["E"][0], places=12)
        pts = np.array(d["normalised"])
        for i, on in enumerate(d["front"]):  # brute force: dominated iff another point is no worse in both
            dom = any(pts[j][0] >= pts[i][0] and pts[j][1] <= pts[i][1] and (pts[j] != pts[i]).any()
                      for j in range(len(pts)) if j != i)
            self.assertEqual(on, not dom, i)
        self.assertEqual(d["marks"], [[1.5, 0.8]])

    def test_bad_arguments(self):
        p = subprocess.run(analysis_command("plot_trade_off", self.h5, "--mark", "1.5"), capture_output=True,
                           text=True, env=ANALYSIS_ENV)
        self.assertEqual(p.returncode, 2)
        self.assertIn("expected X,Y[:LABEL]", p.stderr)
        p = subprocess.run(analysis_command("plot_trade_off", self.h5, "--name", "nope"), capture_output=True,
                           text=True, env=ANALYSIS_ENV)
        self.assertEqual(p.returncode, 2)
        self.assertIn("no trade_off sweep 'nope'", p.stderr)


if __name__ == "__main__":
    KS = sys.argv.pop(1)
    sys.argv.pop(1)
    unittest.main()
