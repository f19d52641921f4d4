"""The best runs verified against their grid (/verification, written by `kinesweep run`) and
`kinesweep compare`:
- each trajectory block's best good run (lowest E, lowest torque_sq_integral) of each method (and end
  state) is in /verification; its
  grid 3 value is its /runs value, and its grid 1 and 2 values are those of the same run computed
  by a study of its own at dt/4, dt/2 (and 4K, 2K knots), read from that study's /runs;
- the observed order, Richardson value and GCI of each monotone row follow from its three values
  (Roache's formulas, computed here with numpy); divergent and oscillatory rows carry no number;
- the table is the same bit for bit whatever the thread count; --no-verify-best writes none;
- `kinesweep run` and `kinesweep info` print "E = ... (GCI ... %...)";
- compare: the best good run per group, runs ending at rest never ranked with runs free to move
  (unless --end any), the margin to the next group with the sum of both uncertainties; its JSON
  equals kinesweep.compare.compare() of the Python package, on a small study and on the shipped
  thesis_table4; --where selects rows as query's; bad --by, --metric and --where are refused with
  exit status 2.

usage: /usr/bin/python3 test_compare.py KINESWEEP_BINARY SOURCE_DIR
"""
import json
import math
import os
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import TempDirTest, runs_column

KS = None
SOURCE = None

STUDY = """
[study]
name = "cmp"
histories = "none"

[[block]]
name = "local"
kind = "trajectory"
k = 0.05
{dt}
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = [-24.25, -20]

[[block]]
name = "vertex"
kind = "trajectory"
method = "vertex_alpha"
alpha1A = -23.75
vertex_alpha = [13.30, 17.28, -12.44, -16.12]
{dt}

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
global_start = "vertex"
alpha1A = -23.75
vertex_alpha = [13.30, 17.28, -12.44, -16.12]
knots = {knots}
{dt}
[block.axes]
end_state = ["rest", "free"]
"""


def run(*args, check=True):
    p = subprocess.run([KS, *args], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"kinesweep {' '.join(args)} exited {p.returncode}:\n{p.stdout}\n{p.stderr}")
    return p


def verification(path):
    """/verification as read by h5py: dataset name -> array (text as str)."""
    with h5py.File(path, "r") as f:
        if "verification" not in f:
            return None
        g = f["verification"]
        return {k: (g[k].asstr()[()] if g[k].dtype.kind == "O" else g[k][()]) for k in g
                if isinstance(g[k], h5py.Dataset) and g[k].shape != ()}, dict(g.attrs)


def json_rows(path, *args):
    return json.loads(run("compare", path, "--format", "json", *args).stdout)["rows"]


def same_cell(a, b):
    if a is None or b is None:
        a = None if isinstance(a, float) and math.isnan(a) else a
        b = None if isinstance(b, float) and math.isnan(b) else b
        return a is None and b is None
    if isinstance(a, float) or isinstance(b, float):
        return a == b or abs(a - b) <= 1e-12 * max(abs(a), abs(b))
    return a == b


