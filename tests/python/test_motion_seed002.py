"""Seed 002's motion experiments (Sections 7.2 and 7.4) as shipped, run here with histories and read
back with h5py; the comparisons studies/README.md states are these files' numbers.

- 7.2 (motion_puma, motion_planar2r): the optimum at the seed's best weight lowers both f5 and f6
  below the initial cubic's, and the k sweep traces a front (no k's optimum dominates another's, kinesweep.pareto as
  `query --pareto` computes it); at the seed's best weight the objective p is below the seed's own p
  at its published optimum (Puma k = 0.4: 0.4 * 22.66/23.03 + 0.6 * 137.97/206.66; 2R k = 0.2:
  0.2 * 370.51/446.85 + 0.8 * 7.39/8.83).
- 7.4 (motion_elbow): the seed's initial cubic collides with the cube (the seed: "becomes
  infeasible"); every optimised run is ok, its least clearance >= 0 at the samples and at the dense
  check, and the clearance recomputed here from the stored link points against the box (point
  distances, kinesweep.motion_view) agrees with the engine's at every stored sample; each K lowers
  both T and f6 below the cubic's, and T is at most Table 7.15's for K = 1, 2, 3.
- 7.5 (motion_moving_2r): three obstacles moving in straight lines; the cubic collides near t = 3 s,
  the optimum is ok with f6 below the cubic's, and the clearance recomputed here with each obstacle
  where it is at each sample's time equals the engine's.
- studies/README.md's tables of these experiments are these files' numbers, and so is its statement of
  the Elbow optimum against the grid (/verification); the report of the Elbow file has the arm's
  motion figure.

usage: /usr/bin/python3 test_motion_seed002.py KINESWEEP_BINARY SOURCE_DIR
"""
import os
import re
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

from e2e_common import ANALYSIS_ENV, analysis_command, history

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
from kinesweep import motion_view, pareto  # noqa: E402
from kinesweep.kinds import text_values  # noqa: E402

KS = SOURCE = None
SEED_P = {"motion_puma": (0.4, 0.4 * 22.66 / 23.03 + 0.6 * 137.97 / 206.66),
          "motion_planar2r": (0.2, 0.2 * 370.51 / 446.85 + 0.8 * 7.39 / 8.83)}
TABLE_7_15_T = {1: 10.7, 2: 10.0, 3: 9.7, 4: 7.4}


def columns(f):
    runs = f["runs"]
    out = {k: runs[k][()] for k in runs if k not in ("status", "block")}
    out["status"] = np.asarray(text_values(runs["status"]))
    out["block"] = np.asarray(text_values(runs["block"]))
    return out


