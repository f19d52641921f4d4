"""End-to-end: robots from standard DH tables ([robot] dh). Every bad DH table is refused by `kinesweep
run` with exit 2 and a located message (FILE:LINE:COL, what was expected, did-you-mean on key names),
nothing written; an error in a robot file is located in that file, with a note at the study's dh key.
The shipped DH robots (studies/robots/planar2r.toml, scara.toml, puma560.toml) are shown by `kinesweep
robot` and run: a trajectory block on the SCARA and an IK block on the Puma 560.

usage: /usr/bin/python3 test_dh_robot_input.py KINESWEEP_BINARY SOURCE_DIR
"""
import json
import os
import subprocess
import sys
import unittest

from e2e_common import TempDirTest

KS = None
SOURCE = None

IK_BLOCK = '[[block]]\nname = "b"\nkind = "ik"\nproblem = "position"\n'

# A valid planar 2R in the study; each case replaces lines (1-based).
ROWS = [
    "[robot]",                                            # 1
    "gravity = [0, -9.81, 0]",                            # 2
    "[[robot.dh]]",                                       # 3
    'type = "revolute"',                                  # 4
    "a = 0.5",                                            # 5
    "alpha = 0",                                          # 6
    "d = 0",                                              # 7
    "theta = 0",                                          # 8
    "mass = 2",                                           # 9
    "com = [-0.25, 0, 0]",                                # 10
    "inertia = { ixx = 0.001, iyy = 0.05, izz = 0.05 }",  # 11
    "limits = { lower = -90, upper = 90 }",               # 12
    "[[robot.dh]]",                                       # 13
    'type = "revolute"',                                  # 14
    "a = 0.5",                                            # 15
    "alpha = 0",                                          # 16
    "d = 0",                                              # 17
    "theta = 0",                                          # 18
    "mass = 1",                                           # 19
    "com = [-0.25, 0, 0]",                                # 20
    "inertia = { ixx = 0.001, iyy = 0.02, izz = 0.02 }",  # 21
]

# name -> (edits {line: text}, "LINE:COL", words the message must hold)
BAD = {
    "row_length": ({10: "com = [-0.25, 0]"}, "10:7", ["com is an array of 2", "expected an array of 3 numbers"]),
    "joint_type": ({4: 'type = "revolut"'}, "4:8", ["unknown joint type 'revolut'", "did you mean 'revolute'?"]),
    "negative_mass": ({9: "mass = -2"}, "9:8", ["mass = -2 is negative", "expected a mass >= 0 [kg]"]),
    "inertia_negative": ({11: "inertia = { ixx = -0.001, iyy = 0.05, izz = 0.05 }"}, "11:11",
                         ["include a negative one", "positive semi-definite"]),
    "inertia_triangle": ({11: "inertia = { ixx = 0.001, iyy = 0.001, izz = 0.05 }"}, "11:11",
                         ["triangle inequality", "0.05 > 0.001 + 0.001"]),
    "missing_field": ({7: "# no d"}, "3:1", ["dh row 1 has no 'd'", "expected d = D [m]"]),
    "missing_inertia": ({11: "# no inertia"}, "3:1", ["dh row 1 has no 'inertia'"]),
    "limits_reversed": ({12: "limits = { lower = 90, upper = -90 }"}, "12:20",
                        ["limits lower = 90 > upper = -90", "expected lower < upper [deg]"]),
    "limits_equal": ({12: "limits = { lower = 10, upper = 10 }"}, "12:20", ["a joint that cannot move"]),
    "velocity_zero": ({12: "limits = { lower = -90, upper = 90, velocity = 0 }"}, "12:48", ["expected a limit > 0 [deg/s]"]),
    "key_typo": ({9: "mas = 2"}, "9:1", ["unknown key 'mas' in dh row 1", "did you mean 'mass'?"]),
    "inertia_key_typo": ({11: "inertia = { ixx = 0.001, iyy = 0.05, izzz = 0.05 }"}, "11:38",
                         ["unknown key 'izzz' in dh row 1 inertia", "did you mean 'izz'?"]),
    "limit_key_typo": ({12: "limits = { lower = -90, uper = 90 }"}, "12:25", ["did you mean 'upper'?"]),
    "not_a_number": ({5: 'a = "half a metre"'}, "5:5", ["dh row 1 a is a string; expected a number"]),
    "robot_key_typo": ({2: "gravty = [0, -9.81, 0]"}, "2:1", ["unknown key 'gravty' in [robot]", "did you mean 'gravity'?"]),
    "massless_joint": ({19: "mass = 0", 21: "inertia = { ixx = 0, iyy = 0, izz = 0 }"}, "13:1",
                       ["joint 'joint2' moves neither mass nor inertia"]),
    "urdf_and_dh": ({2: 'urdf = "x.urdf"'}, "2:8", ["urdf and dh both given"]),
    "planar_key": ({2: "l = [1, 1]"}, "2:5", ["l describes a planar arm; expected no l with dh"]),
}


