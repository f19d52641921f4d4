"""End-to-end refusals and readings of robot input the parsers must not trust: a URDF nested 40,000
elements deep (`run` and `robot` exit 2 at the first element too deep, FILE:LINE:COL, instead of
overflowing the XML parser's stack), <limit>s with lower > upper or lower = upper (exit 2 at the
<limit>), a <limit> without lower and upper read as no position limit by `robot` (JSON null, table
inf) and by a trajectory run (max_q_limit_ratio NaN), and task vertices inside a planar arm's inner
unreachable disc (exit 2 at the vertex, like a vertex beyond the outer reach). Each refusal leaves no
results file.

usage: /usr/bin/python3 test_robot_robustness.py KINESWEEP_BINARY SOURCE_DIR
"""
import json
import math
import os
import subprocess
import sys
import unittest

import h5py

from e2e_common import TempDirTest

KS = None
SOURCE = None
BLOCK = '[[block]]\nname = "b"\nkind = "trajectory"\n'
DEEP_LEVELS = 40000
MAX_DEPTH = 256  # robot/urdf_check.hpp: kMaxElementDepth


def arm_urdf(limit1, inside="", lengths=(0.5, 0.5, 0.3)):
    """A planar 3R about z (links `lengths` [m] of 1 kg, the tip link "tool" fixed at the last one's
    end), joint j1's <limit> `limit1`, the others -2..2 rad, `inside` put in link l2."""
    s = '<robot name="arm">\n  <link name="base"/>\n'
    for i in (1, 2, 3):
        limit = limit1 if i == 1 else DEFAULT_LIMIT
        s += (f'  <joint name="j{i}" type="revolute">\n    <parent link="{"base" if i == 1 else f"l{i - 1}"}"/>\n'
              f'    <child link="l{i}"/>\n    <origin xyz="{0.0 if i == 1 else lengths[i - 2]} 0 0"/>\n'
              f'    <axis xyz="0 0 1"/>\n    {limit}\n  </joint>\n')
        s += ('  <link name="l%d">\n    <inertial><origin xyz="%g 0 0"/><mass value="1"/>'
              '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial>\n%s  </link>\n'
              % (i, lengths[i - 1] / 2, inside if i == 2 else ""))
    s += (f'  <joint name="t" type="fixed"><parent link="l3"/><child link="tool"/>'
          f'<origin xyz="{lengths[2]} 0 0"/></joint>\n  <link name="tool"/>\n')
    return s + "</robot>\n"


DEFAULT_LIMIT = '<limit lower="-2" upper="2" effort="100" velocity="10"/>'
LIMITED = '<limit lower="-1" upper="1.5" effort="100" velocity="10"/>'


def run(*args, timeout=120):
    return subprocess.run([KS, *args], capture_output=True, text=True, timeout=timeout)


class DeepUrdf(TempDirTest):
    def test_forty_thousand_levels_exit_2_located(self):
        inside = "  <x>\n" * DEEP_LEVELS + "</x>" * DEEP_LEVELS + "\n"
        urdf = self.write("deep.urdf", arm_urdf(LIMITED, inside))
        with open(urdf) as f:
            first_x = f.read().split("\n").index("  <x>") + 1
        # robot > link > x: the x at depth MAX_DEPTH + 1 is the (MAX_DEPTH - 1)th, column 3
        where = f"{urdf}:{first_x + MAX_DEPTH - 2}:3:"
        study = self.write("deep.toml", f'[robot]\nurdf = "{urdf}"\nbase = "base"\ntip = "tool"\n'
                                        'gravity = [0, -9.81, 0]\n' + BLOCK)
        out = os.path.join(self.dir, "deep.h5")
        # a generous limit: a hang check (the parse it replaces overflowed the stack), not a speed claim
        for args in (["run", study, "-o", out], ["robot", urdf, "--base", "base", "--tip", "tool"]):
            with self.subTest(args[0]):
                r = run(*args, timeout=60)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn(where, r.stderr)
                self.assertIn(f"nested {MAX_DEPTH + 1} elements deep", r.stderr)
                self.assertIn("expected at most", r.stderr)
        self.assertFalse(os.path.exists(out))