class CompareTest(TempDirTest):
    @classmethod
    def setUpClass(cls):
        import tempfile
        cls.tmpdir = tempfile.TemporaryDirectory()
        d = cls.tmpdir.name
        cls.study = os.path.join(d, "cmp.toml")
        with open(cls.study, "w") as f:
            f.write(STUDY.format(dt="", knots=10))
        cls.h5 = os.path.join(d, "cmp.h5")
        cls.out = run("run", cls.study, "-o", cls.h5, "-q", "--threads", "2").stdout
        cls.v, cls.vattrs = verification(cls.h5)
        with h5py.File(cls.h5, "r") as f:
            cls.runs = {c: runs_column(f["runs"][c]) for c in ("run_id", "block", "method", "status", "end_state",
                                                               "E", "tau_inf", "torque_sq_integral", "opt_objective")}

    @classmethod
    def tearDownClass(cls):
        cls.tmpdir.cleanup()

    def refined(self, name, dt="", knots=10):
        """/runs of the study computed again with `dt` (a `dt = ...` line) or `knots`."""
        p = self.write(name + ".toml", STUDY.format(dt=dt, knots=knots))
        h5 = os.path.join(self.dir, name + ".h5")
        run("run", p, "-o", h5, "-q", "--no-verify-best")
        with h5py.File(h5, "r") as f:
            self.assertNotIn("verification", f)
            return {c: runs_column(f["runs"][c]) for c in ("E", "tau_inf", "torque_sq_integral", "opt_objective",
                                                           "status")}

    def test_best_runs_verified(self):
        v, r = self.v, self.runs
        ok = r["status"] == "ok"
        expected = set()
        for block in ("local", "vertex", "global"):
            for method in set(r["method"][r["block"] == block]):
                ends = set(r["end_state"][r["block"] == block]) if method == "global_spline" else {None}
                for end in ends:
                    sel = ok & (r["block"] == block) & (r["method"] == method)
                    if end is not None:
                        sel &= r["end_state"] == end
                    ids = r["run_id"][sel]
                    for q in ("E", "torque_sq_integral"):  # the lowest of each, ties to the lower run id
                        expected.add(int(ids[np.lexsort((ids, r[q][sel]))][0]))
        self.assertEqual(set(int(x) for x in v["run"]), expected)
        self.assertEqual(self.vattrs["safety_factor"], 1.25)
        for i in range(len(v["run"])):
            run_id, q = int(v["run"][i]), v["quantity"][i]
            self.assertEqual(v["value"][i, 2], r[q][run_id], (run_id, q))  # grid 3: the run as stored
            self.assertEqual(v["status_3"][i], "ok")
            refinement = v["refinement"][i]
            self.assertEqual(v["dt"][i, 2], 1e-3)
            if refinement == "dt":
                np.testing.assert_array_equal(v["dt"][i], [2.5e-4, 5e-4, 1e-3])
            else:
                self.assertEqual(v["method"][i], "global_spline")
                np.testing.assert_array_equal(v["knots"][i], [40, 20, 10])
            if v["method"][i] != "global_spline":
                self.assertTrue(np.all(np.isnan(v["knots"][i])))
        for q in ("E", "tau_inf", "torque_sq_integral"):
            self.assertIn(q, set(v["quantity"]))
        self.assertEqual(set(v["quantity"][v["method"] != "global_spline"]), {"E", "tau_inf", "torque_sq_integral"})
        self.assertIn("opt_objective", set(v["quantity"][v["method"] == "global_spline"]))

    def test_refined_values_are_the_runs_of_refined_studies(self):
        v = self.v
        for dt, grid in (("dt = 0.00025", 0), ("dt = 0.0005", 1)):
            other = self.refined("dt%d" % grid, dt=dt)
            for i in np.flatnonzero(v["refinement"] == "dt"):
                run_id, q = int(v["run"][i]), v["quantity"][i]
                self.assertEqual(v["value"][i, grid], other[q][run_id], (dt, run_id, q))
                self.assertEqual(v[f"status_{grid + 1}"][i], other["status"][run_id])
        for knots, grid in ((40, 0), (20, 1)):
            other = self.refined("k%d" % knots, knots=knots)
            for i in np.flatnonzero(v["refinement"] == "knots"):
                run_id, q = int(v["run"][i]), v["quantity"][i]
                self.assertEqual(v["value"][i, grid], other[q][run_id], (knots, run_id, q))

    def test_gci_follows_from_the_three_values(self):
        v = self.v
        self.assertTrue(set(v["convergence"]) <= {"monotone", "unchanged", "oscillatory", "divergent", "not_enough"})
        for i in range(len(v["run"])):
            f1, f2, f3 = v["value"][i]
            c = v["convergence"][i]
            if c == "monotone":
                e21, e32 = f2 - f1, f3 - f2
                self.assertTrue(0 <= e21 / e32 < 1)
                p = math.log(e32 / e21) / math.log(2)
                self.assertAlmostEqual(v["order"][i], p, delta=1e-9 * abs(p))
                rp = 2.0 ** p
                self.assertAlmostEqual(v["extrapolated"][i], f1 + (f1 - f2) / (rp - 1), delta=1e-12 * abs(f1))
                self.assertAlmostEqual(v["gci_fine"][i], 1.25 * abs(e21 / f1) / (rp - 1), delta=1e-9 * v["gci_fine"][i])
                self.assertAlmostEqual(v["gci_coarse"][i], 1.25 * abs(e32 / f3) * rp / (rp - 1),
                                       delta=1e-9 * v["gci_coarse"][i])
            elif c in ("divergent", "oscillatory"):
                e21, e32 = f2 - f1, f3 - f2
                self.assertTrue(e32 == 0 or e21 / e32 >= 1 or e21 / e32 < 0)
                for k in ("order", "extrapolated", "gci_fine", "gci_coarse"):
                    self.assertTrue(math.isnan(v[k][i]), (k, c))
        self.assertIn("monotone", set(v["convergence"][v["quantity"] == "E"]))

    def test_netcdf_reads_the_table(self):
        import netCDF4
        with netCDF4.Dataset(self.h5, "r") as nc:
            nc.set_auto_mask(False)
            g = nc.groups["verification"]
            self.assertEqual(g.dimensions["grid"].size, 3)
            self.assertEqual(g.dimensions["verification_row"].size, len(self.v["run"]))
            np.testing.assert_array_equal(g["value"][:], self.v["value"])
            np.testing.assert_array_equal(g["run"][:], self.v["run"])
            self.assertEqual(list(g["quantity"][:]), list(self.v["quantity"]))
            self.assertEqual(g["dt"].units, "s")

    def test_printed_by_run_and_info(self):
        self.assertIn("best runs against the grid", self.out)
        self.assertRegex(self.out, r"E = [0-9.]+ Nm \(GCI [0-9.e+-]+ %")
        info = run("info", self.h5).stdout
        self.assertRegex(info, r"E = [0-9.]+ Nm \(GCI [0-9.e+-]+ %")
        for i in np.flatnonzero(self.v["convergence"] == "divergent"):
            self.assertIn(f"{self.v['quantity'][i]} diverges (", self.out)

    def test_threads_and_switch(self):
        h5 = os.path.join(self.dir, "one.h5")
        run("run", self.study, "-o", h5, "-q", "--threads", "1")
        one, _ = verification(h5)
        self.assertEqual(sorted(one), sorted(self.v))
        for k in one:
            if one[k].dtype.kind == "f":
                self.assertEqual(one[k].tobytes(), self.v[k].tobytes(), k)
            else:
                np.testing.assert_array_equal(one[k], self.v[k], k)
        off = os.path.join(self.dir, "off.h5")
        out = run("run", self.study, "-o", off, "-q", "--no-verify-best").stdout
        self.assertNotIn("against the grid", out)
        self.assertIsNone(verification(off))
        self.assertEqual(json_rows(off)[0]["grid"], "none")

    def check_python_equals_cli(self, path, *args, **kw):
        sys.path.insert(0, os.path.join(SOURCE, "analysis"))
        from kinesweep.compare import compare
        cli = json_rows(path, *args)
        py = compare(path, **kw)
        self.assertEqual(len(cli), len(py))
        for a, b in zip(cli, py):
            self.assertEqual(sorted(a), sorted(b))
            for k in a:
                self.assertTrue(same_cell(a[k], b[k]), (k, a[k], b[k], a))
        return cli

    def test_compare_like_for_like(self):
        rows = self.check_python_equals_cli(self.h5, "--metric", "E", "--metric", "torque_sq_integral",
                                            metrics=["E", "torque_sq_integral"])
        r = self.runs
        ok = r["status"] == "ok"
        for row in rows:
            self.assertIn(row["end"], ("rest", "free"))
            method = row["method"]
            # the best good run of its method among the runs of its end condition
            if method == "global_spline":
                sel = ok & (r["method"] == method) & (r["end_state"] == row["end"])
            else:
                self.assertEqual(row["end"], "rest" if method == "vertex_alpha" else "free")
                sel = ok & (r["method"] == method)
            self.assertEqual(row["value"], float(np.min(r[row["metric"]][sel])))
            self.assertEqual(r[row["metric"]][row["run"]], row["value"])
            if row["verdict"] != "last":
                self.assertEqual(row["margin"], next(x["value"] for x in rows if x["end"] == row["end"] and
                                                     x["metric"] == row["metric"] and x["rank"] == row["rank"] + 1)
                                 - row["value"])
                self.assertGreaterEqual(row["margin"], 0)
            if row["metric"] in ("E", "torque_sq_integral"):  # every group's best of these is verified
                self.assertNotEqual(row["grid"], "none", row)
            if row["grid"] == "converged":
                self.assertAlmostEqual(row["uncertainty"], row["gci"] / 100 * abs(row["value"]), delta=1e-15)
        free = [x for x in rows if x["end"] == "free" and x["metric"] == "E"]
        rest = [x for x in rows if x["end"] == "rest" and x["metric"] == "E"]
        self.assertEqual({x["method"] for x in free}, {"local_weighted", "local_unweighted", "global_spline"})
        self.assertEqual({x["method"] for x in rest}, {"vertex_alpha", "global_spline"})
        only_rest = self.check_python_equals_cli(self.h5, "--end", "rest", end="rest")
        self.assertEqual(only_rest, [x for x in json_rows(self.h5) if x["end"] == "rest"])
        mixed = self.check_python_equals_cli(self.h5, "--end", "any", end="any")
        self.assertEqual({x["end"] for x in mixed}, {"any"})
        self.assertEqual(len(mixed), 4)  # one row per method: its best over both end conditions
        by_block = self.check_python_equals_cli(self.h5, "--by", "block", by="block")
        self.assertEqual({x["block"] for x in by_block}, {"local", "vertex", "global"})
        no_global = self.check_python_equals_cli(self.h5, "--where", "block!=global", "-w", "alpha1A<0",
                                                 where=["block!=global", "alpha1A<0"])
        self.assertEqual({x["method"] for x in no_global}, {"local_weighted", "local_unweighted", "vertex_alpha"})
        text = run("compare", self.h5).stdout
        self.assertIn("margin", text)
        self.assertIn("global_spline", text)

    def test_compare_refuses_bad_arguments(self):
        p = run("compare", self.h5, "--by", "methd", check=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("did you mean 'method'", p.stderr)
        p = run("compare", self.h5, "--metric", "Ee", check=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("not a numeric metric", p.stderr)
        p = run("compare", self.h5, "--where", "methd=global_spline", check=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("methd", p.stderr)
        p = run("compare", self.h5, "--end", "stopped", check=False)
        self.assertEqual(p.returncode, 2)
        p = run("compare", os.path.join(self.dir, "missing.h5"), check=False)
        self.assertEqual(p.returncode, 1)

    def test_mixed_kinds_of_a_format_3_file(self):
        # a file of trajectory and IK runs, without /verification: each kind ranked by its own
        # objective among its own good status
        rows = self.check_python_equals_cli(os.path.join(SOURCE, "tests", "format3", "mixed_v3.h5"))
        self.assertEqual({(x["kind"], x["metric"]) for x in rows}, {("ik", "iterations"), ("trajectory", "E")})
        self.assertEqual({x["end"] for x in rows if x["kind"] == "ik"}, {""})
        self.assertEqual({x["grid"] for x in rows}, {"none"})

    def test_thesis_table4(self):
        h5 = os.path.join(self.dir, "t4.h5")
        out = run("run", os.path.join(SOURCE, "studies", "thesis_table4.toml"), "-o", h5, "-q",
                  "--histories", "none").stdout
        self.assertIn("(GCI", out)
        rows = self.check_python_equals_cli(h5, "--metric", "E", "--metric", "tau_inf",
                                            metrics=["E", "tau_inf"])
        methods = {x["method"] for x in rows}
        self.assertEqual(methods, {"local_weighted", "local_unweighted", "vertex_alpha"})
        for x in rows:
            if x["metric"] == "E":
                self.assertNotEqual(x["grid"], "none", x)
        sums = self.check_python_equals_cli(h5, "--metric", "torque_sq_integral", "-w", "method!=vertex_alpha",
                                            metrics=["torque_sq_integral"], where="method!=vertex_alpha")
        self.assertEqual([x["grid"] for x in sums], ["converged", "converged"])


if __name__ == "__main__":
    KS = os.path.abspath(sys.argv[1])
    SOURCE = os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"])
