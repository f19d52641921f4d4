"""The path-global method end to end: global_spline runs (the seed's 3R, a 4R chain and a 7-DOF arm)
give the same file, bit for bit, on 1 and 2 threads, on 2 MPI ranks, and after a SIGKILL and
`--resume`; every `ok` global run is on its path (tracking at rounding) and below the local runs of
its file; an [[optimize]] block takes global_spline's start angle as its variable, and its best point
run as a plain study gives its objective. (Studies run with --no-verify-best: the grid verification
of the best runs, which recomputes them at 2 and 4 times their resolution, is compare_e2e's.)

usage: /usr/bin/python3 test_path_global.py KINESWEEP_BINARY
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import unittest

import h5py
import numpy as np

from e2e_common import TempDirTest, bitwise_equal, runs_table, same_histories

KS = None
MPIRUN = ["mpirun", "--oversubscribe", "--allow-run-as-root", "--bind-to", "none", "-np", "2"]

# The seed's arm: local runs and global ones at several knot counts and starts (about 3 s).
SEED = """
[study]
name = "pg_seed"
histories = "every=50"

[[block]]
name = "local"
kind = "trajectory"
alpha1A = -23.75
[block.axes]
method = ["local_weighted", "local_unweighted"]
k = [0.0, 0.1]

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
global_start = "vertex"
alpha1A = -23.75
vertex_alpha = [13.30, 17.28, -12.44, -16.12]
[block.axes]
knots = [5, 10, 20]
end_state = ["rest", "free"]
"""

# Long enough (about 4 s on 2 threads) to be killed in the middle.
KILL = (SEED.replace('name = "pg_seed"', 'name = "pg_kill"').replace("knots = [5, 10, 20]", "knots = [5, 10, 20, 40, 80]")
        .replace("vertex_alpha = [13.30, 17.28, -12.44, -16.12]", "vertex_alpha = [13.30, 17.28, -12.44, -16.12]\ndt = 0.00025")
        .replace('end_state = ["rest", "free"]',
                 'end_state = ["rest", "free"]\nglobal_objective = ["E", "E_M", "torque_sq_integral", "kinetic_energy"]'))

# A 4R chain: its local runs and global ones (about 3 s).
CHAIN = """
[study]
name = "pg_chain"
histories = "none"

[robot]
l = [1.0, 1.0, 0.5, 0.5]
m = [5.0, 2.0, 0.5, 0.5]
b = 0.1

[[block]]
name = "local"
kind = "trajectory"
alpha1A = 4
[block.axes]
method = ["local_weighted", "local_unweighted"]

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
alpha1A = 4
[block.axes]
knots = [5, 10]
"""

# A 7-DOF arm (studies/robots/arm7.urdf) on the first side of arm7_square's square, sampled every
# 10 ms: its local run and global ones with joint coordinates and the URDF's limits (about 2 s).
ARM7 = """
[study]
name = "pg_arm7"
histories = "every=20"

[robot]
urdf = "{urdf}"
base = "base_link"
tip = "tool"
gravity = [0, 0, -9.81]

[task]
vertices = [[0.5, -0.1, 0.4], [0.5, 0.1, 0.4]]
durations = [2]
integrator = "rk4"
dt = 0.01

[[block]]
name = "local"
kind = "trajectory"
method = "local_weighted"
K_N = 20
K_L = 8
q0_3 = 60
q0_4 = -90

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
start_method = "local_weighted"
K_N = 20
K_L = 8
q0_3 = 60
q0_4 = -90
[block.axes]
knots = [4, 6]
""".format(urdf=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "studies", "robots", "arm7.urdf"))

# [[optimize]] over an outer parameter of global_spline: the start angle alpha1A of the seed's arm.
OPTIMIZE = """
[study]
name = "pg_optimize"
histories = "none"

