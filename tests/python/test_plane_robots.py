"""End-to-end tests of planar robots in any plane of their base frame and of `kinesweep robot`.

- Seed 000's case 1a through `kinesweep run` on the seed arm written as a URDF in the base xz plane
  (tests/data/seed3r_xz.urdf: axes -y, gravity -z; vertices in base or in plane coordinates) and in
  the base xy plane (studies/robots/seed3r.urdf, gravity -y): E and every |tau_i|_inf equal the
  built-in closed-form arm's to 1e-9 relative, and the seed's Table 4 to its printed digits (1 %).
- `kinesweep robot --format json` on that URDF against values derived by hand: joint axes and
  positions, masses, centres of mass, inertias of uniform bars I = m (l^2 + b^2) / 12 about the
  normal and m b^2 / 6 along the bar, total mass, the plane (normal +-y), redundancy; the table
  format; errors located with exit status 2.

usage: /usr/bin/python3 test_plane_robots.py KINESWEEP_BINARY REPO_DIR
"""
import json
import os
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import TempDirTest, runs_column

KS = None
REPO = None

CASE_1A = """
[study]
name = "plane_1a"
histories = "none"
{robot}
{task}
[[block]]
name = "b"
kind = "trajectory"
preset = "1a"
"""
# seed 000, Table 4, case 1a: E, |tau_1|_inf, |tau_2|_inf, |tau_3|_inf [Nm]
TABLE4_1A = (51.03, 82.63, 32.31, 8.77)
SQUARE_XZ = ("[task]\nvertices = [[1.5, 0, 1.5], [1.5, 0, 2.0], [2.0, 0, 2.0], [2.0, 0, 1.5], [1.5, 0, 1.5]]\n"
             "durations = [0.5, 0.5, 0.5, 0.5]")
L, B, M = 1.0, 0.1, (5.0, 2.0, 1.0)  # the seed arm (NOTES.md, Table 2): links, bar thickness, masses


def run(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True)


def urdf_robot(path, gravity):
    return f'[robot]\nurdf = "{path}"\nbase = "base_link"\ntip = "tool"\ngravity = {gravity}'


