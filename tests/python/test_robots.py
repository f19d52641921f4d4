"""End-to-end tests of chain robots: Table 4 through the seed arm's URDF (generic RNEA/CRBA path)
against the closed form, bad robots rejected with a location and nothing written, the shipped
robot studies run and read back with h5py (per-joint columns, histories of width n).

usage: /usr/bin/python3 test_robots.py KINESWEEP_BINARY STUDIES_DIR
"""
import json
import os
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import ANALYSIS_ENV, Histories, TempDirTest, analysis_command, history, runs_column, runs_columns

KS = None
STUDIES = None
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

TABLE4 = """
[study]
name = "t4"
histories = "every=50"
{robot}
[[block]]
name = "table4"
kind = "trajectory"
[block.axes]
preset = ["1a", "1b", "1c", "1d", "1e", "1f", "1g", "1h", "2a", "2b", "2c", "2d", "2e", "2f", "2g", "2h",
          "3", "4", "5a", "5b", "5c"]
"""


def run(*args, **kw):
    return subprocess.run([KS, *args], capture_output=True, text=True, **kw)


def urdf_limits(path):
    """lower, upper, velocity of the URDF's revolute joints in file order (the arm's chain order)."""
    import xml.etree.ElementTree as ET
    joints = [j for j in ET.parse(path).getroot().iter("joint") if j.get("type") == "revolute"]
    lim = [j.find("limit") for j in joints]
    return tuple(np.array([float(l.get(k)) for l in lim]) for k in ("lower", "upper", "velocity"))


def read_runs(path):
    with h5py.File(path, "r") as f:
        return runs_columns(f, skip=("wall_time",))


class Table4ThroughUrdf(TempDirTest):
    def test_generic_path_agrees_with_the_closed_form(self):
        closed = self.write("closed.toml", TABLE4.format(robot=""))
        urdf = os.path.join(STUDIES, "robots", "seed3r.urdf")
        generic = self.write("generic.toml", TABLE4.format(
            robot=f'[robot]\nurdf = "{urdf}"\nbase = "base_link"\ntip = "tool"\ngravity = [0, -9.81, 0]\n'))
        a, b = os.path.join(self.dir, "a.h5"), os.path.join(self.dir, "b.h5")
        for study, out in ((closed, a), (generic, b)):
            r = run("run", study, "-o", out, "--quiet")
            self.assertEqual(r.returncode, 0, r.stderr)
        ra, rb = read_runs(a), read_runs(b)
        self.assertEqual(list(ra["status"]), list(rb["status"]))
        compared = 0
        for name, col in ra.items():
            if name not in rb or col.dtype.kind != "f":
                continue
            x, y = col, rb[name]
            both = np.isfinite(x) & np.isfinite(y)
            self.assertTrue(np.array_equal(np.isfinite(x), np.isfinite(y)), name)
            scale = np.maximum(np.abs(x[both]), 1e-300)
            rel = np.abs(x[both] - y[both]) / scale
            self.assertLess(rel.max(initial=0.0), 1e-9, f"{name}: max relative difference {rel.max():.3g}")
            compared += 1
        self.assertGreaterEqual(compared, 10)
        # the chain's columns: q0_1..3 (the start guess) and the same metric columns as the closed form
        for c in ("E", "E_M", "tau1_inf", "tau2_inf", "tau3_inf", "max_tracking_error"):
            self.assertIn(c, rb)
        with h5py.File(b, "r") as f:
            self.assertEqual(f["study/robot"].attrs["path"].decode() if isinstance(f["study/robot"].attrs["path"], bytes)
                             else f["study/robot"].attrs["path"], urdf)


