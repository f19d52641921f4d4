"""End-to-end tests of `kinesweep run --resume` on a results file whose study was edited since: the
runs of the old file that the edited study still has are reused (not computed again), the rest are
computed, and the file comes out equal to a fresh run of the edited study (the oracle: /runs but
wall_time, every history and every landscape compared bit for bit with h5py). A change of the robot,
the task or the settings that every kind of the study's runs reads is refused with the old file left
byte for byte as it was; an edited task keeps the IK runs.

usage: /usr/bin/python3 test_resume_edited.py KINESWEEP_BINARY ROBOTS_DIR (studies/robots)
"""
import hashlib
import os
import re
import signal
import subprocess
import sys
import time
import unittest

import h5py
import numpy as np

from e2e_common import Histories, TempDirTest, bitwise_equal, runs_column, runs_table, same_histories, same_tables

KS = ROBOTS = None

# 15 trajectory runs (histories every 50th sample) and 15 IK runs: well under a second.
BASE = """[study]
name = "edit"
histories = "every=50"

[[block]]
name = "weighted"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { from = -10, to = 10, step = 5 }
k = [0.0, 0.5, 1.0]

[[block]]
name = "basin"
kind = "ik"
problem = "scara"
method = "newton"
[block.axes]
q0_1 = { from = -90, to = 90, count = 5 }
q0_2 = [0, 45, 90]
"""

UNWEIGHTED = """
[[block]]
name = "unweighted"
kind = "trajectory"
method = "local_unweighted"
[block.axes]
alpha1A = [-5, 0, 5]
"""

PARAMS = ("block", "alpha1A", "k", "method", "q0_1", "q0_2")  # what tells these studies' runs apart


def run(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True)


