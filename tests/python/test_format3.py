"""A format_version 3 results file (tests/format3/mixed_v3.h5, written by kinesweep before format 4
from tests/format3/mixed.toml) against the same study written now (format 4): every command and
the Python reader give the same answers on both, and `kinesweep run --resume` continues the format 3
file in its own layout, to the values of the format 4 file.

The oracle is the format 3 file itself (written by the previous engine, whose stored values the
regression manifest pins): only wall_time, the file name and the creation stamp may differ.

usage: /usr/bin/python3 test_format3.py KINESWEEP_BINARY FORMAT3_DIR (tests/format3)
"""
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

from e2e_common import bitwise_equal, runs_column, same_histories

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
from kinesweep import read as ksread  # noqa: E402

KS = DIR = None


def ks(*args):
    r = subprocess.run([KS, *args], capture_output=True, text=True)
    if r.returncode != 0:
        raise AssertionError(f"kinesweep {' '.join(args)} exited {r.returncode}:\n{r.stderr}")
    return r.stdout


# Unit labels the engine has made precise since the format 3 fixture was written (the SCARA's IK
# residual and error in mm, its third joint's iterate in mm, instead of "problem units" and "rad or
# mm"): read alike on both sides, so that every other difference still shows.
REFINED_UNITS = {"problem units": "mm", "rad or mm": "mm"}


def as_now(text):
    for old, new in REFINED_UNITS.items():
        text = text.replace(old, new)
    return text


# Columns the engine has added since the format 3 fixture was written (the seed arm's start branch
# and end condition, the end-state metrics): the fixture has none of them, so the comparisons below
# are over the columns both files have, and `info`'s lists are read without them.
ADDED = ("start_branch", "end", "end_window", "end_gain", "end_qd_max", "end_kinetic_energy")


def without_added(line):
    for name in ADDED:
        line = re.sub(r", %s( \[[^\]]*\])?(?=,|$)" % name, "", line)
    return line


def comparable(text, path):
    """A command's output without what names the file, its source or its creation (the file, study and
    engine lines of info), unit labels as REFINED_UNITS reads them."""
    out = []
    for line in as_now(text.replace(path, "FILE")).splitlines():
        line = re.sub(r"-{2,}", "--", re.sub(r" +", " ", line))  # (a column's width follows its unit label's)
        if line.startswith(("file ", "engine ", "study ")):
            continue
        out.append(without_added(line))
    return out