def study_text(edits):
    rows = list(ROWS)
    for line, text in edits.items():
        rows[line - 1] = text
    return "\n".join(rows) + "\n" + IK_BLOCK


def run(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True, timeout=120)


class Refusals(TempDirTest):
    def refused(self, study, where, words):
        out = os.path.join(self.dir, "out.h5")
        r = run("run", study, "-o", out)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(where, r.stderr)
        for w in words:
            self.assertIn(w, r.stderr)
        self.assertIn("; expected ", r.stderr)
        self.assertFalse(os.path.exists(out))
        return r

    def test_valid_table_is_accepted(self):
        study = self.write("ok.toml", study_text({}))
        r = run("robot", study, "--format", "json")
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_bad_tables(self):
        for name, (edits, where, words) in BAD.items():
            with self.subTest(name):
                study = self.write(name + ".toml", study_text(edits))
                self.refused(study, f"{study}:{where}:", words)

    def test_robot_file_errors_are_located_in_it(self):
        robot_rows = "\n".join(ROWS[1:]).replace("[[robot.dh]]", "[[dh]]").replace("mass = 1", "mas = 1")
        robot = self.write("bad_robot.toml", robot_rows + "\n")  # "mas = 1" on line 18
        study = self.write("uses_file.toml", '[robot]\ndh = "bad_robot.toml"\n' + IK_BLOCK)
        r = self.refused(study, f"{robot}:18:1:", ["unknown key 'mas' in dh row 2", "did you mean 'mass'?"])
        self.assertIn(f"{study}:2:6: the DH robot file named here", r.stderr)
        self.write("bad_robot.toml", "[[dh]]\na = = 1\n")
        self.refused(study, f"{robot}:2:", ["TOML syntax"])
        missing = self.write("missing.toml", '[robot]\ndh = "no_such_robot.toml"\n' + IK_BLOCK)
        self.refused(missing, f"{missing}:2:6:", ["cannot read the DH robot file"])


class ShippedRobots(TempDirTest):
    def robot(self, name):
        path = os.path.join(SOURCE, "studies", "robots", name + ".toml")
        study = self.write(name + "_show.toml", f'[robot]\ndh = "{path}"\n' + IK_BLOCK)
        r = run("robot", study, "--format", "json")
        self.assertEqual(r.returncode, 0, r.stderr)
        return json.loads(r.stdout), run("robot", study).stdout

    def test_robot_command_shows_the_chains(self):
        for name, joints, planar in (("planar2r", 2, True), ("scara", 4, False), ("puma560", 6, False)):
            with self.subTest(name):
                view, table = self.robot(name)
                self.assertEqual(len(view["joints"]), joints)
                self.assertIn("DH table", view["from"])
                self.assertIn("DH table", table)
                self.assertEqual(view["motion"], "planar" if planar else "spatial")

    def test_runs_on_dh_robots(self):
        scara = os.path.join(SOURCE, "studies", "robots", "scara.toml")
        puma = os.path.join(SOURCE, "studies", "robots", "puma560.toml")
        studies = {
            "scara_square": f'[robot]\ndh = "{scara}"\n[task]\n'
                            'vertices = [[0.4, -0.1, -0.3], [0.4, 0.1, -0.3], [0.5, 0.1, -0.3], [0.5, -0.1, -0.3], [0.4, -0.1, -0.3]]\n'
                            'durations = [1, 1, 1, 1]\n'
                            '[[block]]\nname = "local"\nkind = "trajectory"\nmethod = "local_weighted"\n'
                            '[block.axes]\nk = [0, 0.5]\n',
            "puma_ik": f'[robot]\ndh = "{puma}"\n[[block]]\nname = "ik"\nkind = "ik"\nproblem = "position"\n'
                       'method = "lm"\ntarget_x = 0.4\ntarget_y = 0.2\ntarget_z = 0.3\n',
        }
        for name, text in studies.items():
            with self.subTest(name):
                study = self.write(name + ".toml", text)
                out = os.path.join(self.dir, name + ".h5")
                r = run("run", study, "-o", out, "-q", "--no-verify-best")
                self.assertEqual(r.returncode, 0, r.stderr)
                q = run("query", out, "--columns", "status", "--format", "csv")
                self.assertEqual(q.returncode, 0, q.stderr)
                statuses = q.stdout.split()[1:]
                self.assertTrue(statuses, q.stdout)
                self.assertTrue(all(s in ("ok", "converged") for s in statuses), q.stdout)


if __name__ == "__main__":
    KS, SOURCE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=sys.argv[:1])
