"""Tests of kinesweep.plot_runs (runs from /runs: scatter, slice, parallel coordinates), its row filter
kinesweep.where and kinesweep.plotting.is_log_spaced. The engine runs small random-axis, Latin-hypercube and IK
studies; every view's PNG exists, has the requested size and is not blank, and the numbers it plotted
(--print-data) equal the file's /runs as read here with h5py, masked by done and by the --where filter
computed here with numpy. The filter is also compared with `kinesweep query --where` on the same file.

usage: /usr/bin/python3 test_plot_runs.py KINESWEEP_BINARY REPO_ROOT
"""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

from e2e_common import ANALYSIS_ENV, analysis_command, run_study_text, runs_column

KS = None
ROOT = None
D = 180.0 / math.pi

# Blocks "zeta" then "alpha": the default block is the first in the file, not the first by name.
RANDOM = """
[study]
name = "pr_random"
histories = "none"
[robot]
inertia = "thesis_m11"
[[block]]
name = "zeta"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { random = { from = -45, to = 40, count = 8, seed = 3 } }
k = { random = { from = 0, to = 1, count = 3, seed = 5 } }
[[block]]
name = "alpha"
kind = "trajectory"
[block.axes]
alpha1A = [0, 10]
k = [0, 0.5]
"""

LHS = """
[study]
name = "pr_lhs"
histories = "none"
[robot]
inertia = "thesis_m11"
[[block]]
name = "cube"
kind = "trajectory"
method = "local_weighted"
lhs = { count = 30, seed = 2 }
[block.axes]
alpha1A = { lhs = { from = -45, to = 40 } }
k = { lhs = { from = 0, to = 1 } }
"""

IK = """
[study]
name = "pr_ik"
histories = "none"
[[block]]
name = "damping"
kind = "ik"
problem = "scara"
max_iter = 30
[block.axes]
method = ["lm", "lm_adaptive"]
lambda = { values = [0.001, 0.01, 0.1, 1, 10, 100] }
q0_1 = { random = { from = -180, to = 180, count = 4, seed = 1 } }
"""

GOOD = ("ok", "converged")


