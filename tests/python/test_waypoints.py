"""End-to-end tests of [task] waypoints (a cubic spline through timed waypoints) through `kinesweep run`
and h5py:
- the stored tip path, velocity and acceleration of global_spline runs (the tip on the path at every
  sample) against scipy.interpolate.CubicSpline with bc_type "natural" and "clamped", the oracle: the
  tip position from the history's x, its velocity J(q) qd and acceleration J(q) qdd + dJ/dt qd
  computed here from the stored joint histories of the seed's 3R (links 1 m);
- the seed's closed-form 3R and the same arm as a planar chain follow the same spline;
- seed 002 section 7.3's first SCARA path (a DH robot) runs with status ok and finite
  min_manipulability and power_sq_integral under the local methods.

usage: /usr/bin/python3 test_waypoints.py KINESWEEP_BINARY STUDIES_DIR
"""
import os
import subprocess
import sys
import unittest

import h5py
import numpy as np
from scipy.interpolate import CubicSpline

from e2e_common import TempDirTest, runs_table

KS = None
STUDIES = None

# Uneven times from t0 = 0.5 s, uneven points: no quintic or symmetric shape in disguise
WAYPOINTS = [(0.5, 1.5, 1.5), (0.75, 1.5, 2.0), (1.5, 2.0, 2.0), (2.0, 2.0, 1.5), (2.5, 1.6, 1.45)]

SPLINE = """[study]
name = "spline"
histories = "full"
{robot}
[task]
waypoints = {waypoints}
{spline}
dt = 0.001
[[block]]
name = "b"
kind = "trajectory"
method = "{method}"
"""

SCARA = """[study]
name = "scara_waypoints"
histories = "none"
[robot]
dh = "{robots}/scara.toml"
[task]                      # seed 002 section 7.3, the first path: (t [s], x, y, z [m])
waypoints = [[0, 0.4, 0, -0.3], [1, 0.4, -0.1, -0.3], [2, 0.2, -0.1, -0.3], [3, 0.2, -0.2, -0.3],
             [4, 0.4, -0.25, -0.3], [5, 0.4, -0.2, -0.3], [6, 0.2, -0.25, -0.3]]
[[block]]
name = "local"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
"""


def tip_kinematics(q, qd, qdd):
    """Tip position, velocity and acceleration (n x 2 each) of a planar 3R with 1 m links from joint
    angles q, rates qd, accelerations qdd (n x 3): cumulative angles phi_i = q_1 + .. + q_i."""
    phi, phid, phidd = np.cumsum(q, axis=1), np.cumsum(qd, axis=1), np.cumsum(qdd, axis=1)
    c, s = np.cos(phi), np.sin(phi)
    p = np.stack([c.sum(1), s.sum(1)], axis=1)
    v = np.stack([(-s * phid).sum(1), (c * phid).sum(1)], axis=1)
    a = np.stack([(-c * phid**2 - s * phidd).sum(1), (-s * phid**2 + c * phidd).sum(1)], axis=1)
    return p, v, a


def history(path, run, name):
    with h5py.File(path, "r") as f:
        h = f["histories"]
        start, rows = int(h["start"][run]), int(h["rows"][run])
        return np.asarray(h[name][start:start + rows])


class SplineAgainstScipy(TempDirTest):
    def run_study(self, robot, spline, method="global_spline"):
        text = SPLINE.format(robot=robot, waypoints=[list(w) for w in WAYPOINTS], spline=spline, method=method)
        study = os.path.join(self.dir, "spline.toml")
        with open(study, "w") as f:
            f.write(text)
        out = os.path.join(self.dir, "spline.h5")
        if os.path.exists(out):
            os.remove(out)
        r = subprocess.run([KS, "run", study, "-o", out], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        return out

    def oracle(self, bc):
        w = np.array(WAYPOINTS)
        return CubicSpline(w[:, 0] - w[0, 0], w[:, 1:], bc_type=bc)

    def check_tip(self, out, bc, tol=(1e-12, 1e-10, 1e-9)):
        self.assertEqual(runs_table(out)["status"][0], "ok")
        t, q, qd, qdd = (history(out, 0, n) for n in ("t", "q", "qd", "qdd"))
        x = history(out, 0, "x")
        self.assertEqual(len(t), 2001)  # t = 0 .. 2 s by 1 ms
        spline = self.oracle(bc)
        p, v, a = tip_kinematics(q, qd, qdd)
        np.testing.assert_allclose(x, spline(t[:, 0]), rtol=0, atol=tol[0])
        np.testing.assert_allclose(p, spline(t[:, 0]), rtol=0, atol=tol[0])
        np.testing.assert_allclose(v, spline(t[:, 0], 1), rtol=0, atol=tol[1])
        np.testing.assert_allclose(a, spline(t[:, 0], 2), rtol=0, atol=tol[2])
        return spline

    def test_natural_and_clamped_follow_scipy(self):
        for bc, key in (("natural", 'spline = "natural"'), ("clamped", 'spline = "clamped"'), ("clamped", "")):
            with self.subTest(spline=key or "default"):
                out = self.run_study("", key)
                spline = self.check_tip(out, bc)
                # the other end condition is another path: the comparison tells them apart
                other = self.oracle("clamped" if bc == "natural" else "natural")
                t = history(out, 0, "t")[:, 0]
                self.assertGreater(np.abs(other(t) - spline(t)).max(), 1e-2)

    def test_planar_chain_follows_the_same_spline(self):
        chain = "[robot]\nl = [1.0, 1.0, 1.0]\nm = [5.0, 2.0, 1.0]\ndynamics = \"recursive\"\n"
        # (clamped: the local run that starts global_spline begins at rest, as the clamped path does)
        out = self.run_study(chain, 'spline = "clamped"')
        self.check_tip(out, "clamped")

    def test_closed_form_local_run_tracks_the_clamped_spline(self):
        # an open-loop local run (RK4) starts at rest with the clamped path and follows it closely
        out = self.run_study("", 'spline = "clamped"\nintegrator = "rk4"', method="local_weighted")
        self.assertEqual(runs_table(out)["status"][0], "ok")
        t, x = history(out, 0, "t")[:, 0], history(out, 0, "x")
        np.testing.assert_allclose(x, self.oracle("clamped")(t), rtol=0, atol=1e-4)


class ScaraSeed002Path(TempDirTest):
    def test_local_methods_run_ok(self):
        study = os.path.join(self.dir, "scara_waypoints.toml")
        with open(study, "w") as f:
            f.write(SCARA.format(robots=os.path.join(STUDIES, "robots")))
        out = os.path.join(self.dir, "scara.h5")
        r = subprocess.run([KS, "run", study, "-o", out], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertEqual(list(runs_table(out)["status"]), ["ok", "ok"])
        for name in ("min_manipulability", "power_sq_integral"):
            values = np.asarray(runs_table(out)[name], dtype=float)
            self.assertTrue(np.all(np.isfinite(values)), (name, values))
        self.assertTrue(np.all(np.asarray(runs_table(out)["samples"]) == 6001))


if __name__ == "__main__":
    KS, STUDIES = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    del sys.argv[1:3]
    unittest.main()
