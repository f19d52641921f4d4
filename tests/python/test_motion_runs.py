"""Motion runs (kind = "motion") end to end: a small study on the Puma arm with its wrist locked
(studies/robots/puma560_arm.toml, seed 002 section 7.2's motion from 0 to (90, 45, -30) deg in 9 s),
read back with h5py.

- the initial cubic's run (solve = false) stores f5 and f6 equal to numpy's trapezoid of its stored
  history (tau at the samples, t), and equal to its own references torque_sq_integral_0 / _0;
- the optimised run (w_torque = 0.4, w_power = 0.6, normalised) ends below both references, and its
  history integrates to its stored f5 and f6 too;
- every status is one of the kind's; a good run has no NaN metric but min_clearance without obstacles;
- a sphere on the cubic's path: the cubic collides, and the solved run is never ok with a negative
  clearance (ok with min_clearance >= 0, or collision / infeasible);
- the dense check: a small sphere that the cubic's tip crosses between two of its 3 samples is missed
  by them (min_clearance > 0) and found by the check at 8 times as many (check_samples = 17,
  check_min_clearance < 0): the run is `collision`, never `ok`; the clearance recomputed here from the
  stored link points (kinesweep.motion_view, point distances) agrees with the engine's at every sample;
- kinesweep.plot_motion draws the run's sweep: its closest sample is the least of those clearances;
- parse errors are located: an unknown obstacle type, a link_radius of the wrong size, a centre of 2
  numbers, start_4 on a 3-joint robot, w_clearance without obstacles, a motion block on the seed's
  closed-form 3R.

usage: /usr/bin/python3 test_motion_runs.py KINESWEEP_BINARY ROBOTS_DIR
"""
import json
import math
import os
import re
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import ANALYSIS_ENV, TempDirTest, analysis_command, history

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
from kinesweep import motion_view  # noqa: E402

KS = None
ROBOTS = None
STATUSES = {"ok", "infeasible", "collision", "max_evaluations", "failure"}

MOTION = """
[[block]]
name = "{name}"
kind = "motion"
goal_1 = 90
goal_2 = 45
goal_3 = -30
duration = 9
controls = 1
max_evaluations = 60
w_torque = 0.4
w_power = 0.6
{extra}
"""


def study(name, blocks, world=""):
    return (f'[study]\nname = "{name}"\nhistories = "full"\n\n[robot]\ndh = "{ROBOTS}/puma560_arm.toml"\n\n'
            + world + "".join(MOTION.format(name=n, extra=e) for n, e in blocks))


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