def h5str(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def read_runs(path):
    """/runs as h5py reads it: column -> array (text as str), and the units."""
    with h5py.File(path, "r") as f:
        g = f["runs"]
        cols, units = {}, {}
        for c in g:
            cols[c] = runs_column(g[c])
            units[c] = h5str(g[c].attrs.get("unit", ""))
    return cols, units


def shown(cols, units, name, mask):
    """A column's values under `mask` as the plots show them (angles in degrees)."""
    v = cols[name][mask]
    return v * D if units[name] == "rad" else v


def floats(values):
    return np.array([np.nan if v is None else v for v in values], dtype=float)


class WhereTest(unittest.TestCase):
    """kswhere.select on a table built here; expected masks written as numpy expressions."""

    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, os.path.join(ROOT, "analysis"))
        from kinesweep import read as ksread
        from kinesweep import where as kswhere
        cls.kswhere = kswhere
        rng = np.random.default_rng(7)
        n = 200
        t = ksread.Table()
        t["method"] = rng.choice(np.array(["lm", "newton", "halley"], dtype=object), n)
        t["alpha1A"] = np.radians(rng.uniform(-40, 40, n))
        t["E"] = rng.integers(20, 80, n).astype(float)  # on integers: the ends of ranges are hit
        t["E"][::17] = np.nan
        t["iterations"] = rng.integers(1, 50, n)
        t["status"] = np.where(rng.uniform(size=n) < 0.2, "diverged", "ok").astype(object)
        t.units.update(method="", alpha1A="rad", E="Nm", iterations="", status="")
        cls.t = t

    def sel(self, *exprs, degrees=True):
        return self.kswhere.select(self.t, list(exprs), degrees=degrees)

    def check(self, exprs, want, degrees=True):
        if "<=" in exprs[0] or ">=" in exprs[0] or ".." in exprs[0]:  # the case must tell < from <=
            self.assertTrue(np.any(self.t["E"] == 50) and np.any(self.t["E"] == 30) and np.any(self.t["E"] == 60))
        got = self.sel(*exprs, degrees=degrees)
        np.testing.assert_array_equal(got, want, err_msg=str(exprs))
        self.assertTrue(0 < want.sum() < len(want), f"{exprs}: the case should keep some rows, not all")

    def test_comparisons(self):
        t = self.t
        E, it, m = t["E"], t["iterations"], t["method"]
        with np.errstate(invalid="ignore"):
            self.check(["E<50"], E < 50)
            self.check(["E <= 50"], E <= 50)
            self.check(["E>50"], E > 50)
            self.check(["E>=50"], E >= 50)
            self.check(["E=50"], E == 50)
            self.check(["50>E"], E < 50)  # VALUE OP COL
            self.check(["iterations=7"], it == 7)
            self.check(["iterations==7"], it == 7)
            self.check(["iterations!=7"], it != 7)
            self.check(["iterations=3,7,9"], np.isin(it, [3, 7, 9]))
            self.check(["iterations!=3,7,9"], ~np.isin(it, [3, 7, 9]))
            self.check(["E=30..60"], (E >= 30) & (E <= 60))
            self.check(["E!=30..60"], (E < 30) | (E > 60))
            self.check(["30<E<=60"], (E > 30) & (E <= 60))
            self.check(["60>=E>30"], (E > 30) & (E <= 60))
            self.check(["E=nan"], np.isnan(E))
            self.check(["method=lm"], m == "lm")
            self.check(["method!=lm,halley"], m == "newton")
            self.check(["method<lm"], m == "halley")
            self.check(["E<50", "method=lm"], (E < 50) & (m == "lm"))

    def test_angles_in_degrees(self):
        a = self.t["alpha1A"]
        self.check(["alpha1A>10"], np.degrees(a) > 10)
        self.check(["-10<=alpha1A<=10"], np.abs(np.degrees(a)) <= 10)
        self.check(["alpha1A>0.1"], a > 0.1, degrees=False)

    def test_or_alternatives(self):
        t = self.t
        E, s, m = t["E"], t["status"], t["method"]
        with np.errstate(invalid="ignore"):
            self.check(["E<40 | status=diverged"], (E < 40) | (s == "diverged"))
            self.check(["E<40|status=diverged|method=halley"], (E < 40) | (s == "diverged") | (m == "halley"))
            self.check(["E<40 | status=diverged", "method=lm,newton"],
                       ((E < 40) | (s == "diverged")) & np.isin(m, ["lm", "newton"]))
            self.check(["E!=30..60 | method=lm"], (E < 30) | (E > 60) | (m == "lm"))

    def test_errors(self):
        W = self.kswhere.WhereError
        with self.assertRaises(W) as e:
            self.sel("alpha1a<3")
        self.assertIn("unknown column 'alpha1a'", str(e.exception))
        self.assertIn("did you mean 'alpha1A'?", str(e.exception))
        with self.assertRaises(W) as e:
            self.sel("E<40 | statsu=diverged")
        self.assertIn("did you mean 'status'?", str(e.exception))
        for bad in ("E<abc", "E", "E<>3", "E<", "3=E", "E<40 |", "10<E>3", "E=1..x"):
            with self.assertRaises(W, msg=bad):
                self.sel(bad)

    def test_unheld_value_notes(self):
        notes = self.kswhere.unheld_value_notes(self.t, ["method=lmm,newton"])
        self.assertEqual(len(notes), 1)
        self.assertIn("did you mean 'lm'?", notes[0])

    def test_is_log_spaced(self):
        sys.path.insert(0, os.path.join(ROOT, "analysis"))
        from kinesweep import plotting as ksplot
        rng = np.random.default_rng(3)
        self.assertTrue(ksplot.is_log_spaced(np.repeat([1e-3, 1e-2, 0.1, 1, 10, 100], 4)))
        self.assertTrue(ksplot.is_log_spaced(10 ** rng.uniform(-3, 2, 50)))
        self.assertFalse(ksplot.is_log_spaced(rng.uniform(1e-3, 100, 50)))   # uniform: linear
        self.assertFalse(ksplot.is_log_spaced(np.linspace(1, 1000, 12)))
        self.assertFalse(ksplot.is_log_spaced([1, 2, 4, 8, 16, 32]))         # under 2 decades
        self.assertFalse(ksplot.is_log_spaced([-1, 1e-3, 1, 100]))          # not all positive
        self.assertFalse(ksplot.is_log_spaced([0, 1e-3, 1, 100]))
        self.assertFalse(ksplot.is_log_spaced([5.0, 5.0]))


class PlotRunsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.files = {}
        for name, text in (("random", RANDOM), ("lhs", LHS), ("ik", IK)):
            cls.files[name] = run_study_text(KS, cls.tmp.name, name, text)
        # An interrupted sweep: every third row of block zeta not done (FORMAT.md: done = 0 rows are not
        # results, whatever they hold).
        cls.files["partial"] = os.path.join(cls.tmp.name, "partial.h5")
        shutil.copy(cls.files["random"], cls.files["partial"])
        with h5py.File(cls.files["partial"], "r+") as f:
            done = f["runs"]["done"][()]
            done[::3] = 0
            f["runs"]["done"][...] = done
        cls.n = 0

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def run_command(self, h5, *extra, size=(720, 540)):
        PlotRunsTest.n += 1
        png = os.path.join(self.tmp.name, f"plot_runs_{self.n}.png")
        r = subprocess.run(analysis_command("plot_runs", h5, "-o", png, "--size", f"{size[0]}x{size[1]}",
                                            "--print-data", *extra), capture_output=True, text=True, env=ANALYSIS_ENV)
        return r, png

    def plot(self, h5, *extra, size=(720, 540)):
        r, png = self.run_command(h5, *extra, size=size)
        self.assertEqual(r.returncode, 0, r.stderr)
        import matplotlib.image as mpimg
        self.assertTrue(os.path.exists(png), png)
        img = mpimg.imread(png)
        self.assertEqual(img.shape[:2], (size[1], size[0]))
        self.assertGreater(float(np.var(img[..., :3])), 1e-3, "picture is blank")
        return json.loads(r.stdout)

    def expected_rows(self, name, block):
        cols, units = read_runs(self.files[name])
        mask = (cols["done"] == 1) & (cols["block"] == block)
        return cols, units, mask

    def check_panel(self, panel, cols, units, mask, x, y):
        np.testing.assert_array_equal(panel["run_ids"], cols["run_id"][mask])
        self.assertEqual(panel["status"], list(cols["status"][mask]))
        for key, name in (("x", x), ("y", y)):
            want = shown(cols, units, name, mask)
            if want.dtype == object:
                self.assertEqual(panel[key], list(want))
            else:
                np.testing.assert_allclose(floats(panel[key]), want, rtol=1e-12, equal_nan=True)

    # --- each study shape x each view ------------------------------------------------------------
    def test_scatter_one_parameter(self):
        for name, block, x, metric in (("random", "zeta", "alpha1A", "E"), ("lhs", "cube", "k", "E"),
                                       ("ik", "damping", "q0_1", "iterations")):
            cols, units, mask = self.expected_rows(name, block)
            d = self.plot(self.files[name], "--x", x)
            self.assertEqual((d["block"], d["metric"]["name"]), (block, metric))
            self.assertEqual(len(d["panels"]), 1)
            self.check_panel(d["panels"][0], cols, units, mask, x, metric)
            self.assertEqual(d["n_failed"], int(np.sum(~np.isin(cols["status"][mask], GOOD))))

    def test_scatter_two_parameters_failed_runs_outside_colour_scale(self):
        for name, block in (("random", "zeta"), ("lhs", "cube")):
            cols, units, mask = self.expected_rows(name, block)
            d = self.plot(self.files[name], "--x", "alpha1A", "--y", "k", "--metric", "tau_inf")
            p = d["panels"][0]
            self.check_panel(p, cols, units, mask, "alpha1A", "k")
            np.testing.assert_array_equal(floats(p["colour"]), cols["tau_inf"][mask])
            ok = np.isin(cols["status"][mask], GOOD)
            good_values = cols["tau_inf"][mask][ok]
            self.assertEqual(d["colour_range"], [float(np.nanmin(good_values)), float(np.nanmax(good_values))])
            self.assertEqual(d["axes"]["colour"]["unit"], "Nm")
        # IK runs stopped at max_iter hold the largest iteration counts: outside the colour range
        cols, units, mask = self.expected_rows("ik", "damping")
        d = self.plot(self.files["ik"], "--x", "q0_1", "--y", "lambda")
        self.check_panel(d["panels"][0], cols, units, mask, "q0_1", "lambda")
        ok = np.isin(cols["status"][mask], GOOD)
        it = cols["iterations"][mask]
        self.assertGreater(it[~ok].max(), it[ok].max(), "the IK study should have max_iter runs")
        self.assertEqual(d["colour_range"], [float(it[ok].min()), float(it[ok].max())])
        self.assertEqual(d["axes"]["y"]["scale"], "log")
        # the random study reaches past the workspace: failed runs exist and are reported as such
        cols, _, mask = self.expected_rows("random", "zeta")
        self.assertTrue((~np.isin(cols["status"][mask], GOOD)).any(), "the random study should have failed runs")

    def test_slice(self):
        for name, block, metric in (("random", "zeta", "E"), ("lhs", "cube", "E"), ("ik", "damping", "iterations")):
            cols, units, mask = self.expected_rows(name, block)
            d = self.plot(self.files[name], "--view", "slice")
            # default parameters: the parameter columns taking more than one value among the block's rows
            with h5py.File(self.files[name], "r") as f:
                g = f["runs"]
                params = [h5str(c) for c in g.attrs["columns"] if h5str(g[h5str(c)].attrs["role"]) == "parameter"]
            swept = [c for c in params
                     if len(set(cols[c][mask]) if cols[c].dtype == object else np.unique(cols[c][mask])) > 1]
            self.assertEqual([p["name"] for p in d["params"]], swept)
            self.assertEqual([p["param"] for p in d["panels"]], swept)
            self.assertEqual(d["colour"]["name"], "run_id")
            for p in d["panels"]:
                self.check_panel(p, cols, units, mask, p["param"], metric)
                np.testing.assert_array_equal(p["colour"], cols["run_id"][mask])

    def test_parcoords(self):
        for name, block, metric in (("random", "zeta", "E"), ("lhs", "cube", "E"), ("ik", "damping", "iterations")):
            cols, units, mask = self.expected_rows(name, block)
            d = self.plot(self.files[name], "--view", "parcoords", size=(900, 500))
            names = [a["name"] for a in d["axes"]]
            self.assertEqual(names[-1], metric)
            np.testing.assert_array_equal(d["run_ids"], cols["run_id"][mask])
            for a in d["axes"]:
                want = shown(cols, units, a["name"], mask)
                got = d["values"][a["name"]]
                if a["scale"] == "category":
                    self.assertEqual(got, list(want))
                    self.assertEqual(a["categories"], list(dict.fromkeys(want)))
                else:
                    np.testing.assert_allclose(floats(got), want, rtol=1e-12, equal_nan=True)
            if name != "lhs":
                self.assertIn("method", names)  # a text axis

    def test_log_axis_for_lambda(self):
        d = self.plot(self.files["ik"], "--view", "slice")
        scales = {p["name"]: p["scale"] for p in d["params"]}
        self.assertEqual(scales["lambda"], "log")
        self.assertEqual(scales["q0_1"], "linear")
        self.assertEqual(scales["method"], "category")
        d = self.plot(self.files["ik"], "--x", "lambda")
        self.assertEqual(d["axes"]["x"]["scale"], "log")
        d = self.plot(self.files["ik"], "--view", "parcoords", "--params", "lambda,q0_1")
        self.assertEqual([a["scale"] for a in d["axes"]], ["log", "linear", "linear"])
        d = self.plot(self.files["random"], "--x", "k")
        self.assertEqual(d["axes"]["x"]["scale"], "linear")

    # --- filters, facets, blocks, unfinished files --------------------------------------------------
    def test_where_or_form(self):
        cols, units, mask = self.expected_rows("random", "zeta")
        E, st = cols["E"], cols["status"]
        with np.errstate(invalid="ignore"):
            want = mask & ((E < 55) | (st == "unreachable_start")) & (cols["method"] == "local_weighted") \
                & (cols["alpha1A"] * D < 10)
        self.assertTrue(0 < want.sum() < mask.sum())
        self.assertTrue((want & (st == "unreachable_start")).any(), "the OR should bring in failed runs")
        d = self.plot(self.files["random"], "--view", "slice", "-w", "E<55 | status=unreachable_start",
                      "--where", "method=local_weighted", "-w", "alpha1A<10")
        for p in d["panels"]:
            self.check_panel(p, cols, units, want, p["param"], "E")

    def test_where_matches_kinesweep_query(self):
        cols, _, mask = self.expected_rows("random", "zeta")
        for expr in ("E<55", "-10<alpha1A<=30", "method!=local_weighted", "k=0.2..0.8", "alpha1A!=-10..10",
                     "60>=E"):
            q = subprocess.run([KS, "query", self.files["random"], "-w", expr, "-w", "block=zeta", "--columns",
                                "run_id", "--format", "json"], capture_output=True, text=True)
            self.assertEqual(q.returncode, 0, q.stderr)
            ids = [row["run_id"] for row in json.loads(q.stdout)["rows"]]
            d = self.plot(self.files["random"], "-w", expr, "--x", "k")
            self.assertEqual(d["panels"][0]["run_ids"], ids, expr)

    def test_facets(self):
        cols, units, mask = self.expected_rows("random", "zeta")
        d = self.plot(self.files["random"], "--x", "alpha1A", "--y", "k", "--facet", "method")
        methods = list(dict.fromkeys(cols["method"][mask]))
        self.assertEqual(d["facets"], methods)
        self.assertEqual([p["facet"] for p in d["panels"]], methods)
        for p in d["panels"]:
            self.check_panel(p, cols, units, mask & (cols["method"] == p["facet"]), "alpha1A", "k")
        d = self.plot(self.files["random"], "--view", "slice", "--facet", "method", size=(900, 700))
        with h5py.File(self.files["random"], "r") as f:
            order = [h5str(c) for c in f["runs"].attrs["columns"]]
        self.assertEqual([p["name"] for p in d["params"]],  # the swept parameters but the facet, file order
                         [c for c in order if c in ("alpha1A", "k")])
        self.assertEqual(len(d["panels"]), 2 * len(methods))
        for p in d["panels"]:
            self.check_panel(p, cols, units, mask & (cols["method"] == p["facet"]), p["param"], "E")
        # --facet block: every block of the run kind, in file order
        d = self.plot(self.files["random"], "--facet", "block", "--x", "k")
        self.assertEqual(d["facets"], ["zeta", "alpha"])
        for p in d["panels"]:
            self.check_panel(p, cols, units, (cols["done"] == 1) & (cols["block"] == p["facet"]), "k", "E")

    def test_default_block_is_first_in_file(self):
        cols, units = read_runs(self.files["random"])
        self.assertEqual(cols["block"][0], "zeta")
        d = self.plot(self.files["random"], "--view", "parcoords")
        self.assertEqual(d["block"], "zeta")
        np.testing.assert_array_equal(d["run_ids"], cols["run_id"][cols["block"] == "zeta"])
        d = self.plot(self.files["random"], "--block", "alpha", "--x", "k")
        self.check_panel(d["panels"][0], cols, units, cols["block"] == "alpha", "k", "E")

    def test_partial_file_plots_done_rows_only(self):
        cols, units, mask = self.expected_rows("partial", "zeta")
        self.assertTrue(0 < mask.sum() < np.sum(cols["block"] == "zeta"))
        for view in ("scatter", "slice", "parcoords"):
            d = self.plot(self.files["partial"], "--view", view)
            ids = d["run_ids"] if view == "parcoords" else d["panels"][0]["run_ids"]
            np.testing.assert_array_equal(ids, cols["run_id"][mask])
        d = self.plot(self.files["partial"], "--x", "alpha1A")
        self.check_panel(d["panels"][0], cols, units, mask, "alpha1A", "E")

    def test_nothing_to_draw(self):
        r, png = self.run_command(self.files["random"], "-w", "E<-1")
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("nothing to draw", r.stderr)
        self.assertFalse(os.path.exists(png))

    def test_errors(self):
        for extra, text in ((["--block", "zetta"], "did you mean 'zeta'?"),
                            (["--metric", "tau_in"], "did you mean 'tau_inf'?"),
                            (["--x", "alpha1a"], "did you mean 'alpha1A'?"),
                            (["--view", "slice", "--params", "k,mthod"], "did you mean 'method'?"),
                            (["-w", "E<50 | alpha1a>3"], "did you mean 'alpha1A'?"),
                            (["-w", "E<fifty"], "is not a number"),
                            (["--facet", "E"], "a facet column is text")):
            r, png = self.run_command(self.files["random"], *extra)
            self.assertEqual(r.returncode, 2, (extra, r.stderr))
            self.assertIn(text, r.stderr, extra)
            self.assertFalse(os.path.exists(png), extra)

    def test_help(self):
        r = subprocess.run(analysis_command("plot_runs", "--help"), capture_output=True, text=True, env=ANALYSIS_ENV)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("--view", r.stdout)


if __name__ == "__main__":
    KS, ROOT = sys.argv[1], sys.argv[2]
    unittest.main(argv=[sys.argv[0]] + sys.argv[3:], verbosity=2)
