"""End-to-end tests of `kinesweep query`'s OR filters, --group-by/--agg and filters on an optimisation's
evaluations, and of `kinesweep info` on drawn (random, Latin-hypercube) axes; every expected value
computed here with numpy from the file as read by h5py.

usage: /usr/bin/python3 test_query_group.py KINESWEEP_BINARY REPO_ROOT
"""
import csv
import io
import math
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

from e2e_common import OPTIMIZE as OPTIMIZE_COMMON, StudyFileTest, run_study_text

KS = None
D = 180.0 / math.pi

STUDY = """
[study]
name = "query_group"
histories = "none"

[[block]]
name = "local"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { from = -30, to = 30, step = 10 }
k = { from = 0, to = 1, count = 5 }

[[block]]
name = "drawn"
kind = "trajectory"
method = "local_weighted"
lhs = { count = 12, seed = 3 }
[block.axes]
alpha1A = { lhs = { from = -30, to = 30 } }
k = { lhs = { from = 0, to = 0.5 } }
"""

OPTIMIZE = OPTIMIZE_COMMON.replace('name = "e2e_optimize"', 'name = "group_opt"')


def ks(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True)


def read_csv(text):
    rows = list(csv.reader(io.StringIO(text)))
    return rows[0], rows[1:]


def s(v):
    return v.decode() if isinstance(v, bytes) else str(v)


