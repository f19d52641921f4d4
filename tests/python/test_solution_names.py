"""One name per IK solution everywhere: on the SCARA study (studies/ik_scara.toml) the report's basin
figure and plot_basins name each solution as /runs' solution column does (solution s, with the
joint values of the runs /runs counts as reaching s, read here with h5py).

usage: /usr/bin/python3 test_solution_names.py KINESWEEP_BINARY SOURCE_DIR
"""
import json
import os
import re
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import ANALYSIS_ENV, TempDirTest, analysis_command, report_page, runs_column

KS = SOURCE = None


class SolutionNames(TempDirTest):
    def test_report_and_plot_basins_use_the_runs_names(self):
        out = os.path.join(self.dir, "ik.h5")
        r = subprocess.run([KS, "run", os.path.join(SOURCE, "studies", "ik_scara.toml"), "-o", out, "-q"],
                           capture_output=True, text=True, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        # /runs: the median theta1 [deg] of the converged runs of each solution id
        with h5py.File(out, "r") as f:
            sol = f["runs"]["solution"][()]
            ok = runs_column(f["runs"]["status"]) == "converged"
            q1 = np.degrees(f["runs"]["q_final_1"][()])
        want = {int(s): float(np.median(q1[ok & (sol == s)])) for s in np.unique(sol[ok]) if s >= 0}
        self.assertEqual(sorted(want), [0, 1])
        _, islands = report_page(self, out, self.dir)
        islands = {k: v for k, v in islands.items() if k.startswith("basins-")}
        self.assertTrue(islands)
        for fid, text in islands.items():
            names = {int(s): float(t) for s, t in re.findall(r"solution (\d+): \\u03b81 = (-?[\d.]+)", text)}
            self.assertTrue(names, fid)
            for s, theta in names.items():
                self.assertIn(s, want, fid)
                self.assertAlmostEqual(theta, want[s], delta=0.1, msg=f"{fid} solution {s}")
        r = subprocess.run(analysis_command("plot_basins", out, "-o", os.path.join(self.dir, "b.png"), "--print-data"),
                           capture_output=True, text=True, timeout=300, env=ANALYSIS_ENV)
        self.assertEqual(r.returncode, 0, r.stderr)
        labels = json.loads(r.stdout)["solutions"]
        for s, label in labels.items():
            m = re.match(r"solution (\d+): θ1 = (-?[\d.]+)", label)
            self.assertIsNotNone(m, label)
            self.assertEqual(int(m.group(1)), int(s))
            self.assertAlmostEqual(float(m.group(2)), want[int(s)], delta=0.1, msg=label)


if __name__ == "__main__":
    KS = os.path.abspath(sys.argv[1])
    SOURCE = os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"])