class MotionRuns(TempDirTest):
    def run_study(self, name, body):
        path = self.write(name + ".toml", body)
        out = os.path.join(self.dir, name + ".h5")
        r = subprocess.run([KS, "run", path, "-o", out, "-q"], capture_output=True, text=True, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        return out

    def rows(self, f):
        runs = f["runs"]
        status = runs["status"]
        labels = h5py.check_enum_dtype(status.dtype)
        if labels:
            by_code = {v: k for k, v in labels.items()}
            st = [by_code[int(c)] for c in status[:]]
        else:
            st = [text(s) for s in status[:]]
        cols = {k: runs[k][:] for k in runs if k not in ("status", "block")}
        return st, cols

    def integrals(self, f, run):
        h = history(f, run)
        t, tau, qd = h["t"].ravel(), h["tau"], h["qd"]
        trapezoid = getattr(np, "trapezoid", None) or np.trapz  # numpy < 2 names it trapz
        return trapezoid((tau ** 2).sum(axis=1), t), trapezoid(((tau * qd) ** 2).sum(axis=1), t)

    def test_cubic_and_optimised(self):
        out = self.run_study("puma", study("puma", [("cubic", "solve = false"), ("opt", "")]))
        with h5py.File(out, "r") as f:
            st, c = self.rows(f)
            self.assertEqual(len(st), 2)
            self.assertTrue(set(st) <= STATUSES, st)
            self.assertEqual(st, ["ok", "ok"])
            f5, f6 = c["torque_sq_integral"], c["power_sq_integral"]
            f50, f60 = c["torque_sq_integral_0"], c["power_sq_integral_0"]
            for run in (0, 1):
                i5, i6 = self.integrals(f, run)
                self.assertAlmostEqual(i5 / f5[run], 1.0, delta=1e-9)
                self.assertAlmostEqual(i6 / f6[run], 1.0, delta=1e-9)
                for k, v in c.items():
                    if k not in ("min_clearance", "check_min_clearance", "check_max_limit") and \
                            np.issubdtype(v.dtype, np.floating):  # NaN: no obstacles, no limits
                        self.assertFalse(math.isnan(v[run]), f"run {run} {k}")
            self.assertEqual((f5[0], f6[0]), (f50[0], f60[0]))
            self.assertEqual(c["evaluations"][0], 0)
            self.assertAlmostEqual(c["objective"][0], 1.0, delta=1e-12)  # 0.4 + 0.6 at the reference
            self.assertLess(f5[1], f50[1])
            self.assertLess(f6[1], f60[1])
            self.assertLess(c["objective"][1], 1.0)
            self.assertGreater(c["evaluations"][1], 0)
            self.assertTrue(np.isnan(c["min_clearance"]).all())  # no [world]
            self.assertAlmostEqual(c["final_duration"][1], 9.0)
            print(f"cubic f5 {f5[0]:.6g} f6 {f6[0]:.6g}; optimised f5 {f5[1]:.6g} f6 {f6[1]:.6g}")

    def test_sphere_on_the_path(self):
        world = ('[world]\nlink_radius = [0.05, 0.05, 0.05]\n'
                 'obstacles = [{ type = "sphere", centre = [0.141, 0.141, 0.083], radius = 0.05 }]\n\n')
        out = self.run_study("sphere", study("sphere", [("cubic", "solve = false"), ("opt", "w_clearance = 0.1")], world))
        with h5py.File(out, "r") as f:
            st, c = self.rows(f)
            self.assertTrue(set(st) <= STATUSES, st)
            self.assertLess(c["min_clearance"][0], 0.0)  # the sphere is on the cubic's path
            self.assertEqual(st[0], "collision")
            self.assertIn(st[1], {"ok", "collision", "infeasible", "max_evaluations"})
            if st[1] == "ok":
                self.assertGreaterEqual(c["min_clearance"][1], 0.0)
            if c["min_clearance"][1] < 0.0:
                self.assertEqual(st[1], "collision")
            print(f"sphere: cubic {st[0]} ({c['min_clearance'][0]:.4g} m), solved {st[1]} ({c['min_clearance'][1]:.4g} m)")

    def test_dense_check_finds_a_collision_between_samples(self):
        dense = self.run_study("dense", study("dense", [("cubic", "solve = false\nsamples = 201")]))
        with h5py.File(dense, "r") as f:
            pts = history(f, 0)["points"]
        self.assertEqual(pts.shape, (201, 12))  # joint origins of 3 joints and the tip, x y z each
        tip = pts[50, 9:12]  # t = T / 4: between the samples 0, T / 2, T of a 3-sample run
        world = ('[world]\nlink_radius = [0.0, 0.0, 0.0]\n'
                 f'obstacles = [{{ type = "sphere", centre = [{tip[0]!r}, {tip[1]!r}, {tip[2]!r}], radius = 0.02 }}]\n\n')
        out = self.run_study("between", study("between", [("coarse", "solve = false\nsamples = 3"),
                                                          ("fine", "solve = false\nsamples = 201")], world))
        obstacles, radii = motion_view.world_of(world)
        with h5py.File(out, "r") as f:
            st, c = self.rows(f)
            self.assertGreater(c["min_clearance"][0], 0.02)        # its 3 samples miss the sphere
            self.assertEqual(int(c["check_samples"][0]), 17)
            self.assertLess(c["check_min_clearance"][0], 0.0)      # the check does not
            self.assertEqual(st[0], "collision")
            self.assertEqual(st[1], "collision")
            self.assertLess(c["min_clearance"][1], 0.0)
            self.assertTrue(np.isnan(c["check_max_limit"]).all())  # the arm has no limits
            fine = history(f, 1)["points"]
            here = np.array([motion_view.clearance(row, radii, obstacles) for row in fine])
        self.assertAlmostEqual(here.min(), c["min_clearance"][1], delta=1e-12)
        self.assertLessEqual(c["check_min_clearance"][1], here.min() + 1e-12)
        png = os.path.join(self.dir, "between.png")
        r = subprocess.run(analysis_command("plot_motion", out, "--runs", "1", "-o", png, "--print-data"),
                           capture_output=True, text=True, timeout=300, env=ANALYSIS_ENV)
        self.assertEqual(r.returncode, 0, r.stderr)
        data = json.loads(r.stdout)
        self.assertTrue(os.path.getsize(png) > 0)
        self.assertEqual(data["rows"][0]["closest_sample"], int(np.argmin(here)))
        self.assertEqual(data["rows"][0]["frames"][0], 0)
        self.assertEqual(data["rows"][0]["frames"][-1], 200)

    def refused(self, name, body, line, words):
        path = self.write(name + ".toml", body)
        r = subprocess.run([KS, "run", path, "-o", os.path.join(self.dir, name + ".h5"), "-q"],
                           capture_output=True, text=True, timeout=60)
        self.assertNotEqual(r.returncode, 0)
        self.assertRegex(r.stderr, re.escape(name + ".toml") + f":{line}:\\d+")
        for w in words:
            self.assertIn(w, r.stderr)

    def test_parse_errors(self):
        world = ('[world]\nlink_radius = [0.05, 0.05, 0.05]\n'
                 'obstacles = [{ type = "cube", centre = [0, 0, 0], radius = 0.1 }]\n\n')
        self.refused("bad_type", study("bad_type", [("m", "")], world), 10,
                     ["unknown obstacle type 'cube'", "expected \"sphere\", \"box\" or \"capsule\""])
        world = ('[world]\nlink_radius = [0.05, 0.05]\n'
                 'obstacles = [{ type = "sphere", centre = [1, 1, 1], radius = 0.1 }]\n\n')
        self.refused("bad_radii", study("bad_radii", [("m", "")], world), 9,
                     ["link_radius is an array of 2", "expected an array of 3 radii"])
        world = ('[world]\nlink_radius = [0.05, 0.05, 0.05]\n'
                 'obstacles = [{ type = "box", centre = [1, 1], half = [0.1, 0.1, 0.1] }]\n\n')
        self.refused("bad_centre", study("bad_centre", [("m", "")], world), 10, ["centre is an array of 2"])
        world = ('[world]\nlink_radius = [0.05, 0.05, 0.05]\n'
                 'obstacles = [{ type = "sphere", centre = [1, 1, 1], radius = 0.1, velocity = [1, 2] }]\n\n')
        self.refused("bad_velocity", study("bad_velocity", [("m", "")], world), 10,
                     ["velocity is an array of 2", "[vx, vy, vz] [m/s]"])
        self.refused("start4", study("start4", [("m", "start_4 = 10")]), 20, ["unknown key 'start_4'"])
        self.refused("no_world", study("no_world", [("m", "w_clearance = 1")]), 20,
                     ["w_clearance weighs the least clearance", "[world] obstacles with link_radius"])
        seed = '[study]\nname = "seed"\n\n[[block]]\nname = "m"\nkind = "motion"\n'
        self.refused("seed", seed, 6, ["closed-form 3R", "l = [1, 1, 1]"])


if __name__ == "__main__":
    KS = os.path.abspath(sys.argv[1])
    ROBOTS = os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"])