class GroupAndOr(StudyFileTest):
    NAME, STUDY = "g", STUDY

    @classmethod
    def setUpClass(cls):
        cls.KS = KS
        super().setUpClass()
        cls.t = cls.runs

    def test_or_form(self):
        t = self.t
        r = ks("query", self.h5, "-w", "E<45 | alpha1A>=20", "-w", "block=local", "-c", "run_id", "-f", "csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        got = [int(x[0]) for x in read_csv(r.stdout)[1]]
        m = ((t["E"] < 45) | (t["alpha1A"] * D >= 20 - 1e-9)) & (t["block"] == "local") & (t["done"] == 1)
        self.assertEqual(got, t["run_id"][m].tolist())
        self.assertGreater(len(got), 0)
        self.assertLess(len(got), int((t["block"] == "local").sum()))
        # A range outside (!=LO..HI) inside an alternative.
        r = ks("query", self.h5, "-w", "k!=0.2..0.8 | method=local_unweighted", "-c", "run_id", "-f", "csv")
        got = [int(x[0]) for x in read_csv(r.stdout)[1]]
        m = ((t["k"] < 0.2) | (t["k"] > 0.8) | (t["method"] == "local_unweighted")) & (t["done"] == 1)
        self.assertEqual(got, t["run_id"][m].tolist())
        r = ks("query", self.h5, "-w", "E<45 |")
        self.assertEqual(r.returncode, 2)
        self.assertIn("empty alternative", r.stderr)

    def test_group_by_with_aggregates(self):
        t = self.t
        r = ks("query", self.h5, "-w", "block=local", "--group-by", "method", "--agg",
               "min:E,argmin:E,count,mean:k,max:alpha1A", "-f", "csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        head, rows = read_csv(r.stdout)
        self.assertEqual(head, ["method", "min(E)", "argmin(E)", "count", "mean(k)", "max(alpha1A) [deg]"])
        methods = sorted(set(t["method"][t["block"] == "local"]))
        self.assertEqual([x[0] for x in rows], methods)
        for x in rows:
            m = (t["block"] == "local") & (t["method"] == x[0])
            i = np.nanargmin(np.where(m, t["E"], np.nan))
            self.assertEqual(float(x[1]), t["E"][i])
            self.assertEqual(int(x[2]), int(t["run_id"][i]))
            self.assertEqual(int(x[3]), int(m.sum()))
            self.assertAlmostEqual(float(x[4]), float(np.mean(t["k"][m])), places=12)
            self.assertAlmostEqual(float(x[5]), float(np.max(t["alpha1A"][m])) * D, places=9)

    def test_group_by_two_columns_and_table_trailer(self):
        t = self.t
        r = ks("query", self.h5, "-g", "block,method", "--agg", "count", "-f", "csv")
        head, rows = read_csv(r.stdout)
        self.assertEqual(head, ["block", "method", "count"])
        pairs = sorted(set(zip(t["block"], t["method"])))
        self.assertEqual([(x[0], x[1]) for x in rows], pairs)
        for x in rows:
            self.assertEqual(int(x[2]), int(((t["block"] == x[0]) & (t["method"] == x[1])).sum()))
        r = ks("query", self.h5, "-g", "method")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"of {len(set(t['method']))} groups of {len(t['E'])} rows", r.stdout)

    def test_group_by_errors(self):
        for args, what in ((["-g", "methd"], "did you mean 'method'"),
                           (["-g", "method", "--agg", "mn:E"], "did you mean 'min'"),
                           (["-g", "method", "--agg", "min:status"], "holds text"),
                           (["--agg", "min:E"], "--agg needs --group-by"),
                           (["-g", "method", "--sort", "E"], "--sort and --columns apply to rows")):
            with self.subTest(args):
                r = ks("query", self.h5, *args)
                self.assertEqual(r.returncode, 2, r.stdout)
                self.assertIn(what, r.stderr)

    def test_info_gives_a_drawn_axis_its_range(self):
        # The Latin-hypercube block's landscape dimension (its LHS axes advance together: the
        # dimension "sample", alpha1A's draws in run order a coordinate along it): info shows the
        # range of the draws.
        with h5py.File(self.h5, "r") as f:
            g = f["landscapes"]["drawn"]
            name = s(g.attrs["axes"][0])
            self.assertEqual(name, "sample")
            a = g["alpha1A"][()] * D
        drawn = self.t["alpha1A"][self.t["block"] == "drawn"] * D
        np.testing.assert_allclose(np.sort(a), np.sort(drawn), rtol=1e-12)
        r = ks("info", self.h5)
        self.assertEqual(r.returncode, 0, r.stderr)
        line = [x for x in r.stdout.splitlines() if "drawn: " + name in x]
        self.assertTrue(line, r.stdout)
        lo, hi = (f"{v:.6g}" for v in (a.min(), a.max()))
        self.assertIn(f"alpha1A ({len(a)}, drawn in {lo} .. {hi} deg)", line[0])


class OptimizationWhere(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.h5 = run_study_text(KS, cls.tmp.name, "o", OPTIMIZE)
        with h5py.File(cls.h5, "r") as f:
            e = f["optimizations"]["h1"]["evaluations"]
            cls.x, cls.obj = e["x"][()], e["objective"][()]
            cls.stage = np.array([s(v) for v in e["stage"][()]], dtype=object)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_where_sort_and_group_on_evaluations(self):
        thr = float(np.median(self.obj))
        r = ks("query", self.h5, "--optimization", "h1", "-w", f"objective<{thr!r} | stage=global",
               "--sort", "objective", "-f", "csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        head, rows = read_csv(r.stdout)
        m = (self.obj < thr) | (self.stage == "global")
        idx = np.nonzero(m)[0]
        idx = idx[np.argsort(self.obj[idx], kind="stable")]
        self.assertEqual([int(x[0]) for x in rows], idx.tolist())
        r = ks("query", self.h5, "--optimization", "h1", "-g", "stage", "--agg", "min:objective,count", "-f", "csv")
        head, rows = read_csv(r.stdout)
        self.assertEqual(head, ["stage", "min(objective)", "count"])
        for x in rows:
            m = self.stage == x[0]
            self.assertEqual(float(x[1]), float(np.min(self.obj[m])))
            self.assertEqual(int(x[2]), int(m.sum()))
        r = ks("query", self.h5, "--optimization", "h1", "-w", "alpha1A<-10", "-c", "index", "-f", "csv")
        got = [int(x[0]) for x in read_csv(r.stdout)[1]]
        self.assertEqual(got, np.nonzero(self.x[:, 0] * D < -10)[0].tolist())


if __name__ == "__main__":
    KS = sys.argv[1]
    unittest.main(argv=[sys.argv[0]] + sys.argv[3:], verbosity=2)