class BadRobots(TempDirTest):
    def test_each_bad_robot_is_rejected_with_location_and_no_file(self):
        self.write("broken.urdf", "<robot name='x'><link name='a'>")
        cases = {
            "missing_urdf": ('[robot]\nurdf = "nope.urdf"\nbase = "a"\ntip = "b"\n', 2),
            "broken_urdf": ('[robot]\nurdf = "broken.urdf"\nbase = "a"\ntip = "b"\n', 2),
            "unknown_tip": (f'[robot]\nurdf = "{STUDIES}/robots/arm7.urdf"\nbase = "base_link"\ntip = "tool0"\n', 4),
            "out_of_reach": ('[robot]\nl = [0.3, 0.3, 0.3, 0.3]\nm = [1, 1, 1, 1]\n', None),
            "too_few_joints": ('[robot]\nl = [2, 2]\nm = [1, 1]\n', 4),
        }
        for name, (robot, line) in cases.items():
            with self.subTest(name):
                study = self.write(name + ".toml", robot + '[[block]]\nname = "b"\nkind = "trajectory"\n')
                out = os.path.join(self.dir, name + ".h5")
                r = run("run", study, "-o", out)
                self.assertEqual(r.returncode, 2, r.stderr)
                if line is not None:
                    self.assertIn(f"{study}:{line}:", r.stderr)
                self.assertIn("expected", r.stderr)
                self.assertFalse(os.path.exists(out))


