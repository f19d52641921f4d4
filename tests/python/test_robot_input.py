"""End-to-end refusals of hostile robot input by `kinesweep run`: each bad URDF of tests/fuzz/urdf_bad
(a kinematic loop, unit-suffixed, infinite and negative masses, a stray character in an inertia, a
negative and a triangle-violating inertia, a mimic joint, a heavy side branch), the vertex_alpha
shorthand on robots without vertex angles, and task vertices beyond the robot's reach. Each: exit 2, the
message located (the URDF's file and line, the study's line and column), no results file created and an
existing one left as it was. The loop is refused within bounds on time and memory.

usage: /usr/bin/python3 test_robot_input.py KINESWEEP_BINARY SOURCE_DIR
"""
import os
import resource
import subprocess
import sys
import tempfile
import time
import unittest

from e2e_common import TempDirTest

KS = None
SOURCE = None
SHADOW_SANITIZERS = {"address", "hwaddress", "memory", "thread", "leak"}
SANITIZED = set(os.environ.get("KINESWEEP_SANITIZE", "").replace(" ", "").split(",")) & SHADOW_SANITIZERS

BLOCK = '[[block]]\nname = "b"\nkind = "trajectory"\n'

# file -> (the text of the element at fault, words the message must hold)
BAD_URDFS = {
    "loop.urdf": ('<joint name="joint_close"', ["link 'link1' is the child of joint 'joint1'", "kinematic loop"]),
    "mass_unit.urdf": ('<mass value="3.0kg"/>', ["link 'link1'", 'value="3.0kg"', "followed by 'kg'"]),
    "mass_inf.urdf": ('<mass value="inf"/>', ["link 'link1'", 'value="inf"', "not finite"]),
    "mass_negative.urdf": ('<link name="link1">', ["link 'link1'", "negative", "expected a mass >= 0"]),
    "inertia_suffix.urdf": ('<inertia ixx="0.0127x"', ["link 'link1'", 'ixx="0.0127x"', "followed by 'x'"]),
    "inertia_negative.urdf": ('<link name="link1">', ["link 'link1'", "negative"]),
    "inertia_triangle.urdf": ('<link name="link1">', ["link 'link1'", "triangle inequality", "0.5 > 0.01 + 0.01"]),
    "mimic.urdf": ('<joint name="joint2"', ["joint 'joint2' mimics joint 'joint1'", "cannot honour"]),
    "not_a_chain.urdf": ('<joint name="branch_joint"', ["link 'link1'", "side branch through the moving joint 'branch_joint'"]),
}


def line_of(text, needle):
    """1-based line of the first `needle` in `text` (the test's own search)."""
    at = text.index(needle)
    return text.count("\n", 0, at) + 1


def run(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True, timeout=120)