class MotionSeed002(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.h5 = {}
        for s in ("motion_puma", "motion_planar2r", "motion_elbow", "motion_moving_2r"):
            cls.h5[s] = os.path.join(cls.tmp.name, s + ".h5")
            r = subprocess.run([KS, "run", os.path.join(SOURCE, "studies", s + ".toml"), "-o", cls.h5[s], "-q"],
                               capture_output=True, text=True)
            assert r.returncode == 0, r.stderr
        cls.c = {}
        for s, path in cls.h5.items():
            with h5py.File(path, "r") as f:
                cls.c[s] = columns(f)
        with open(os.path.join(SOURCE, "studies", "README.md"), encoding="utf-8") as fh:
            cls.readme = fh.read()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_weight_sweeps_lower_both_criteria_and_trace_a_front(self):
        for s, (k, seed_p) in SEED_P.items():
            with self.subTest(s):
                c = self.c[s]
                sweep = c["block"] == "k_sweep"
                self.assertTrue((c["status"][sweep] == "ok").all())
                front = pareto.pareto_front(self.h5[s], "torque_sq_integral,power_sq_integral", where="block=k_sweep")
                self.assertEqual(len(front["run_id"]), int(sweep.sum()))  # every k's optimum is on it
                at = sweep & np.isclose(c["w_torque"], k)
                self.assertEqual(int(at.sum()), 1)
                self.assertLess(float(c["objective"][at][0]), seed_p)
                self.assertLess(c["torque_sq_integral"][at][0], c["torque_sq_integral_0"][at][0])
                self.assertLess(c["power_sq_integral"][at][0], c["power_sq_integral_0"][at][0])

    def test_elbow_passes_the_cube_where_the_cubic_collides(self):
        c = self.c["motion_elbow"]
        with open(os.path.join(SOURCE, "studies", "motion_elbow.toml"), encoding="utf-8") as fh:
            obstacles, radii = motion_view.world_of(fh.read())
        self.assertEqual([o["type"] for o in obstacles], ["box"])
        with h5py.File(self.h5["motion_elbow"], "r") as f:
            for run in range(len(c["status"])):
                pts = history(f, run)["points"]
                here = np.array([motion_view.clearance(row, radii, obstacles) for row in pts])
                with self.subTest(run=run):
                    # sampled along each link, the distance here is at most 1.2 m / 2000 / 2 above the exact one
                    self.assertGreaterEqual(here.min(), c["min_clearance"][run] - 1e-12)
                    self.assertLessEqual(here.min(), c["min_clearance"][run] + 4e-4)
        cubic = c["block"] == "cubic"
        self.assertEqual(c["status"][cubic].tolist(), ["collision"])
        self.assertLess(c["check_min_clearance"][cubic][0], 0.0)
        self.assertEqual(c["final_duration"][cubic][0], 10.0)
        opt = c["block"] == "controls"
        self.assertEqual(sorted(c["controls"][opt].tolist()), [1, 2, 3, 4])
        for i in np.nonzero(opt)[0]:
            with self.subTest(controls=int(c["controls"][i])):
                self.assertEqual(c["status"][i], "ok")
                self.assertGreaterEqual(c["min_clearance"][i], 0.0)
                self.assertGreaterEqual(c["check_min_clearance"][i], 0.0)
                self.assertLess(c["final_duration"][i], 10.0)
                self.assertLess(c["power_sq_integral"][i], c["power_sq_integral_0"][i])
                K = int(c["controls"][i])
                if K <= 3:
                    self.assertLessEqual(c["final_duration"][i], TABLE_7_15_T[K])

    def test_planar2r_passes_three_moving_obstacles(self):
        c = self.c["motion_moving_2r"]
        with open(os.path.join(SOURCE, "studies", "motion_moving_2r.toml"), encoding="utf-8") as fh:
            obstacles, radii = motion_view.world_of(fh.read())
        self.assertTrue(motion_view.moving(obstacles))
        with h5py.File(self.h5["motion_moving_2r"], "r") as f:
            for run in (0, 1):
                h = history(f, run)
                t = h["t"][:, 0]
                here = np.array([motion_view.clearance(row, radii, obstacles, ts) for row, ts in zip(h["points"], t)])
                # spheres: exact point-segment distances, each obstacle where it is at the sample's time
                self.assertAlmostEqual(here.min(), c["min_clearance"][run], delta=1e-12)
                if run == 0:  # the cubic runs into an obstacle near t = 3 s (the seed: t = 3 s and 5 s)
                    hit = t[here < 0]
                    self.assertTrue(len(hit) > 0 and 2.5 < hit.min() and hit.max() < 3.5, hit)
        self.assertEqual(c["status"].tolist(), ["collision", "ok"])
        self.assertGreaterEqual(c["check_min_clearance"][1], 0.0)
        self.assertLess(c["power_sq_integral"][1], c["power_sq_integral_0"][1])

    def test_readme_tables_are_these_files(self):
        c = self.c["motion_elbow"]
        section = self.readme[self.readme.index("**Section 7.4, time, power and a fixed obstacle.**"):]
        for i in range(len(c["status"])):
            K = int(c["controls"][i]) if c["block"][i] == "controls" else 0
            m = re.search(r"^\| " + str(K) + r"[^|]*\| [^|]* / ([0-9.]+) \| [^|]* / ([0-9.]+) W²s", section, re.M)
            self.assertIsNotNone(m, f"studies/README.md has no Elbow row for K = {K}")
            self.assertEqual(m.group(1), f"{c['final_duration'][i]:.2f}")
            self.assertEqual(m.group(2), f"{c['power_sq_integral'][i]:.1f}")
        for s, (k, _) in SEED_P.items():
            c = self.c[s]
            at = (c["block"] == "k_sweep") & np.isclose(c["w_torque"], k)
            label = {"motion_puma": "Puma 560", "motion_planar2r": "planar 2R"}[s]
            m = re.search(r"^\| " + re.escape(label) + r", k = [0-9.]+ \| [^|]* / ([0-9.]+) \([^)]*\) \| "
                          r"[^|]* / ([0-9.]+) \([^)]*\) \| [^|]* / ([0-9.]+) \|", self.readme, re.M)
            self.assertIsNotNone(m, f"studies/README.md has no row for {label}")
            self.assertEqual(m.group(1), f"{c['torque_sq_integral'][at][0]:.1f}")
            self.assertEqual(m.group(2), f"{c['power_sq_integral'][at][0]:.2f}")
            self.assertEqual(m.group(3), f"{c['objective'][at][0]:.3f}")

    def test_readme_grid_statement_is_this_file(self):
        """The Elbow's "Against the grid" paragraph: K = 4's optimum against 2 and 4 times the sample
        intervals and 2K, 4K controls, as /verification holds them."""
        with h5py.File(self.h5["motion_elbow"], "r") as f:
            g = f["verification"]
            rows = {(g["refinement"].asstr()[i], g["quantity"].asstr()[i]): (g["value"][i], g["gci_coarse"][i],
                                                                              g["extrapolated"][i])
                    for i in range(len(g["run"])) if g["group"].asstr()[i].startswith("lowest objective")}
        para = self.readme[self.readme.index("**Against the grid**"):]
        para = " ".join(para[:para.index("\n\n")].split())
        e = lambda x: f"{100 * x:.1e}".replace("e-0", "e-")  # noqa: E731
        T, T_gci, _ = rows[("samples", "final_duration")]
        self.assertIn(f"T = {T[2]:.3f} s, GCI {e(T_gci)} %", para)
        self.assertIn(f"f6 GCI {e(rows[('samples', 'power_sq_integral')][1])} %", para)
        _, gci, rich = rows[("controls", "final_duration")]
        self.assertIn(f"T GCI {100 * gci:.1f} %, Richardson value {rich:.2f} s", para)
        _, gci, rich = rows[("controls", "power_sq_integral")]
        self.assertIn(f"f6 GCI {100 * gci:.1f} %, {rich:.0f} W²s", para)

    def test_report_draws_the_arm(self):
        out = os.path.join(self.tmp.name, "elbow.html")
        r = subprocess.run(analysis_command("report", self.h5["motion_elbow"], "-o", out), capture_output=True,
                           text=True, env=ANALYSIS_ENV, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(out, encoding="utf-8") as fh:
            self.assertIn('id="motion-0"', fh.read())


if __name__ == "__main__":
    KS, SOURCE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    del sys.argv[1:]
    unittest.main(argv=[sys.argv[0], "-v"])