class Case1aInAnyPlane(TempDirTest):
    def metrics(self, name, robot, task=""):
        study = self.write(name + ".toml", CASE_1A.format(robot=robot, task=task))
        out = os.path.join(self.dir, name + ".h5")
        r = run("run", study, "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        with h5py.File(out, "r") as f:
            runs = f["runs"]
            self.assertEqual(runs_column(runs["status"])[0], "ok")
            return np.array([runs[c][0] for c in ("E", "tau1_inf", "tau2_inf", "tau3_inf")])

    def test_xz_and_xy_urdf_equal_the_closed_form(self):
        closed = self.metrics("closed", "")
        # the seed's printed E (physical inertia: |tau_2|_inf differs from the print by ~6 %)
        self.assertAlmostEqual(closed[0] / TABLE4_1A[0], 1.0, delta=1e-2)
        xz = os.path.join(REPO, "tests", "data", "seed3r_xz.urdf")
        xy = os.path.join(REPO, "studies", "robots", "seed3r.urdf")
        cases = {
            "xz_base_vertices": (urdf_robot(xz, "[0, 0, -9.81]"), SQUARE_XZ),
            "xz_default_path": (urdf_robot(xz, "[0, 0, -9.81]"), ""),
            "xz_gravity_defaulted": (f'[robot]\nurdf = "{xz}"\nbase = "base_link"\ntip = "tool"', ""),
            "xy": (urdf_robot(xy, "[0, -9.81, 0]"), ""),
        }
        for name, (robot, task) in cases.items():
            with self.subTest(name):
                got = self.metrics(name, robot, task)
                np.testing.assert_allclose(got, closed, rtol=1e-9, atol=0)

    def test_horizontal_arm_runs_and_needs_gravity_given(self):
        xy = os.path.join(REPO, "studies", "robots", "seed3r.urdf")
        study = self.write("h.toml", CASE_1A.format(robot=f'[robot]\nurdf = "{xy}"\nbase = "base_link"\ntip = "tool"',
                                                    task=""))
        r = run("run", study, "-o", os.path.join(self.dir, "h.h5"), "-q")
        self.assertEqual(r.returncode, 2)
        self.assertIn(f"{study}:6:8: error:", r.stderr)
        self.assertIn("not vertical", r.stderr)
        # with gravity normal to the plane: no gravity torque, so less effort than the vertical arm
        horizontal = self.metrics("horizontal", urdf_robot(xy, "[0, 0, -9.81]"))
        vertical = self.metrics("vertical", urdf_robot(xy, "[0, -9.81, 0]"))
        self.assertTrue(np.all(np.isfinite(horizontal)))
        self.assertLess(horizontal[0], vertical[0])


def q(x):
    """The value of a {"value": ..., "unit": ...} quantity."""
    return x["value"]


class RobotCommand(TempDirTest):
    XZ = None

    def setUp(self):
        super().setUp()
        self.XZ = os.path.join(REPO, "tests", "data", "seed3r_xz.urdf")

    def robot_json(self, *args):
        r = run("robot", *args, "--format", "json")
        self.assertEqual(r.returncode, 0, r.stderr)
        return json.loads(r.stdout)

    def check_seed_xz(self, d):
        self.assertEqual(len(d["joints"]), 3)
        for i, j in enumerate(d["joints"]):
            self.assertEqual(j["type"], "revolute")
            np.testing.assert_allclose(q(j["axis"]), [0, -1, 0], atol=1e-15)
            np.testing.assert_allclose(q(j["position"]), [i * L, 0, 0], atol=1e-15)
            self.assertEqual(j["position"]["unit"], "m")
            self.assertIsNone(q(j["lower"]))  # continuous: no limits
            self.assertEqual(j["lower"]["unit"], "rad")
            self.assertEqual(j["effort"]["unit"], "Nm")
            self.assertEqual(q(j["mass"]), M[i])
            self.assertEqual(j["mass"]["unit"], "kg")
            np.testing.assert_allclose(q(j["com"]), [i * L + L / 2, 0, 0], atol=1e-15)
            # a uniform bar along x: m b^2 / 6 about its length, m (l^2 + b^2) / 12 about y and z
            along, across = M[i] * B * B / 6, M[i] * (L * L + B * B) / 12
            np.testing.assert_allclose(q(j["inertia"]), np.diag([along, across, across]), rtol=1e-14, atol=1e-17)
            self.assertEqual(j["inertia"]["unit"], "kg m^2")
        self.assertAlmostEqual(q(d["total_mass"]), sum(M), places=14)
        np.testing.assert_allclose(q(d["tip"]), [3 * L, 0, 0], atol=1e-15)
        self.assertEqual(d["motion"], "planar")
        p = d["plane"]
        n = np.array(q(p["normal"]))
        self.assertAlmostEqual(abs(n[1]), 1.0, places=15)  # the normal is +-y
        self.assertAlmostEqual(abs(n[0]) + abs(n[2]), 0.0, places=15)
        e1, e2 = np.array(q(p["e1"])), np.array(q(p["e2"]))
        self.assertAlmostEqual(float(e1 @ n), 0.0, places=15)
        self.assertAlmostEqual(float(e2 @ n), 0.0, places=15)
        self.assertAlmostEqual(float(e1 @ e2), 0.0, places=15)
        np.testing.assert_allclose(q(p["origin"]), [0, 0, 0], atol=1e-15)

    def test_urdf_file_in_the_xz_plane(self):
        d = self.robot_json(self.XZ, "--base", "base_link", "--tip", "tool", "--gravity", "0,0,-9.81")
        self.check_seed_xz(d)
        self.assertEqual(q(d["gravity"]), [0, 0, -9.81])
        self.assertEqual(d["gravity"]["unit"], "m/s^2")
        self.assertFalse(d["gravity_default"])
        self.assertAlmostEqual(np.linalg.norm(q(d["plane"]["gravity_in_plane"])), 9.81, places=14)
        self.assertAlmostEqual(q(d["plane"]["gravity_normal"]), 0.0, places=15)
        self.assertEqual(d["task"], {"space": "planar_position", "rows": 2, "joints": 3, "redundancy": 1})
        # gravity along y, normal to the plane: all of it along the normal
        d = self.robot_json(self.XZ, "--base", "base_link", "--tip", "tool", "--gravity", "0,9.81,0")
        self.assertAlmostEqual(abs(q(d["plane"]["gravity_normal"])), 9.81, places=14)
        self.assertEqual(np.abs(q(d["plane"]["gravity_in_plane"])).max(), 0.0)

    def test_study_with_the_xz_urdf_and_a_pose_task(self):
        study = self.write("s.toml", urdf_robot(self.XZ, "[0, 0, -9.81]") +
                           "\n[task]\norientation = [0, 10, 20, 10, 0]\n[[block]]\nname = \"b\"\nkind = \"ik\"\n"
                           "problem = \"position\"\n")
        d = self.robot_json(study)
        self.check_seed_xz(d)
        # a planar pose task: x, y and the tip angle, 3 rows for 3 joints
        self.assertEqual(d["task"], {"space": "planar_pose", "rows": 3, "joints": 3, "redundancy": 0})
        self.assertIn(self.XZ, d["from"])

    def test_seed_closed_form_and_planar_arm_studies(self):
        d = self.robot_json(self.write("seed.toml", '[study]\nname = "x"\n[[block]]\nname = "b"\nkind = "trajectory"\n'))
        self.assertEqual(d["dynamics"], "closed_form")
        self.assertEqual([q(j["mass"]) for j in d["joints"]], list(M))
        np.testing.assert_allclose(q(d["plane"]["normal"]), [0, 0, 1])
        np.testing.assert_allclose(q(d["gravity"]), [0, -9.81, 0])
        d = self.robot_json(self.write("arm4.toml", "[robot]\nl = [1.0, 1.0, 0.5, 0.5]\nm = [5.0, 2.0, 0.5, 0.5]\nb = 0.1\n"
                                                "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n"))
        self.assertEqual(d["dynamics"], "recursive")
        self.assertEqual(d["task"]["redundancy"], 2)
        np.testing.assert_allclose(q(d["joints"][2]["inertia"])[2][2], 0.5 * (0.25 + 0.01) / 12, rtol=1e-14)

    def test_table_format_names_units(self):
        r = run("robot", self.XZ, "--base", "base_link", "--tip", "tool")
        self.assertEqual(r.returncode, 0, r.stderr)
        for text in ("joint1", "[kg]", "[kg m^2]", "total mass  8 kg", "m/s^2", "normal (0, -1, 0)", "redundancy 1",
                     "URDF's z up"):
            self.assertIn(text, r.stdout)

    def test_errors_exit_2_with_a_location(self):
        bad = self.write("bad.toml", '[robot]\nl = [1, 1]\nm = [1]\n')
        r = run("robot", bad)
        self.assertEqual(r.returncode, 2)
        self.assertIn(f"{bad}:3:", r.stderr)
        r = run("robot", self.XZ, "--base", "base_link", "--tip", "tol")
        self.assertEqual(r.returncode, 2)
        self.assertIn("did you mean 'tool'", r.stderr)
        self.assertIn(self.XZ, r.stderr)
        broken = self.write("broken.urdf", "<robot name='x'>\n<link name='a'>\n")
        r = run("robot", broken, "--base", "a", "--tip", "a")
        self.assertEqual(r.returncode, 2)
        self.assertIn(f"{broken}:", r.stderr)
        r = run("robot", self.XZ)
        self.assertEqual(r.returncode, 2)
        self.assertIn("--base", r.stderr)
        r = run("robot", self.XZ, "--base", "base_link", "--tip", "tool", "--gravity", "0,0")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--gravity", r.stderr)


if __name__ == "__main__":
    KS, REPO = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=sys.argv[:1])