class Refusals(TempDirTest):
    def check_refused(self, study, where, words):
        """`kinesweep run study -o OUT`: exit 2, `where` and `words` in stderr, OUT neither created nor,
        when it exists (with or without --overwrite), changed."""
        out = os.path.join(self.dir, "out.h5")
        if os.path.exists(out):
            os.remove(out)
        r = run("run", study, "-o", out)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(where, r.stderr)
        for w in words:
            self.assertIn(w, r.stderr)
        self.assertIn("expected", r.stderr)
        self.assertFalse(os.path.exists(out))
        for extra in ([], ["--overwrite"]):
            with open(out, "wb") as f:
                f.write(b"an earlier results file")
            r = run("run", study, "-o", out, *extra)
            self.assertEqual(r.returncode, 2, r.stderr)
            with open(out, "rb") as f:
                self.assertEqual(f.read(), b"an earlier results file")
        return r

    def test_bad_urdfs(self):
        for name, (needle, words) in BAD_URDFS.items():
            with self.subTest(name):
                urdf = os.path.join(SOURCE, "tests", "fuzz", "urdf_bad", name)
                with open(urdf) as f:
                    line = line_of(f.read(), needle)
                study = self.write(name + ".toml", f'[robot]\nurdf = "{urdf}"\nbase = "base_link"\ntip = "tool"\n' + BLOCK)
                r = self.check_refused(study, f"{urdf}:{line}", words)
                self.assertIn(f"{study}:2:", r.stderr)  # at the study's urdf key
                # the robot's error alone: nothing about the task or the blocks
                self.assertEqual(r.stderr.count("error:"), 1, r.stderr)

    def test_vertex_alpha_shorthand_without_vertex_angles(self):
        robots = {
            "nlink": ('[robot]\nl = [0.9, 0.9, 0.8, 0.6]\nm = [3.6, 3.6, 3.2, 2.4]\nb = 0.06\n', "a planar arm of 4 joints"),
            "urdf": (f'[robot]\nurdf = "{SOURCE}/studies/robots/planar4r.urdf"\nbase = "base_link"\ntip = "tool"\n',
                     "a planar arm of 4 joints"),
        }
        tables = {
            "block": BLOCK + "vertex_alpha = [10, 20, 30, 40]\n",
            "optimize": '[[optimize]]\nname = "o"\nkind = "trajectory"\nvertex_alpha = [10, 20, 30, 40]\n'
                        'variables = { k = [0, 1] }\n[optimize.local]\nalgorithm = "LN_BOBYQA"\nmax_evals = 5\n',
        }
        for rname, (robot, why) in robots.items():
            for tname, table in tables.items():
                with self.subTest(f"{rname} {tname}"):
                    study = self.write(f"{rname}_{tname}.toml", robot + table)
                    # vertex_alpha is on line 8 (4 [robot] lines, then the table's 3), column 1
                    self.check_refused(study, f"{study}:8:1:", ["vertex_alpha = [...]", why])

    def test_vertices_beyond_reach(self):
        cases = {
            # the seed's arm: links of 1 m; (3.5, 0) is 3.5 m from the first joint's axis
            "seed": ('[task]\nvertices = [[1, 0], [3.5, 0]]\ndurations = [1]\n', "2:21:",
                     ["vertex 2 is 3.5 m from the first joint's axis", "at most 3 m"]),
            # an n-link arm of 0.9 + 0.9 + 0.8 + 0.6 = 3.2 m; (0, 3.3)
            "nlink": ('[robot]\nl = [0.9, 0.9, 0.8, 0.6]\nm = [3.6, 3.6, 3.2, 2.4]\nb = 0.06\n'
                      '[task]\nvertices = [[1, 0], [0, 3.3]]\ndurations = [1]\n', "6:21:",
                      ["vertex 2 is 3.3 m from the first joint's axis", "at most 3.2 m"]),
            # arm7: a1 at z = 0.15 m, then 0.19 + 4 x 0.2 + 0.081 + 0.045 + 0.1 = 1.216 m; (0.9, 0, 1.35)
            # is (0.9, 0, 1.2) from it: 1.5 m
            "urdf": (f'[robot]\nurdf = "{SOURCE}/studies/robots/arm7.urdf"\nbase = "base_link"\ntip = "tool"\n'
                     '[task]\nvertices = [[0.5, 0, 0.6], [0.9, 0, 1.35]]\ndurations = [1]\n', "6:28:",
                     ["vertex 2 is 1.5 m from the first joint,", "at most 1.216 m"]),
        }
        for name, (text, where, words) in cases.items():
            with self.subTest(name):
                study = self.write(name + ".toml", text + BLOCK)
                self.check_refused(study, f"{study}:{where}", words)


class LoopBounds(TempDirTest):
    def test_loop_is_refused_quickly_in_little_memory(self):
        urdf = os.path.join(SOURCE, "tests", "fuzz", "urdf_bad", "loop.urdf")
        study = self.write("loop.toml", f'[robot]\nurdf = "{urdf}"\nbase = "base_link"\ntip = "tool"\n' + BLOCK)

        def cap():  # 2 GB of address space: the unbounded growth this refusal replaces ends here, not in swap
            resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

        with tempfile.TemporaryFile("w+") as err:
            start = time.monotonic()
            p = subprocess.Popen([KS, "run", study, "-o", os.path.join(self.dir, "loop.h5")],
                                 stdout=subprocess.DEVNULL, stderr=err, preexec_fn=None if SANITIZED else cap)
            _, status, usage = os.wait4(p.pid, 0)
            seconds = time.monotonic() - start
            err.seek(0)
            self.assertEqual(os.waitstatus_to_exitcode(status), 2, err.read())
        self.assertLess(seconds, 1.0 * (5 if SANITIZED else 1))
        if not SANITIZED:
            self.assertLess(usage.ru_maxrss * 1024, 100 * 2**20)


if __name__ == "__main__":
    KS, SOURCE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=sys.argv[:1])