class Format3(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        d = cls.tmp.name
        cls.v3 = os.path.join(d, "mixed_v3.h5")
        shutil.copyfile(os.path.join(DIR, "mixed_v3.h5"), cls.v3)
        cls.v4 = os.path.join(d, "mixed_v4.h5")
        ks("run", os.path.join(DIR, "mixed.toml"), "-o", cls.v4, "-q", "--no-verify-best")
        with h5py.File(cls.v3, "r") as f:
            cls.columns = [c.decode() if isinstance(c, bytes) else c for c in f["runs"].attrs["columns"]]
            cls.version3 = int(f.attrs["format_version"])
        with h5py.File(cls.v4, "r") as f:
            cls.version4 = int(f.attrs["format_version"])

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_the_files_are_of_the_two_formats(self):
        self.assertEqual(self.version3, 3)
        self.assertEqual(self.version4, 5)  # this kinesweep's format (labelled columns since 4)
        with h5py.File(self.v3, "r") as f3, h5py.File(self.v4, "r") as f4:
            self.assertEqual(f3["runs"]["method"].dtype.kind, "O")  # strings ...
            self.assertIsNotNone(h5py.check_enum_dtype(f4["runs"]["method"].dtype))  # ... and labels

    def same_output(self, *args):
        a = ks(*[self.v3 if x == "F" else x for x in args])
        b = ks(*[self.v4 if x == "F" else x for x in args])
        self.assertEqual(comparable(a, self.v3), comparable(b, self.v4), " ".join(args))

    def test_commands_answer_alike(self):
        cols = ",".join(c for c in self.columns if c != "wall_time")
        self.same_output("info", "F")
        self.same_output("info", "F", "--best", "5")
        self.same_output("query", "F", "--columns", cols)
        self.same_output("query", "F", "--columns", cols, "-f", "csv")
        self.same_output("query", "F", "--columns", cols, "-f", "json", "--where", "method=newton,halley")
        self.same_output("query", "F", "--where", "status=ok", "--sort", "E", "--limit", "5", "--columns", cols)
        self.same_output("query", "F", "--where", "block=basins", "--sort", "iterations:desc,run_id", "--limit", "7",
                         "--columns", cols)
        self.same_output("query", "F", "--where", "status!=converged", "--where", "block=basins | block=grid",
                         "--columns", cols)
        self.same_output("query", "F", "--group-by", "block,status", "--agg", "count,min:E,argmin:iterations,median:E")
        self.same_output("query", "F", "--group-by", "method", "--agg", "mean:E,sum:iterations,max:E,argmax:E",
                         "-f", "csv")
        self.same_output("query", "F", "--where", "preset=1g", "--include-pending", "--columns", "run_id,preset,E")
        self.same_output("query", "F", "--run", "1", "--history", "all")

    def test_the_python_reader_reads_alike(self):
        with ksread.open_results(self.v3) as r3, ksread.open_results(self.v4) as r4:
            t3, t4 = r3.runs(done_only=False), r4.runs(done_only=False)
            self.assertEqual(list(t3), [c for c in t4 if c not in ADDED])
            for c in t3:
                if c == "wall_time":
                    continue
                self.assertTrue(bitwise_equal(np.asarray(t3[c]), np.asarray(t4[c])), c)
                self.assertEqual(as_now(t3.units[c]), as_now(t4.units[c]), c)
            d3, d4 = r3.to_pandas(), r4.to_pandas()
            self.assertEqual(list(d3.columns), [c for c in d4.columns if c not in ADDED])
            for c in d3.columns:
                if c == "wall_time":
                    continue
                a, b = d3[c].to_numpy(), d4[c].to_numpy()
                if d4[c].dtype.name == "category":
                    self.assertEqual(a.astype(object).tolist(), b.astype(object).tolist(), c)
                else:
                    self.assertTrue(bitwise_equal(a, b), c)
            self.assertEqual(r3.blocks(), r4.blocks())
            self.assertEqual(r3.row_kinds().tolist(), r4.row_kinds().tolist())
            self.assertEqual(r3.landscapes(), r4.landscapes())
            for b in r3.landscapes():
                l3, l4 = r3.landscape(b), r4.landscape(b)
                for m in l3.metrics:
                    self.assertTrue(bitwise_equal(l3.metrics[m], l4.metrics[m]), f"{b} {m}")
            for i in r3.history_ids():
                h3, h4 = r3.history(i), r4.history(i)
                self.assertEqual(list(h3), list(h4))
                for a in h3:
                    self.assertTrue(bitwise_equal(h3[a], h4[a]), f"run {i} {a}")

    def test_resume_of_a_file_without_the_added_columns_is_refused_untouched(self):
        # The fixture predates columns the schema now has (ADDED): resume refuses it before any write
        # (a file is resumed only by a study whose columns it holds), naming the column, and the file
        # and its absent journal stay as they were.
        path = os.path.join(self.tmp.name, "resumed_v3.h5")
        shutil.copyfile(self.v3, path)
        with open(path, "rb") as f:
            before = hashlib.sha256(f.read()).hexdigest()
        r = subprocess.run([KS, "run", os.path.join(DIR, "mixed.toml"), "-o", path, "--resume"],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("refusing to resume", r.stderr)
        self.assertIn("start_branch", r.stderr)
        with open(path, "rb") as f:
            self.assertEqual(hashlib.sha256(f.read()).hexdigest(), before)
        self.assertFalse(os.path.exists(path + ".journal"))


if __name__ == "__main__":
    KS, DIR = sys.argv[1], sys.argv[2]
    del sys.argv[1:3]
    unittest.main(verbosity=2)