class ChainStudies(TempDirTest):
    def test_arm7_square_runs_with_seven_joint_histories(self):
        study = os.path.join(STUDIES, "arm7_square.toml")
        out = os.path.join(self.dir, "arm7.h5")
        r = run("run", study, "-o", out, "--quiet")
        self.assertEqual(r.returncode, 0, r.stderr)
        with h5py.File(out, "r") as f:
            runs = f["runs"]
            self.assertIn("q0_7", runs)
            self.assertIn("tau7_inf", runs)
            status, method = runs_column(runs["status"]), runs_column(runs["method"])
            # Some runs keep within every limit of the URDF (local_weighted with the limit spring at
            # small k), the others leave one and say by how much; the tip follows the 3-D path (RK4).
            self.assertEqual(set(status), {"ok", "out_of_limits"})
            worst = np.maximum.reduce([runs[c][()] for c in ("max_q_limit_ratio", "max_qd_limit_ratio",
                                                            "max_tau_limit_ratio")])
            self.assertTrue(np.all(worst[status == "out_of_limits"] > 1.0))
            self.assertTrue(np.all(worst[status == "ok"] <= 1.0))
            self.assertGreaterEqual(int(np.sum(status == "ok")), 5)
            weighted = method == "local_weighted"
            self.assertGreater(int(weighted.sum()), 20)
            self.assertLess(np.max(runs["max_tracking_error"][()][weighted]), 1e-3)
            # independent of the engine's ratios: the URDF's limits read here, every stored sample of
            # every ok run (and the start of every run) within them
            lower, upper, velocity = urdf_limits(os.path.join(STUDIES, "robots", "arm7.urdf"))
            hist = Histories(f)
            for i in hist.ids():
                h = history(f, i)
                q, qd = h["q"], h["qd"]
                self.assertTrue(np.all((q[0] >= lower) & (q[0] <= upper)), f"run {i} starts outside its limits")
                if status[i] == "ok":
                    self.assertTrue(np.all((q >= lower) & (q <= upper)), f"run {i}")
                    self.assertTrue(np.all(np.abs(qd) <= velocity), f"run {i}")
            h = history(f, Histories(f).ids()[0])
            self.assertEqual(h["q"].shape[1], 7)
            self.assertEqual(h["x"].shape[1], 3)

    def test_arm7_ik_basins_run(self):
        study = os.path.join(STUDIES, "arm7_ik_basins.toml")
        out = os.path.join(self.dir, "basins.h5")
        r = run("run", study, "-o", out, "--quiet")
        self.assertEqual(r.returncode, 0, r.stderr)
        with h5py.File(out, "r") as f:
            runs = f["runs"]
            status = runs_column(runs["status"]).tolist()
            self.assertGreater(status.count("converged"), len(status) // 4)
            self.assertIn("q_final_7", runs)
        # the basins plot names the solutions by clustering (no closed form for a 7-DOF arm); a pose
        # target leaves redundancy 1, a continuum, named by the joints that stay discrete (the elbow)
        png = os.path.join(self.dir, "basins.png")
        r = subprocess.run(analysis_command("plot_basins", out, "--x", "q0_2", "--y", "q0_4", "-o", png,
                                            "--print-data"), capture_output=True, text=True, env=ANALYSIS_ENV)
        self.assertEqual(r.returncode, 0, r.stderr)
        data = json.loads(r.stdout)
        self.assertTrue(data["clustered"])
        self.assertEqual(data["continuum"]["discrete"], ["q_final_4"])
        self.assertEqual(len(data["solutions"]), 2)
        self.assertGreater(os.path.getsize(png), 10000)


class ClusterSolutions(unittest.TestCase):
    def test_every_member_is_near_its_clusters_first_and_firsts_are_apart(self):
        sys.path.insert(0, os.path.join(REPO, "analysis"))
        from kinesweep import read as ksread
        rng = np.random.default_rng(7)
        centres = rng.uniform(-np.pi, np.pi, size=(5, 3))
        q = centres[rng.integers(0, 5, 400)] + rng.uniform(-4e-4, 4e-4, size=(400, 3))
        q[::7] += 2 * np.pi  # the same solution one turn away
        q[3, 1] = np.nan
        labels = ksread.cluster_solutions(q, [True, True, True], 1e-3)
        self.assertEqual(labels[3], -1)
        firsts = {}
        for i, l in enumerate(labels):
            if l < 0:
                continue
            f = firsts.setdefault(l, i)
            d = np.remainder(q[i] - q[f] + np.pi, 2 * np.pi) - np.pi
            self.assertLessEqual(np.max(np.abs(d)), 1e-3)
        self.assertEqual(sorted(firsts), list(range(len(firsts))))  # labels in order of first members
        self.assertEqual(sorted(firsts.values()), [firsts[l] for l in range(len(firsts))])
        self.assertEqual(len(firsts), 5)  # 5 well separated centres, one turn counted as the same

    def test_the_row_by_row_rule_on_overlapping_clusters(self):
        """Rows near two clusters' first members (the tolerance of the order of the spread): each row
        takes the lowest-labelled cluster whose first member is within tolerance among those opened
        before it, else opens one (the rule written row by row here as the oracle)."""
        sys.path.insert(0, os.path.join(REPO, "analysis"))
        from kinesweep import read as ksread

        def row_by_row(q, rev, tol):
            labels, firsts = np.full(len(q), -1), []
            for i, row in enumerate(q):
                if not np.all(np.isfinite(row)):
                    continue
                for c, f in enumerate(firsts):
                    d = row - f
                    d[rev] = np.remainder(d[rev] + np.pi, 2 * np.pi) - np.pi
                    if np.max(np.abs(d)) <= tol:
                        labels[i] = c
                        break
                else:
                    labels[i] = len(firsts)
                    firsts.append(row)
            return labels

        rng = np.random.default_rng(11)
        for trial in range(20):
            n, k = int(rng.integers(1, 600)), int(rng.integers(1, 4))
            centres = rng.uniform(-4, 4, size=(int(rng.integers(1, 8)), k))
            q = centres[rng.integers(0, len(centres), n)] + rng.normal(0, rng.choice([1e-4, 1e-3, 3e-2]), size=(n, k))
            q[rng.random(n) < 0.05, 0] = np.nan
            rev = rng.random(k) < 0.6
            tol = float(rng.choice([1e-3, 1e-2, 0.1]))
            np.testing.assert_array_equal(ksread.cluster_solutions(q, rev, tol), row_by_row(q, rev, tol), str(trial))


if __name__ == "__main__":
    KS, STUDIES = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=sys.argv[:1])
