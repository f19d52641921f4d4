"""Motion runs against their grid (/verification, written by `kinesweep run`): the best good run of
each motion block is computed again with 2 and 4 times as many sample intervals (refinement
`samples`) and, when it solves with controls, with 2K and 4K controls (`controls`):
- every row's grid 3 value is the run's /runs value; its grid 1 and 2 values are those of the same
  run computed by a study of its own with those samples or controls, read from that study's /runs
  (bit for bit);
- its `dt` is the sample step at the stored final duration, its `knots` the controls per joint;
- a motion that only evaluates the cubic (solve = false) has the samples refinement alone;
- `kinesweep run`, `info` and `compare` print the grid statements.

usage: /usr/bin/python3 test_motion_verification.py KINESWEEP_BINARY SOURCE_DIR
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

import h5py

from e2e_common import runs_column

KS = None
SOURCE = None

STUDY = """
[study]
name = "motion_grid"
histories = "none"

[robot]
dh = "{robots}/planar2r.toml"

[[block]]
name = "cubic"
kind = "motion"
goal_1 = 90
goal_2 = 45
duration = 2
controls = 2
samples = {samples}
solve = false

[[block]]
name = "m"
kind = "motion"
goal_1 = 90
goal_2 = 45
duration = 2
controls = {controls}
samples = {samples}
w_torque = 1
w_power = 1
max_evaluations = 400
"""
SAMPLES, CONTROLS = 41, 2
QUANTITIES = ("objective", "final_duration", "torque_sq_integral", "power_sq_integral")


def sample_count(samples, controls):
    """The motion's samples: the least N >= samples with N - 1 a multiple of controls + 1."""
    seg = controls + 1
    return max(1, -(-(samples - 1) // seg)) * seg + 1


def run(*args):
    p = subprocess.run([KS, *args], capture_output=True, text=True)
    if p.returncode != 0:
        raise AssertionError(f"kinesweep {' '.join(args)} exited {p.returncode}:\n{p.stdout}\n{p.stderr}")
    return p.stdout


class MotionVerification(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.robots = os.path.abspath(os.path.join(SOURCE, "studies", "robots"))
        cls.h5 = cls.study(SAMPLES, CONTROLS, "grid", verify=True)
        with h5py.File(cls.h5, "r") as f:
            cls.runs = {c: runs_column(f["runs"][c]) for c in ("run_id", "block", "status") + QUANTITIES}
            g = f["verification"]
            n = len(g["run"])
            cols = {k: (g[k].asstr()[()] if g[k].dtype.kind == "O" else g[k][()]) for k in g
                    if isinstance(g[k], h5py.Dataset) and g[k].shape[:1] == (n,)}
            cls.rows = [{k: v[i] for k, v in cols.items()} for i in range(n)]

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    @classmethod
    def study(cls, samples, controls, name, verify=False):
        p = os.path.join(cls.tmp.name, name + ".toml")
        with open(p, "w") as f:
            f.write(STUDY.format(robots=cls.robots, samples=samples, controls=controls))
        h5 = os.path.join(cls.tmp.name, name + ".h5")
        if verify:
            cls.printed = run("run", p, "-o", h5, "--threads", "2")
        else:
            run("run", p, "-o", h5, "-q", "--no-verify-best")
        return h5

    def stored(self, path, block, quantity):
        with h5py.File(path, "r") as f:
            blocks = runs_column(f["runs"]["block"])
            (i,) = [k for k, b in enumerate(blocks) if b == block]
            return float(f["runs"][quantity][i])

    def test_rows_of_each_block(self):
        by_block = {}
        for r in self.rows:
            by_block.setdefault(r["block"], set()).add((r["refinement"], r["quantity"]))
        self.assertEqual(by_block["m"], {(ref, q) for ref in ("samples", "controls") for q in QUANTITIES})
        self.assertEqual(by_block["cubic"], {("samples", q) for q in QUANTITIES})
        for r in self.rows:
            self.assertTrue(r["group"].endswith(" of block=" + r["block"]), r["group"])

    def test_grids_are_the_runs_of_refined_studies(self):
        n = sample_count(SAMPLES, CONTROLS)
        refined = {}
        for factor in (2, 4):
            refined[("samples", factor)] = self.study(factor * (n - 1) + 1, CONTROLS, f"samples{factor}")
            refined[("controls", factor)] = self.study(SAMPLES, CONTROLS * factor, f"controls{factor}")
        checked = 0
        for r in self.rows:
            stored = self.stored(self.h5, r["block"], r["quantity"])
            self.assertEqual(r["value"][2], stored, r)
            T = self.stored(self.h5, r["block"], "final_duration")
            k = CONTROLS
            for g, factor in ((0, 4), (1, 2)):
                if r["refinement"] == "samples":
                    self.assertEqual(r["knots"][g], k)
                    self.assertAlmostEqual(r["dt"][g], T / (factor * (sample_count(SAMPLES, k) - 1)), delta=1e-15)
                else:
                    self.assertEqual(r["knots"][g], k * factor)
                    self.assertAlmostEqual(r["dt"][g], T / (sample_count(SAMPLES, k * factor) - 1), delta=1e-15)
                if r["block"] == "cubic" and r["refinement"] == "controls":
                    continue
                self.assertEqual(r["value"][g], self.stored(refined[(r["refinement"], factor)], r["block"],
                                                            r["quantity"]), (r["refinement"], factor, r["quantity"]))
                checked += 1
        self.assertEqual(checked, 2 * (2 * 4 + 4))

    def test_printed_by_run_info_and_compare(self):
        self.assertIn("samples: objective = ", self.printed)
        self.assertIn("controls: objective = ", self.printed)
        info = run("info", self.h5)
        self.assertIn("(block m, lowest objective, torque_sq_integral of block=m)", info)
        rows = json.loads(run("compare", self.h5, "--by", "block", "--metric", "objective", "--format", "json"))
        rows = rows["rows"] if isinstance(rows, dict) else rows
        grid = {row["block"]: row["grid"] for row in rows}
        converged = [r for r in self.rows if r["block"] == "m" and r["quantity"] == "objective"]
        expected = "converged" if all(r["convergence"] in ("monotone", "unchanged") for r in converged) else None
        if expected:
            self.assertEqual(grid["m"], expected)
        else:
            self.assertIn(grid["m"], ("diverges", "oscillates", "not_enough"))
        for r in self.rows:
            if r["convergence"] == "monotone":
                f1, f2, f3 = r["value"]
                p = math.log(abs((f3 - f2) / (f2 - f1))) / math.log(2.0)
                self.assertAlmostEqual(r["order"], p, delta=1e-9 * max(1.0, abs(p)))


if __name__ == "__main__":
    KS, SOURCE = sys.argv[1], sys.argv[2]
    del sys.argv[1:]
    unittest.main()