class Limits(TempDirTest):
    def test_lower_not_below_upper_is_refused_at_the_limit(self):
        for name, limit, words in (
                ("above", '<limit lower="1" upper="-1" effort="100" velocity="10"/>', "lower > upper"),
                ("equal", '<limit lower="0" upper="0" effort="100" velocity="10"/>', "lower = upper")):
            with self.subTest(name):
                text = arm_urdf(limit)
                urdf = self.write(name + ".urdf", text)
                line = text[:text.index(limit)].count("\n") + 1
                r = run("robot", urdf, "--base", "base", "--tip", "tool")
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn(f"{urdf}:{line}:5: joint 'j1'", r.stderr)
                self.assertIn(words, r.stderr)

    def test_limit_without_lower_and_upper_is_no_position_limit(self):
        urdf = self.write("open.urdf", arm_urdf('<limit effort="100" velocity="10"/>'))
        r = run("robot", urdf, "--base", "base", "--tip", "tool", "--format", "json")
        self.assertEqual(r.returncode, 0, r.stderr)
        j1, j2, _ = json.loads(r.stdout)["joints"]
        self.assertIsNone(j1["lower"]["value"] if isinstance(j1["lower"], dict) else j1["lower"])
        self.assertIsNone(j1["upper"]["value"] if isinstance(j1["upper"], dict) else j1["upper"])
        self.assertIsNotNone(j2["lower"]["value"] if isinstance(j2["lower"], dict) else j2["lower"])
        table = run("robot", urdf, "--base", "base", "--tip", "tool").stdout
        row = next(l for l in table.splitlines() if l.split()[:2] == ["1", "j1"])
        self.assertIn("-inf", row.split())
        self.assertIn("inf", row.split())
        # a trajectory run: joints 2 and 3 limited (the ratio finite), joint 1 free; the same arm with
        # every <limit> without lower and upper has no position limit at all (NaN ratio)
        for name, others, finite in (("some", DEFAULT_LIMIT, True), ("none", '<limit effort="100" velocity="10"/>', False)):
            with self.subTest(name):
                text = arm_urdf('<limit effort="100" velocity="10"/>').replace(DEFAULT_LIMIT, others)
                u = self.write(name + ".urdf", text)
                study = self.write(name + ".toml", f'[study]\nname = "l"\nhistories = "none"\n'
                                   f'[robot]\nurdf = "{u}"\nbase = "base"\ntip = "tool"\ngravity = [0, -9.81, 0]\n'
                                   '[task]\nvertices = [[0.6, 0.2], [0.6, 0.4]]\ndurations = [1]\n'
                                   + BLOCK + 'on_violation = "ignore"\n')
                out = os.path.join(self.dir, name + ".h5")
                r = run("run", study, "-o", out, "-q")
                self.assertEqual(r.returncode, 0, r.stderr)
                with h5py.File(out, "r") as f:
                    ratio = float(f["runs"]["max_q_limit_ratio"][0])
                self.assertEqual(math.isfinite(ratio), finite, ratio)


class InnerReach(TempDirTest):
    def check_refused(self, text, where, words):
        study = self.write("s.toml", text)
        out = os.path.join(self.dir, "s.h5")
        r = run("run", study, "-o", out)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(f"{study}:{where}", r.stderr)
        for w in words:
            self.assertIn(w, r.stderr)
        self.assertFalse(os.path.exists(out))

    ARM = '[robot]\nl = [2.0, 0.5, 0.5]\nm = [5.0, 2.0, 1.0]\nb = 0.1\n'

    def test_vertex_inside_the_inner_disc_is_refused(self):
        # links 2, 0.5, 0.5: no tip position closer than 2 * 2 - 3 = 1 m to the first joint's axis
        self.check_refused(self.ARM + '[task]\nvertices = [[0.3, 0.0], [0.4, 0.0]]\ndurations = [1.0]\n' + BLOCK,
                           "6:13:", ["vertex 1 is 0.3 m from the first joint's axis", "cannot reach", "1 m"])
        self.check_refused(self.ARM + '[task]\nvertices = [[2.5, 0.0], [0.3, 0.0], [2.5, 0.5]]\n'
                           'durations = [1.0, 1.0]\n' + BLOCK, "6:25:", ["vertex 2 is 0.3 m"])

    def test_planar_urdf_chain(self):
        # links 1.5, 0.3 and 0.3 m: no tip position closer than 2 * 1.5 - 2.1 = 0.9 m
        urdf = self.write("long.urdf", arm_urdf(LIMITED, lengths=(1.5, 0.3, 0.3)))
        head = f'[robot]\nurdf = "{urdf}"\nbase = "base"\ntip = "tool"\ngravity = [0, -9.81, 0]\n'
        self.check_refused(head + '[task]\nvertices = [[1.5, 0.0], [0.5, 0.5]]\ndurations = [1.0]\n' + BLOCK,
                           "7:25:", ["vertex 2 is 0.7071", "0.9 m"])
        study = self.write("ok.toml", head + '[task]\nvertices = [[1.5, 0.0], [1.3, 0.0]]\ndurations = [1.0]\n'
                           + BLOCK)
        r = run("run", study, "-o", os.path.join(self.dir, "ok.h5"), "-q")
        self.assertEqual(r.returncode, 0, r.stderr)


if __name__ == "__main__":
    KS, SOURCE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=sys.argv[:1])