def file_sha(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def datasets(path, group):
    """Every dataset under /GROUP: {path inside the group: array}."""
    out = {}
    with h5py.File(path, "r") as f:
        f[group].visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
    return out


def computed(stdout):
    """(computed now, already in the file) from the run's summary line."""
    m = re.search(r"\((\d+) computed now, (\d+) already in the file\)", stdout)
    assert m, stdout
    return int(m.group(1)), int(m.group(2))


def keyed_wall_times(path):
    """{(block, parameter values...): wall_time} of a results file's runs."""
    with h5py.File(path, "r") as f:
        g = f["runs"]
        cols = [runs_column(g[k]) for k in PARAMS]
        wall = g["wall_time"][()]
    return {tuple(c[i] if isinstance(c[i], str) else c[i].tobytes() for c in cols): wall[i] for i in range(len(wall))}


class ResumeEdited(TempDirTest):
    def study(self, name, text):
        return self.write(name + ".toml", text)

    def fresh(self, text):
        """The oracle: a fresh run of `text` (another file name, same options)."""
        path = self.study("fresh", text)
        out = os.path.join(self.dir, "fresh.h5")
        r = run("run", path, "-o", out, "-q", "--overwrite")
        self.assertEqual(r.returncode, 0, r.stderr)
        return out

    def old_and_edited(self, old_text, new_text, *args):
        """Runs `old_text` into edit.h5 (a byte copy kept as old_copy.h5), then resumes it with
        `new_text` (and `args`): (file, old copy, the resume's CompletedProcess)."""
        out = self.old_file(old_text)
        copy = os.path.join(self.dir, "old_copy.h5")
        with open(out, "rb") as a, open(copy, "wb") as b:
            b.write(a.read())
        r = run("run", self.study("edit", new_text), "-o", out, "-q", "--resume", *args)
        return out, copy, r

    def old_file(self, text):
        out = os.path.join(self.dir, "edit.h5")
        r = run("run", self.study("old", text), "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        return out

    def assert_equal_to_fresh(self, out, text):
        ref = self.fresh(text)
        self.assertTrue(same_tables(runs_table(out), runs_table(ref)), "/runs differs from a fresh run's")
        got, want = datasets(out, "landscapes"), datasets(ref, "landscapes")
        self.assertEqual(sorted(got), sorted(want))
        self.assertGreater(len(want), 0)
        for k in want:
            self.assertTrue(bitwise_equal(np.asarray(got[k]), np.asarray(want[k])), f"/landscapes/{k}")
        with h5py.File(out, "r") as f, h5py.File(ref, "r") as g:
            # every run's history, bit for bit (runs are placed in the row space in write order:
            # reused runs before computed ones, so the datasets' row order may differ)
            self.assertGreater(len(Histories(g).ids()), 0)
            same_histories(self, f, g)
            self.assertEqual(f["study/text"][()], g["study/text"][()])
            self.assertEqual(f.attrs["study_sha256"], g.attrs["study_sha256"])
        self.assertEqual([n for n in os.listdir(self.dir) if ".tmp-" in n or n.endswith(".journal")], [])

    def assert_reused(self, out, old, computed_now):
        """The runs of `out` that `old` has kept their wall_time (copied, not computed), and
        `computed_now` runs are new."""
        before, after = keyed_wall_times(old), keyed_wall_times(out)
        kept = [k for k in after if k in before]
        for k in kept:
            self.assertEqual(after[k], before[k], k)
        self.assertEqual(len(after) - len(kept), computed_now)

    def test_comment_edit_computes_nothing(self):
        edited = "# the same study, commented\n" + BASE.replace('method = "newton"', 'method = "newton"  # the basin')
        out, old, r = self.old_and_edited(BASE, edited)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (0, 30))
        self.assertIn("30 of its 30 done runs", r.stdout)
        self.assert_equal_to_fresh(out, edited)
        with h5py.File(out, "r") as f, h5py.File(old, "r") as g:  # copied, not computed again
            self.assertTrue(bitwise_equal(f["runs"]["wall_time"][()], g["runs"]["wall_time"][()]))

    def test_axis_extended_computes_only_the_new_runs(self):
        edited = BASE.replace("k = [0.0, 0.5, 1.0]", "k = [0.0, 0.25, 0.5, 0.75, 1.0]")
        out, old, r = self.old_and_edited(BASE, edited)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (10, 30))
        self.assert_reused(out, old, 10)
        self.assert_equal_to_fresh(out, edited)

    def test_block_added_in_the_middle(self):
        i = BASE.index("[[block]]\nname = \"basin\"")
        edited = BASE[:i] + UNWEIGHTED.lstrip() + "\n" + BASE[i:]
        out, old, r = self.old_and_edited(BASE, edited)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (3, 30))
        self.assert_reused(out, old, 3)
        self.assert_equal_to_fresh(out, edited)

    def test_block_removed_and_values_dropped(self):
        edited = BASE[:BASE.index("[[block]]\nname = \"basin\"")].replace("k = [0.0, 0.5, 1.0]", "k = [0.5]")
        out, old, r = self.old_and_edited(BASE, edited)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (0, 5))
        self.assertIn("5 of its 30 done runs", r.stdout)
        self.assert_equal_to_fresh(out, edited)

    def test_blocks_reordered(self):
        i = BASE.index("[[block]]\nname = \"weighted\"")
        j = BASE.index("[[block]]\nname = \"basin\"")
        edited = BASE[:i] + BASE[j:] + "\n" + BASE[i:j]
        out, old, r = self.old_and_edited(BASE, edited)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (0, 30))
        self.assert_reused(out, old, 0)
        self.assert_equal_to_fresh(out, edited)

    def test_a_partial_file_is_extended_and_completed(self):
        # the old file holds only some of its runs: those reused, the others of the edited study computed
        old_study = self.study("old", BASE)
        out = os.path.join(self.dir, "edit.h5")
        self.assertEqual(run("run", old_study, "-o", out, "-q").returncode, 0)
        with h5py.File(out, "r+") as f:  # as after a crash: runs 3..9 not done
            done = f["runs"]["done"]
            done[3:10] = 0
        edited = BASE.replace("q0_2 = [0, 45, 90]", "q0_2 = [0, 45, 90, 135]")
        r = run("run", self.study("edit", edited), "-o", out, "-q", "--resume")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (5 + 7, 23))
        self.assert_equal_to_fresh(out, edited)

    def refused(self, edited, *args, expect, old_text=BASE):
        out, old, r = self.old_and_edited(old_text, edited, *args)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        for e in expect:
            self.assertIn(e, r.stderr)
        self.assertIn("refusing to resume: rerun with --overwrite", r.stderr)
        self.assertEqual(file_sha(out), file_sha(old))  # untouched, byte for byte
        self.assertEqual(sorted(os.listdir(self.dir)), sorted(["old.toml", "edit.toml", "edit.h5", "old_copy.h5"]))

    def test_robot_changed_is_refused_saying_what_changed(self):
        self.refused(BASE + "\n[robot]\nm = [5.0, 2.0, 1.5]\n",
                     expect=["the robot changed: [robot] m: [5, 2, 1] -> [5, 2, 1.5]"])

    def test_task_changed_computes_the_trajectory_runs_again_and_keeps_the_ik_runs(self):
        # IK runs read no path (their kind's resume_context has no task): an edited [task] keeps them
        edited = BASE + "\n[task]\ndt = 0.002\n"
        out, old, r = self.old_and_edited(BASE, edited)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("the task changed: [task] dt: 0.001 -> 0.002 (read by the trajectory runs, which are "
                      "computed again)", r.stdout)
        self.assertEqual(computed(r.stdout), (15, 15))
        with h5py.File(out, "r") as f, h5py.File(old, "r") as g:
            block, was_block = runs_column(f["runs"]["block"]), runs_column(g["runs"]["block"])
            wall, was_wall = f["runs"]["wall_time"][()], g["runs"]["wall_time"][()]
        ik, was_ik = wall[np.asarray(block) == "basin"], was_wall[np.asarray(was_block) == "basin"]
        self.assertTrue(bitwise_equal(ik, was_ik))  # copied, not computed again
        self.assertEqual(len(ik), 15)
        self.assert_equal_to_fresh(out, edited)

    def test_task_changed_is_refused_when_every_run_reads_it(self):
        trajectory_only = BASE[:BASE.index("[[block]]\nname = \"basin\"")]
        self.refused(trajectory_only + "\n[task]\ndt = 0.002\n", old_text=trajectory_only,
                     expect=["the task changed: [task] dt: 0.001 -> 0.002"])

    def test_histories_changed_is_refused(self):
        self.refused("# histories off from now on\n" + BASE, "--histories", "none",
                     expect=["the settings changed: [study] histories: every=50 -> none"])

    def test_a_histories_option_given_then_is_remembered(self):
        # The old file was written with --histories every=25 (its study says every=50): resuming an
        # edited study with the same option reuses every run, since the file records the policy.
        out = os.path.join(self.dir, "edit.h5")
        r = run("run", self.study("old", BASE), "-o", out, "-q", "--histories", "every=25")
        self.assertEqual(r.returncode, 0, r.stderr)
        with h5py.File(out, "r") as f:
            self.assertEqual(f.attrs["histories"], "every=25")
        edited = "# commented\n" + BASE
        r = run("run", self.study("edit", edited), "-o", out, "-q", "--resume", "--histories", "every=25")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (0, 30))
        with h5py.File(out, "r") as f:
            self.assertEqual(f.attrs["histories"], "every=25")

    def test_plain_resume_with_another_histories_option_is_refused(self):
        out = self.old_file(BASE)
        before = file_sha(out)
        r = run("run", self.study("old", BASE), "-o", out, "-q", "--resume", "--histories", "full")
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertIn("its runs were written with histories = every=50, this run asks for full", r.stderr)
        self.assertIn("resume with --histories every=50", r.stderr)
        self.assertEqual(file_sha(out), before)
        r = run("run", self.study("old", BASE), "-o", out, "-q", "--resume", "--histories", "every=50")
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_the_defaults_written_out_are_no_change(self):
        edited = BASE + "\n[robot]\ng = 9.81\n[task]\ndt = 1e-3\nintegrator = \"semi_implicit_euler\"\n"
        out, old, r = self.old_and_edited(BASE, edited)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (0, 30))
        self.assert_equal_to_fresh(out, edited)

    def test_identical_text_resumes_in_place(self):
        out, old, r = self.old_and_edited(BASE, BASE)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (0, 30))
        self.assertNotIn("reused", r.stdout)

    def big_extension(self):
        """An old file of BASE, and a study adding 2000 trajectory runs to it (seconds on one thread)."""
        edited = BASE + """
[[block]]
name = "wide"
kind = "trajectory"
method = "local_unweighted"
[block.axes]
alpha1A = { from = -30, to = 30, count = 200 }
k = { from = 0, to = 1, count = 10 }
"""
        out = self.old_file(BASE)
        old = os.path.join(self.dir, "old_copy.h5")
        with open(out, "rb") as a, open(old, "wb") as b:
            b.write(a.read())
        return out, old, self.study("edit", edited), edited

    def test_sigkill_during_an_extension_leaves_the_old_file_and_resume_completes(self):
        out, old, study, edited = self.big_extension()
        p = subprocess.Popen([KS, "run", study, "-o", out, "-q", "--resume", "--threads", "1"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        while p.poll() is None and not any(".tmp-" in n for n in os.listdir(self.dir)):
            time.sleep(0.005)
        time.sleep(0.2)
        p.send_signal(signal.SIGKILL)
        p.wait()
        if file_sha(out) != file_sha(old):  # it finished before the kill: then it is the complete file
            self.assert_equal_to_fresh(out, edited)
            self.skipTest("finished before the kill")
        self.assertTrue(any(".tmp-" in n for n in os.listdir(self.dir)))  # killed mid-way: its staged file
        r = run("run", study, "-o", out, "-q", "--resume")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (2000, 30))
        self.assert_equal_to_fresh(out, edited)  # the killed run's staged file is gone too

    def test_sigint_during_an_extension_leaves_the_old_file(self):
        out, old, study, edited = self.big_extension()
        p = subprocess.Popen([KS, "run", study, "-o", out, "-q", "--resume", "--threads", "1"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        while p.poll() is None and not any(".tmp-" in n for n in os.listdir(self.dir)):
            time.sleep(0.005)
        p.send_signal(signal.SIGINT)
        stdout, stderr = p.communicate()
        if p.returncode == 0:
            self.skipTest("finished before the signal")
        self.assertEqual(p.returncode, 130, stderr)
        self.assertIn(out + " is unchanged", stdout)
        self.assertIn("resume with: ", stdout)
        self.assertEqual(file_sha(out), file_sha(old))
        self.assertEqual([n for n in os.listdir(self.dir) if ".tmp-" in n], [])


URDF_STUDY = """[study]
name = "urdf"
histories = "full"

[robot]
urdf = "robot.urdf"
base = "base_link"
tip = "tool"

[[block]]
name = "position"
kind = "ik"
problem = "position"
method = "lm"
[block.axes]
q0_1 = [0, 30, 60]
q0_2 = [10, 20]
"""


class ResumeEditedUrdf(TempDirTest):
    """A URDF robot: what counts is the chain the file gives, not its text."""

    def setUp(self):
        super().setUp()
        with open(os.path.join(ROBOTS, "planar4r.urdf")) as f:
            self.urdf = f.read()
        self.study = self.write("s.toml", URDF_STUDY)
        self.write("robot.urdf", self.urdf)
        self.out = os.path.join(self.dir, "s.h5")
        r = run("run", self.study, "-o", self.out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_urdf_comment_and_new_axis_values_reuse_the_runs(self):
        self.write("robot.urdf", self.urdf.replace("<link name=\"tool\"/>", "<!-- the tool --><link name=\"tool\"/>"))
        edited = self.write("s.toml", URDF_STUDY.replace("q0_2 = [10, 20]", "q0_2 = [10, 20, 40]"))
        r = run("run", edited, "-o", self.out, "-q", "--resume")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(computed(r.stdout), (3, 6))
        ref = os.path.join(self.dir, "ref.h5")
        self.assertEqual(run("run", edited, "-o", ref, "-q").returncode, 0)
        self.assertTrue(same_tables(runs_table(self.out), runs_table(ref)))
        with h5py.File(self.out, "r") as f, h5py.File(ref, "r") as g:
            same_histories(self, f, g)
        with h5py.File(self.out, "r") as f:  # the edited URDF text is the one stored
            self.assertIn("the tool", f["study/robot"][()].decode())

    def test_urdf_mass_changed_is_refused(self):
        before = file_sha(self.out)
        self.write("robot.urdf", self.urdf.replace('<mass value="3.2"/>', '<mass value="3.3"/>'))
        self.write("s.toml", "# edited\n" + URDF_STUDY)
        r = run("run", self.study, "-o", self.out, "-q", "--resume")
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("the robot changed: [robot] joint 3 mass: 3.2 -> 3.3", r.stderr)
        self.assertEqual(file_sha(self.out), before)


if __name__ == "__main__":
    KS = sys.argv.pop(1)
    ROBOTS = sys.argv.pop(1)
    unittest.main()
