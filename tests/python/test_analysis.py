"""End-to-end tests of analysis/: run the engine on small studies, then every plot command on the
output; the PNG exists, has the requested size, is not blank, and the numbers the script plotted
(--print-data) equal the file's as read here with h5py.

usage: /usr/bin/python3 test_analysis.py KINESWEEP_BINARY REPO_ROOT
"""
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

from e2e_common import OPTIMIZE as OPTIMIZE_COMMON, axis_dataset_name, history, runs_column
from e2e_common import ANALYSIS_ENV, analysis_command

KS = None
ROOT = None
D = 180.0 / math.pi

LANDSCAPE = """
[study]
name = "ana_landscape"
histories = "none"
[robot]
inertia = "thesis_m11"
[[block]]
name = "local"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { from = -26, to = 34, step = 4 }
k = { from = 0, to = 1, step = 0.125 }
"""

BASINS = """
[study]
name = "ana_basins"
histories = "none"
[[block]]
name = "basins"
kind = "ik"
problem = "scara"
lambda = 0.1
[block.axes]
method = ["newton", "lm", "halley"]
q0_1 = { from = -180, to = 180, count = 15 }
q0_2 = { from = -180, to = 180, count = 13 }
"""

# A coarse alpha1A x k landscape and an [[optimize]] block over the same two variables (seconds).
OPTIMIZE = OPTIMIZE_COMMON.replace('name = "e2e_optimize"', 'name = "ana_optimize"') + """[[optimize]]
name = "k_only"
preset = "1d"
variables = { k = [0, 1] }
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 10
"""


def h5str(v):
    return v.decode() if isinstance(v, bytes) else str(v)


class AnalysisTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.files = {}
        for name, text in (("landscape", LANDSCAPE), ("basins", BASINS), ("optimize", OPTIMIZE)):
            path = os.path.join(cls.tmp.name, name + ".toml")
            with open(path, "w") as f:
                f.write(text)
            cls.files[name] = cls._run(path)
        cls.files["table4"] = cls._run(os.path.join(ROOT, "studies", "thesis_table4.toml"))
        cls.files["convergence"] = cls._run(os.path.join(ROOT, "studies", "examples_convergence.toml"))

    @classmethod
    def _run(cls, study):
        out = os.path.join(cls.tmp.name, os.path.basename(study).replace(".toml", ".h5"))
        r = subprocess.run([KS, "run", study, "-o", out, "--overwrite", "-q"], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        return out

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def plot(self, command, h5, *extra, size=(640, 480)):
        png = os.path.join(self.tmp.name, f"{command}_{abs(hash(extra))}.png")
        r = subprocess.run(analysis_command(command, h5, "-o", png, "--size", f"{size[0]}x{size[1]}", "--print-data",
                                            *extra), capture_output=True, text=True, env=ANALYSIS_ENV)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.check_png(png, size)
        return json.loads(r.stdout)

    def check_png(self, png, size):
        import matplotlib.image as mpimg
        self.assertTrue(os.path.exists(png), png)
        img = mpimg.imread(png)
        self.assertEqual(img.shape[:2], (size[1], size[0]))
        self.assertGreater(float(np.var(img[..., :3])), 1e-3, "picture is blank")

    @staticmethod
    def nan_equal(a, b):
        a = np.array([[np.nan if v is None else v for v in row] for row in a], dtype=float)
        np.testing.assert_array_equal(a, np.asarray(b, dtype=float))

    # -------------------------------------------------------------------------------------------
    def test_landscape_fixed_method(self):
        d = self.plot("plot_landscape", self.files["landscape"], "--fix", "method=local_unweighted", "--thesis")
        with h5py.File(self.files["landscape"], "r") as f:
            g = f["landscapes"]["local"]
            self.assertEqual([h5str(x) for x in g.attrs["axes"]], ["method", "alpha1A", "k"])
            labels = h5str(g[axis_dataset_name("method")].attrs["unit"])[len("labels:"):].split(",")
            m = labels.index("local_unweighted")
            E = g["E"][()][m]          # alpha1A x k
            st = g["status_code"][()][m]
            want = np.where(st == 0, E, np.nan).T  # plotted as y=k rows, x=alpha1A columns
            np.testing.assert_allclose(d["x"]["values"], g["alpha1A"][()] * D, rtol=1e-13)
            np.testing.assert_array_equal(d["y"]["values"], g["k"][()])
        self.assertEqual((d["x"]["name"], d["y"]["name"]), ("alpha1A", "k"))
        self.nan_equal(d["z"], want)
        self.assertTrue(np.isnan(want).any(), "the test study should have unreachable cells")
        masked = np.array([[c is not None for c in row] for row in d["masked_status"]])
        np.testing.assert_array_equal(masked, np.isnan(want))
        self.assertIn("unreachable_start", {c for row in d["masked_status"] for c in row})
        self.assertAlmostEqual(d["best"]["value"], np.nanmin(want))
        self.assertEqual(d["thesis"][0]["case"], "2h")

    def test_landscape_reduced_min_and_log(self):
        d = self.plot("plot_landscape", self.files["landscape"], "--metric", "tau_inf", "--log",
                      "--x", "k", "--y", "alpha1A", "--reduce", "min")
        self.assertEqual(d["reduce"], "min")
        with h5py.File(self.files["landscape"], "r") as f:
            g = f["landscapes"]["local"]
            v = np.where(g["status_code"][()] == 0, g["tau_inf"][()], np.nan)
            with np.errstate(all="ignore"):
                import warnings
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    want = np.nanmin(v, axis=0)  # over method -> alpha1A x k = y x x
        self.nan_equal(d["z"], want)

    def test_landscape_convergence_fraction(self):
        d = self.plot("plot_landscape", self.files["basins"], "--metric", "convergence")
        with h5py.File(self.files["basins"], "r") as f:
            g = f["landscapes"]["basins"]
            want = g["converged"][()].mean(axis=0).T  # method x q0_1 x q0_2 -> q0_2 rows, q0_1 columns
            np.testing.assert_allclose(d["x"]["values"], g["q0_1"][()] * D, rtol=1e-13)
        self.nan_equal(d["z"], want)
        self.assertEqual(d["reduce"], "mean")

    def test_landscape_svg_and_errors(self):
        svg = os.path.join(self.tmp.name, "l.svg")
        r = subprocess.run(analysis_command("plot_landscape", self.files["landscape"], "-o", svg,
                                            "--fix", "method=local_weighted"),
                           capture_output=True, text=True, env=ANALYSIS_ENV)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(svg) as f:
            self.assertIn("<svg", f.read(2000))
        r = subprocess.run(analysis_command("plot_landscape", self.files["landscape"], "--fix", "method=nope"),
                           capture_output=True, text=True, env=ANALYSIS_ENV)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("local_weighted", r.stderr)

    def test_landscape_optimization_overlay(self):
        d = self.plot("plot_landscape", self.files["optimize"], "--optimization", "h1")
        o = d["optimization"]
        with h5py.File(self.files["optimize"], "r") as f:
            g = f["optimizations"]["h1"]
            self.assertEqual([h5str(v) for v in g.attrs["variables"]], ["alpha1A", "k"])
            x, stage = g["evaluations"]["x"][()], [h5str(v) for v in g["evaluations"]["stage"][()]]
            obj = g["evaluations"]["objective"][()]
            lf, lt = g["local"]["from"][()], g["local"]["to"][()]
            bx, bobj = g.attrs["best_x"], g.attrs["best_objective"]
        self.assertEqual((d["x"]["name"], d["y"]["name"]), ("alpha1A", "k"))
        np.testing.assert_allclose(o["points"]["x"], x[:, 0] * D, rtol=1e-13)  # degrees, as the plot's x
        np.testing.assert_array_equal(o["points"]["y"], x[:, 1])
        self.assertEqual(o["points"]["stage"], stage)
        self.assertEqual(set(stage), {"sweep", "global", "local"})
        np.testing.assert_array_equal(o["points"]["objective"], obj)
        self.assertEqual(len(o["paths"]), len(lf))
        np.testing.assert_allclose([p["from"] for p in o["paths"]], lf * [D, 1.0], rtol=1e-13)
        np.testing.assert_allclose([p["to"] for p in o["paths"]], lt * [D, 1.0], rtol=1e-13)
        self.assertAlmostEqual(o["best"]["x"], bx[0] * D, delta=1e-12)
        self.assertEqual(o["best"]["y"], bx[1])
        self.assertEqual(o["best"]["objective"], bobj)
        # Swapped axes: the overlay follows them.
        d = self.plot("plot_landscape", self.files["optimize"], "--optimization", "h1", "--x", "k", "--y", "alpha1A")
        np.testing.assert_array_equal(d["optimization"]["points"]["x"], x[:, 1])
        # Without --optimization: no overlay; a name that is not there, or other variables: an error.
        self.assertIsNone(self.plot("plot_landscape", self.files["optimize"])["optimization"])
        for name, want in (("nope", "h1, k_only"), ("k_only", "not the plotted axes")):
            r = subprocess.run(analysis_command("plot_landscape", self.files["optimize"], "--optimization", name, "-o",
                                                os.path.join(self.tmp.name, "bad.png")),
                               capture_output=True, text=True, env=ANALYSIS_ENV)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn(want, r.stderr)

    def test_reader_optimization(self):
        sys.path.insert(0, os.path.join(ROOT, "analysis"))
        from kinesweep import read as ksread
        with h5py.File(self.files["optimize"], "r") as f:
            g = f["optimizations"]["h1"]
            x = g["evaluations"]["x"][()]
            st = g["stages"]
            stages = [h5str(v) for v in st["name"][()]]
            sbx, sev = st["best_x"][()], st["evaluations"][()]
            a = dict(g.attrs)
            metrics = {h5str(m): g["best"].attrs[h5str(m)] for m in g["best"].attrs["metrics"]}
        with ksread.open_results(self.files["optimize"]) as r:
            self.assertEqual(r.optimizations(), ["h1", "k_only"])
            o = r.optimization("h1")
            self.assertEqual(o.units, ["rad", ""])
            np.testing.assert_array_equal(o.evaluations["x"], x)
            od = r.optimization("h1", degrees=True)
            self.assertEqual(od.units, ["deg", ""])
            np.testing.assert_allclose(od.evaluations["x"], x * [D, 1.0], rtol=1e-14)
            np.testing.assert_allclose(od.lower, [-30, 0], rtol=1e-14)
            np.testing.assert_allclose(od.best["x"], a["best_x"] * [D, 1.0], rtol=1e-14)
            self.assertEqual(od.best["objective"], a["best_objective"])
            self.assertEqual(list(od.best["metrics"]), list(metrics))
            for m, v in metrics.items():  # NaN: a metric the task has not (max_orientation_error of a planar path)
                np.testing.assert_array_equal(od.best["metrics"][m], v, err_msg=m)
            self.assertEqual(list(od.stages["name"]), stages)
            np.testing.assert_array_equal(od.stages["evaluations"], sev)
            np.testing.assert_allclose(od.stages["best_x"], sbx * [D, 1.0], rtol=1e-14)
            self.assertEqual(int(sev.sum()), od.n_evaluations)
            self.assertAlmostEqual(od.references["thesis_alpha1A"], -24.1, places=10)
            self.assertEqual(od.references["thesis_E"], 37.79)
            self.assertEqual(od.objective, "E")
            with self.assertRaises(KeyError):
                r.optimization("nope")

    def test_histories(self):
        d = self.plot("plot_histories", self.files["table4"], "--preset", "1a,2d", "--what", "tau,q,qd")
        with h5py.File(self.files["table4"], "r") as f:
            preset = runs_column(f["runs"]["preset"]).tolist()
            for case in ("1a", "2d"):
                run = preset.index(case)
                h = history(f, run)
                got = d["runs"][str(run)]
                self.assertIn(case, got["label"])
                np.testing.assert_array_equal(got["t"], h["t"][:, 0])
                np.testing.assert_array_equal(got["tau"], h["tau"])
                np.testing.assert_array_equal(got["qd"], h["qd"])  # rad/s, not converted
                np.testing.assert_allclose(got["q"], h["q"] * D, rtol=1e-13)

    def test_cases(self):
        d = self.plot("plot_cases", self.files["table4"])
        with h5py.File(self.files["table4"], "r") as f:
            preset = runs_column(f["runs"]["preset"]).tolist()
            E = f["runs"]["E"][()]
        self.assertEqual(d["cases"], preset)
        np.testing.assert_array_equal(d["kinesweep"], E)
        # The thesis' values: parsed from the engine's own table (engine/methods/closed_form/seed_cases.cpp).
        with open(os.path.join(ROOT, "engine", "methods", "closed_form", "seed_cases.cpp")) as f:
            src = f.read()
        thesis = {m.group(1): float(m.group(2)) for m in
                  re.finditer(r'\{"(\w+)",\s*"[^"]*",\s*\w+,\s*[-\d.]+,\s*[-\d.]+,\s*(?:\w+|\{[^}]*\}),\s*([\d.]+)', src)}
        self.assertEqual(len(thesis), 21)
        np.testing.assert_array_equal(d["thesis"], [thesis[c] for c in preset])
        d = self.plot("plot_cases", self.files["table4"], "--metric", "tau2_inf", "--cases", "1a,2d", "--log")
        self.assertEqual(d["cases"], ["1a", "2d"])
        self.assertEqual(d["thesis"], [32.31, 2135.90])

    def test_basins(self):
        d = self.plot("plot_basins", self.files["basins"], size=(900, 400))
        names = ["converged", "stalled", "singular", "max_iter", "cycle", "diverged", "unsupported", "no_solution"]
        with h5py.File(self.files["basins"], "r") as f:
            g = f["landscapes"]["basins"]
            labels = h5str(g[axis_dataset_name("method")].attrs["unit"])[len("labels:"):].split(",")
            st, sol, it = g["status_code"][()], g["solution"][()], g["iterations"][()]
        self.assertEqual([p["label"] for p in d["panels"]], labels)
        for m, p in enumerate(d["panels"]):
            want = [[(int(sol[m, i, j]) if names[int(st[m, i, j])] == "converged" and np.isfinite(sol[m, i, j])
                      else ("converged, other solution" if st[m, i, j] == 0 else names[int(st[m, i, j])]))
                     for i in range(st.shape[1])] for j in range(st.shape[2])]  # rows = q0_2
            self.assertEqual(p["class"], want)
            np.testing.assert_array_equal(np.array(p["iterations"], dtype=float), it[m].T)
            self.assertAlmostEqual(p["converged_fraction"], float(np.mean(st[m] == 0)))

    def test_convergence(self):
        d = self.plot("plot_convergence", self.files["convergence"])
        with h5py.File(self.files["convergence"], "r") as f:
            method = runs_column(f["runs"]["method"]).tolist()
            lam = f["runs"]["lambda"][()]
            self.assertEqual(len(d["runs"]), len(method))  # one line per (method, lambda)
            for run, got in d["runs"].items():
                h = history(f, int(run))
                np.testing.assert_array_equal(got["norm_F"], h["norm_F"][:, 0])
                np.testing.assert_array_equal(got["k"], h["k"][:, 0])
                self.assertEqual(got["method"], method[int(run)])
                if got["lambda"] is not None:
                    self.assertEqual(got["lambda"], lam[int(run)])

    def test_help_of_every_command(self):
        for s in ("plot_landscape", "plot_histories", "plot_cases", "plot_basins", "plot_convergence", "make_examples"):
            r = subprocess.run(analysis_command(s, "--help"), capture_output=True, text=True, env=ANALYSIS_ENV)
            self.assertEqual(r.returncode, 0, (s, r.stderr))
            self.assertIn("usage:", r.stdout)

    def test_reader_module(self):
        sys.path.insert(0, os.path.join(ROOT, "analysis"))
        from kinesweep import read as ksread
        with h5py.File(self.files["landscape"], "r") as f:
            done = f["runs"]["done"][()] == 1
            E, alpha = f["runs"]["E"][()][done], f["runs"]["alpha1A"][()][done]
        with ksread.open_results(self.files["landscape"]) as r:
            t = r.runs()
            np.testing.assert_array_equal(t["E"], E)
            self.assertEqual(t.units["alpha1A"], "rad")
            self.assertEqual(r.runs(degrees=True).units["alpha1A"], "deg")
            np.testing.assert_allclose(r.runs(degrees=True)["alpha1A"], alpha * D)
            ls = r.landscape("local")
            self.assertEqual([a.name for a in ls.axes], ["method", "alpha1A", "k"])
            self.assertEqual(ls.axes[0].labels, ["local_weighted", "local_unweighted"])
            self.assertEqual(ls.units["E"], "Nm")
        with ksread.open_results(self.files["table4"]) as r:
            h = r.history(0)
            self.assertEqual(h["tau"].shape[1], 3)
            self.assertEqual(h.units["tau"], "Nm")
        try:
            import pandas  # noqa: F401
        except ImportError:
            return
        df = ksread.read_runs(self.files["landscape"], pandas=True)
        np.testing.assert_array_equal(df["E"].to_numpy(), E)


if __name__ == "__main__":
    KS, ROOT = sys.argv[1], sys.argv[2]
    unittest.main(argv=[sys.argv[0]] + sys.argv[3:], verbosity=2)
