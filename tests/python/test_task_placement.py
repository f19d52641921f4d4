"""End-to-end tests of the task placement parameters (task_rotation, task_dx, task_dy, task_dz,
task_time_scale) through `kinesweep run` and h5py:
- a placement that puts the path outside the robot's workspace ends the run with status out_of_reach
  and stores seed 002's inverse-kinematics error (oracle: the distance from each vertex to the arm's
  reach, computed here), never a crash or a NaN ik_error;
- a study resumed after a placement axis was added reuses the runs already done (their wall_time
  copied, the summary line's counts) and comes out equal to a fresh run of the edited study;
- bad placement values exit 2 with FILE:LINE:COL.

usage: /usr/bin/python3 test_task_placement.py KINESWEEP_BINARY
"""
import math
import os
import re
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import TempDirTest, bitwise_equal, runs_column, runs_table, same_tables

KS = None
SQUARE = [(1.5, 1.5), (1.5, 2.0), (2.0, 2.0), (2.0, 1.5), (1.5, 1.5)]  # the seed's square [m]

FAR = """[study]
name = "far"
histories = "none"
{robot}
[[block]]
name = "placed"
kind = "trajectory"
method = "local_weighted"
[block.axes]
task_dx = [0.0, 0.5, 1.25, 5.0]
task_rotation = [0.0, 1.0]
"""

BASE = """[study]
name = "grow"
histories = "every=100"

[[block]]
name = "b"
kind = "trajectory"
method = "local_weighted"
[block.axes]
k = [0.0, 0.5]
alpha1A = [0, 10]
"""


def run(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True)


def computed(stdout):
    m = re.search(r"\((\d+) computed now, (\d+) already in the file\)", stdout)
    assert m, stdout
    return int(m.group(1)), int(m.group(2))


def reach_error(dx, beta, outer):
    """Seed 002's IK error of the square turned by beta and moved by dx, for an arm reaching `outer`
    metres (no inner hole): the sum over vertices of the distance beyond the reach, each when >= 1 mm."""
    total = 0.0
    for x, y in SQUARE:
        px = math.cos(beta) * x - math.sin(beta) * y + dx
        py = math.sin(beta) * x + math.cos(beta) * y
        d = max(0.0, math.hypot(px, py) - outer)
        total += d if d >= 1e-3 else 0.0
    return total


class OutOfReach(TempDirTest):
    def check(self, robot):
        study = self.write("far.toml", FAR.format(robot=robot))
        out = os.path.join(self.dir, "far.h5")
        r = run("run", study, "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        with h5py.File(out, "r") as f:
            g = f["runs"]
            status = runs_column(g["status"])
            dx, beta, err, E = g["task_dx"][()], g["task_rotation"][()], g["ik_error"][()], g["E"][()]
        self.assertEqual(len(status), 8)
        self.assertFalse(np.isnan(err).any(), err)  # measured for every run
        seen = set()
        for i in range(len(status)):
            want = reach_error(dx[i], beta[i], 3.0)
            self.assertAlmostEqual(err[i], want, delta=1e-9, msg=(dx[i], beta[i]))
            if want > 0:
                self.assertEqual(status[i], "out_of_reach", (dx[i], beta[i]))
                self.assertTrue(np.isnan(E[i]))
            else:
                self.assertNotEqual(status[i], "out_of_reach", (dx[i], beta[i]))
            seen.add(status[i])
        self.assertIn("out_of_reach", seen)
        self.assertIn("ok", seen)  # the square as written

    def test_seed_arm(self):
        self.check("")

    def test_planar_chain(self):
        self.check('[robot]\nl = [1.0, 1.0, 1.0]\nm = [5.0, 2.0, 1.0]\ndynamics = "recursive"\n')


class ResumeAfterPlacementAxis(TempDirTest):
    def keyed(self, path):
        """{(k, alpha1A): wall_time} of the runs at the identity placement."""
        with h5py.File(path, "r") as f:
            g = f["runs"]
            k, a, w = g["k"][()], g["alpha1A"][()], g["wall_time"][()]
            dx = g["task_dx"][()] if "task_dx" in g else np.zeros(len(w))
        return {(k[i], a[i]): w[i] for i in range(len(w)) if dx[i] == 0.0}

    def test_added_axis_keeps_the_runs_done(self):
        old = self.write("grow.toml", BASE)
        out = os.path.join(self.dir, "grow.h5")
        r = run("run", old, "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        before = self.keyed(out)
        self.assertEqual(len(before), 4)
        edited_text = BASE.replace("alpha1A = [0, 10]\n", "alpha1A = [0, 10]\ntask_dx = [0.0, 0.25, 9.0]\n")
        edited = self.write("grow_edited.toml", edited_text)
        r = run("run", edited, "-o", out, "-q", "--resume")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (8, 4))  # 12 runs: the 4 at task_dx = 0 reused
        after = self.keyed(out)
        self.assertEqual(after, before)  # wall_time copied bit for bit: not computed again
        # the oracle: a fresh run of the edited study, every /runs column but wall_time bit for bit
        fresh = os.path.join(self.dir, "fresh.h5")
        r = run("run", edited, "-o", fresh, "-q", "--overwrite")
        self.assertEqual(r.returncode, 0, r.stderr)
        a, b = runs_table(out), runs_table(fresh)
        self.assertEqual(sorted(a), sorted(b))
        for key in a:
            self.assertTrue(bitwise_equal(a[key], b[key]), key)
        self.assertIn("out_of_reach", list(a["status"]))  # task_dx = 9 leaves the 3 m reach
        self.assertTrue(same_tables(a, b))


class BadValues(TempDirTest):
    def located(self, text, line, needle):
        study = self.write("bad.toml", text)
        r = run("run", study, "-o", os.path.join(self.dir, "bad.h5"), "-q")
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        self.assertRegex(r.stderr, re.escape(study) + ":" + str(line) + r":\d+: error: ")
        self.assertIn(needle, r.stderr)

    def test_errors(self):
        head = '[[block]]\nname = "b"\nkind = "trajectory"\n'
        self.located(head + "task_dz = 0.1\n", 4, "out of the plane")
        self.located(head + "[block.axes]\ntask_time_scale = [1.0, 0.0]\n", 5, "expected task_time_scale within [0.01, 100]")
        self.located(head + "task_rotaton = 0.1\n", 4, "did you mean 'task_rotation'")
        self.located(head + "[[optimize]]\nname = \"o\"\nmethod = \"local_weighted\"\n"
                     "variables = { task_dz = [0.0, 0.1] }\n", 7, "out of the plane")


if __name__ == "__main__":
    KS = sys.argv.pop(1)
    unittest.main()