[[optimize]]
name = "start_angle"
method = "global_spline"
global_start = "vertex"
vertex_alpha = [13.30, 17.28, -12.44, -16.12]
knots = 5
variables = { alpha1A = [-24, -12] }
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 8
"""


def run(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True, timeout=600)


class PathGlobal(TempDirTest):
    def run_study(self, text, name, *args):
        study = self.write(name + ".toml", text)
        out = os.path.join(self.dir, name + ".h5")
        r = run("run", study, "-o", out, "--overwrite", "-q", "--no-verify-best", *args)
        self.assertEqual(r.returncode, 0, r.stderr)
        return study, out

    def assert_same(self, a, b):
        ta, tb = runs_table(a), runs_table(b)
        self.assertEqual(sorted(ta), sorted(tb))
        for c in ta:
            self.assertTrue(bitwise_equal(np.asarray(ta[c]), np.asarray(tb[c])), c)
        with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
            if "histories" in fa:
                same_histories(self, fa, fb)

    def test_threads_and_ranks_give_the_same_file(self):
        for text, name in ((SEED, "seed"), (CHAIN, "chain"), (ARM7, "arm7")):
            _, one = self.run_study(text, name + "1", "--threads", "1")
            _, two = self.run_study(text, name + "2", "--threads", "2")
            self.assert_same(one, two)
            if shutil.which("mpirun"):
                study = self.write(name + "m.toml", text)
                out = os.path.join(self.dir, name + "m.h5")
                r = subprocess.run([*MPIRUN, KS, "run", study, "-o", out, "--overwrite", "-q", "--threads", "1", "--no-verify-best"],
                                   capture_output=True, text=True, timeout=600)
                self.assertEqual(r.returncode, 0, r.stderr)
                self.assert_same(one, out)

    def test_killed_and_resumed_gives_the_same_file(self):
        _, whole = self.run_study(KILL, "whole", "--threads", "2")
        study = self.write("killed.toml", KILL)
        out = os.path.join(self.dir, "killed.h5")
        p = subprocess.Popen([KS, "run", study, "-o", out, "-q", "--threads", "2", "--no-verify-best"], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
        deadline = time.time() + 60
        while time.time() < deadline and p.poll() is None:  # kill once some runs are committed, not all
            q = run("query", out, "--limit", "1")
            m = re.search(r"(\d+) of (\d+) runs done", q.stdout + q.stderr)
            if m and 0 < int(m.group(1)) < int(m.group(2)):
                break
            time.sleep(0.05)
        self.assertIsNone(p.poll(), "the study ended before it could be killed")
        p.send_signal(signal.SIGKILL)
        p.wait()
        r = run("run", study, "-o", out, "--resume", "--threads", "2", "--no-verify-best")
        self.assertEqual(r.returncode, 0, r.stderr)
        m = re.search(r"(\d+) runs \((\d+) computed now, (\d+) already in the file\)", r.stdout + r.stderr)
        self.assertIsNotNone(m, r.stdout + r.stderr)
        total, now = int(m.group(1)), int(m.group(2))
        self.assertTrue(0 < now < total, m.group(0))  # killed in the middle, resumed from what it kept
        self.assert_same(whole, out)

    def test_optimize_block_over_an_outer_parameter(self):
        _, out = self.run_study(OPTIMIZE, "optimize")
        with h5py.File(out, "r") as f:
            g = f["optimizations/start_angle"]
            obj = g["evaluations/objective"][()]
            status = [s.decode() if isinstance(s, bytes) else s for s in g["evaluations/status"][()]]
            best, best_x = float(g.attrs["best_objective"]), float(np.ravel(g.attrs["best_x"])[0])
        self.assertGreaterEqual(len(obj), 3)
        self.assertTrue(all(s == "ok" for s in status), status)
        self.assertEqual(best, obj.min())
        self.assertTrue(-24 * np.pi / 180 - 1e-12 <= best_x <= -12 * np.pi / 180 + 1e-12, best_x)
        # the best point, run as a plain study, gives the optimiser's objective (E)
        plain = OPTIMIZE.split("[[optimize]]")[0] + (
            '[[block]]\nname = "best"\nkind = "trajectory"\nmethod = "global_spline"\nglobal_start = "vertex"\n'
            "vertex_alpha = [13.30, 17.28, -12.44, -16.12]\nknots = 5\nalpha1A = %.17g\n" % np.degrees(best_x))
        _, again = self.run_study(plain, "plain")
        E = float(np.asarray(runs_table(again)["E"], float)[0])
        # (alpha1A written in degrees is a rounding away from the optimiser's radians, and SLSQP's path
        # from it ends within its own tolerance of the same optimum)
        self.assertAlmostEqual(E / best, 1.0, delta=1e-6)

    def test_global_runs_are_on_their_path_and_below_the_local_runs(self):
        for text, name in ((SEED, "seed"), (CHAIN, "chain"), (ARM7, "arm7")):
            _, out = self.run_study(text, name)
            t = runs_table(out)
            block, status = np.asarray(t["block"]), np.asarray(t["status"])
            E, track = np.asarray(t["E"], float), np.asarray(t["max_tracking_error"], float)
            # every global run ends ok (the arm7's under its limits: the penalty continuation)
            glob = block == "global"
            self.assertTrue((status[glob] == "ok").all(), (name, status[glob]))
            self.assertGreater(glob.sum(), 0, name)
            if name == "arm7":
                for c in ("max_q_limit_ratio", "max_qd_limit_ratio", "max_tau_limit_ratio"):
                    self.assertLessEqual(np.asarray(t[c], float)[glob].max(), 1.0, c)
            self.assertLess(track[glob].max(), 1e-9, name)
            local_ok = (block == "local") & (status == "ok")
            # the finest global run of the file beats every local run from the same start angle
            knots = np.asarray(t["knots"])
            finest = glob & (knots == knots[glob].max())
            self.assertLess(E[finest].min(), E[local_ok].min(), name)


if __name__ == "__main__":
    KS = sys.argv.pop(1)
    unittest.main()
