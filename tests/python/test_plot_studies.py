"""Every shipped study (studies/*.toml, the examples_*.toml among them) plus a random-axis study, a
Latin-hypercube study and a planar 3R IK study, each drawn by every plot command that applies to its
file: the picture exists and is not blank, and where a command does not apply it exits non-zero with a
message (never a traceback). What applies is decided from the file, read here with h5py: landscapes
with two swept numeric axes (plot_landscape), IK landscapes over (q0_1, q0_2) (plot_basins), trajectory
histories (plot_histories), IK histories (plot_convergence), preset rows (plot_cases), landscapes over
(alpha1A, k) (compare_landscapes). Then the commands' choices are checked against the file: the default
block (file order), log-scaled axes, faceting, round contour levels, joint units, one colour per run.

usage: /usr/bin/python3 test_plot_studies.py KINESWEEP_BINARY REPO_ROOT [--shipped DIR]
(--shipped: the shipped studies' results files as regression_hashes.py --workdir DIR left them; a
study found there is not run again)
(KS_KEEP_PLOTS=1 keeps the pictures and names their directory)
"""
import glob
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import types
import unittest

import h5py
import numpy as np

from e2e_common import ANALYSIS_ENV, Histories, analysis_command, axis_dataset_name, runs_column
from regression_hashes import FULL_HISTORIES

KS = None
ROOT = None
THREADS = "2"
# histories per study: the regression manifest's full ones, a sampled one for the 7-DOF square, else none
HISTORIES_BEYOND_MANIFEST = {"arm7_square": "every=10"}
HISTORIES = {**{s: "full" for s in FULL_HISTORIES}, **HISTORIES_BEYOND_MANIFEST}
# The results files regression_hashes wrote (the CTest fixture shipped_results; same command and
# histories), used instead of running those studies again; None: every study runs here.
SHIPPED = None

RANDOM = """
[study]
name = "random_axes"
histories = "every=50"
[[block]]
name = "traj"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { random = { from = -20, to = 30, count = 12, seed = 5 } }
k = { from = 0, to = 1, count = 6 }
[[block]]
name = "ik"
kind = "ik"
problem = "scara"
method = "lm"
lambda = 0.1
[block.axes]
q0_1 = { random = { from = -180, to = 180, count = 10, seed = 2 } }
q0_2 = { from = -180, to = 180, count = 9 }
"""

LHS = """
[study]
name = "lhs_axes"
histories = "every=50"
[[block]]
name = "lhs_alpha"
kind = "trajectory"
method = "local_unweighted"
lhs = { count = 16, seed = 4 }
[block.axes]
alpha1A = { lhs = { from = -20, to = 30 } }
k = { from = 0, to = 1, count = 5 }
[[block]]
name = "lhs_starts"
kind = "ik"
problem = "scara"
method = "newton"
lhs = { count = 25, seed = 9 }
[block.axes]
q0_1 = { lhs = { from = -180, to = 180 } }
q0_2 = { lhs = { from = -180, to = 180 } }
"""

PLANAR3R = """
[study]
name = "planar3r_basins"
histories = "none"
[[block]]
name = "pose"
kind = "ik"
problem = "planar3r_pose"
[block.axes]
method = ["newton", "lm"]
q0_1 = { from = -180, to = 180, count = 15 }
q0_2 = { from = -180, to = 180, count = 15 }
"""


DEFAULT_PLOTS = ("plot_landscape", "plot_basins", "plot_histories", "plot_convergence", "plot_cases")


def h5str(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def file_blocks(f):
    """Block names in order of first appearance in /runs/block."""
    return list(dict.fromkeys(runs_column(f["runs"]["block"]).tolist()))


def landscape_axes(g):
    """[(name, categorical, n values, sampled)] of a /landscapes group; sampled: the points of a design,
    which no plot draws a grid over: the dimension `sample` (its `parameters` along it), or in format 4
    files a group of axes ("a+b") whose values are not monotonic, or repeated values (a Saltelli design)."""
    out = []
    for a in g.attrs["axes"]:
        d = g[axis_dataset_name(h5str(a))]
        cat = h5str(d.attrs.get("unit", "")).startswith("labels:")
        v = d[()].astype(float)
        steps = np.diff(v)
        sampled = "parameters" in d.attrs or not cat and len(v) > 1 and (len(np.unique(v)) < len(v) or (
            "+" in h5str(a) and not (np.all(steps > 0) or np.all(steps < 0))))  # format 5: `sample`; 4: a+b
        out.append((h5str(a), cat, len(d), sampled))
    return out


def numeric(axes):
    return [n for n, cat, size, sampled in axes if not cat and size > 1 and not sampled]


def ordered_landscapes(f):
    have = set(f["landscapes"]) if "landscapes" in f else set()
    return [b for b in file_blocks(f) if b in have]


class PlotStudiesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = types.SimpleNamespace(name=tempfile.mkdtemp(prefix="ks_plot_studies_"))
        cls.files = {}
        studies = sorted(glob.glob(os.path.join(ROOT, "studies", "*.toml")))
        for name, text in (("random_axes", RANDOM), ("lhs_axes", LHS), ("planar3r_basins", PLANAR3R)):
            path = os.path.join(cls.tmp.name, name + ".toml")
            with open(path, "w") as f:
                f.write(text)
            studies.append(path)
        for toml in studies:
            name = os.path.splitext(os.path.basename(toml))[0]
            shipped = os.path.join(SHIPPED or "", name + ".h5")
            if SHIPPED and toml.startswith(os.path.join(ROOT, "studies")) and name not in HISTORIES_BEYOND_MANIFEST \
                    and os.path.exists(shipped):
                cls.files[name] = shipped  # the run regression_hashes made (the same command), read only
                continue
            out = os.path.join(cls.tmp.name, name + ".h5")
            cmd = [KS, "run", toml, "-o", out, "--overwrite", "-q", "--threads", THREADS, "--no-verify-best"]
            if toml.startswith(os.path.join(ROOT, "studies")):
                cmd += ["--histories", HISTORIES.get(name, "none")]
            r = subprocess.run(cmd, capture_output=True, text=True)
            assert r.returncode == 0, f"{name}: {r.stderr}"
            cls.files[name] = out
        # Every command's default picture of every file, two at a time (the checks read these results).
        cls.cache = {}
        jobs = [(s, h5, (), None if s == "plot_basins" else (800, 600)) for h5 in cls.files.values()
                for s in DEFAULT_PLOTS]
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(max_workers=int(THREADS)) as pool:
            for key, r in zip(jobs, pool.map(lambda j: cls.run_plot(*j), jobs)):
                cls.cache[key] = r

    @classmethod
    def tearDownClass(cls):
        if os.environ.get("KS_KEEP_PLOTS"):  # keep the pictures to look at
            print(f"pictures kept in {cls.tmp.name}/png", file=sys.stderr)
        else:
            shutil.rmtree(cls.tmp.name, ignore_errors=True)

    def command(self, command, *args):
        return subprocess.run(analysis_command(command, *args), capture_output=True, text=True, env=ANALYSIS_ENV)

    @classmethod
    def run_plot(cls, command, h5, extra, size):
        png = os.path.join(cls.tmp.name, "png", f"{os.path.basename(h5)}_{command}_{abs(hash(extra))}.png")
        args = [h5, "-o", png, "--print-data", *extra]
        if size:
            args += ["--size", f"{size[0]}x{size[1]}"]
        return png, subprocess.run(analysis_command(command, *args), capture_output=True, text=True, env=ANALYSIS_ENV)

    def plot(self, script, h5, *extra, size=(800, 600), expect_ok=True):
        """Run a script with --print-data; when it succeeds check the picture; returns (rc, data, stderr)."""
        key = (script, h5, extra, size)
        png, r = self.cache[key] if key in self.cache else self.run_plot(*key)
        self.assertNotIn("Traceback", r.stderr, f"{script} {h5} {extra}")
        if expect_ok:
            self.assertEqual(r.returncode, 0, f"{script} {h5} {extra}: {r.stderr}")
        if r.returncode != 0:
            return r.returncode, None, r.stderr
        self.check_png(png, size)
        return 0, json.loads(r.stdout), r.stderr

    def check_png(self, png, size):
        import matplotlib.image as mpimg
        self.assertTrue(os.path.exists(png), png)
        img = mpimg.imread(png)
        if size:
            self.assertEqual(img.shape[:2], (size[1], size[0]))
        self.assertGreater(float(np.var(img[..., :3])), 1e-3, f"{png}: picture is blank")

    # -------------------------------------------------------------------------------------------
    def test_every_study_every_applicable_plot(self):
        drawn = {}
        for name, h5 in sorted(self.files.items()):
            with self.subTest(study=name), h5py.File(h5, "r") as f:
                drawn[name] = self.check_study(name, h5, f)
        # Every command drew something somewhere.
        for s in ("plot_landscape", "plot_basins", "plot_histories", "plot_cases", "plot_convergence"):
            self.assertTrue(any(s in v for v in drawn.values()), s)

    def check_study(self, name, h5, f):
        drawn = []
        lands = ordered_landscapes(f)
        axes = {b: landscape_axes(f["landscapes"][b]) for b in lands}
        # plot_landscape: the first landscape in file order with two swept numeric axes.
        first = next((b for b in lands if len(numeric(axes[b])) >= 2), None)
        if first is None:
            rc, _, err = self.plot("plot_landscape", h5, expect_ok=False)
            self.assertNotEqual(rc, 0)
            self.assertIn("landscape", err)
        else:
            g = f["landscapes"][first]
            ik = "converged" in g
            x, y = numeric(axes[first])[:2]
            rest = [(n, cat, size) for n, cat, size, _ in axes[first] if n not in (x, y) and size > 1]
            facet = len(rest) == 1 and rest[0][1] and rest[0][2] <= 6
            rc, d, err = self.plot("plot_landscape", h5, expect_ok=ik or facet or not rest)
            if rc == 2:
                self.assertIn("--fix", err)
                self.assertIn("--reduce", err)
                for n, _, _ in rest:
                    self.assertIn(n, err)
                rc, d, err = self.plot("plot_landscape", h5, "--reduce", "min")
                self.assertEqual(d["reduce"], "min")
            self.assertEqual(d["block"], first)
            self.assertEqual((d["x"]["name"], d["y"]["name"]), (x, y))
            self.assertEqual(d["facet"], rest[0][0] if facet and not ik else None)
            drawn.append("plot_landscape")
        # plot_basins: the first IK landscape in file order over (q0_1, q0_2).
        basins = [b for b in lands if "converged" in f["landscapes"][b]
                  and len([n for n in numeric(axes[b]) if n.startswith("q0_")]) >= 2]
        rc, d, err = self.plot("plot_basins", h5, size=None, expect_ok=bool(basins))
        if basins:
            self.assertEqual(d["block"], basins[0])
            self.assertEqual([d["x"]["name"], d["y"]["name"]],
                             [n for n in numeric(axes[basins[0]]) if n.startswith("q0_")][:2])
            drawn.append("plot_basins")
        else:
            self.assertNotEqual(rc, 0)
            self.assertIn("IK landscape", err)
        # plot_histories / plot_convergence: trajectory (time) and IK (norm_F) histories.
        hist = Histories(f)
        traj = [int(i) for i in hist.ids() if "t" in hist.names(i)]
        ikh = [int(i) for i in hist.ids() if "norm_F" in hist.names(i)]
        rc, d, err = self.plot("plot_histories", h5, expect_ok=bool(traj))
        if traj:
            self.assertEqual(sorted(int(r) for r in d["runs"]), sorted(traj)[:3])
            # at most 4 panels a row (the 7-DOF arm: 4 + 3), the legend in a panel of its own when one is free
            joints = int(f["runs"]["tau_inf"].attrs.get("joints", 0)) or max(
                len(d["runs"][r]["tau"][0]) for r in d["runs"])
            self.assertEqual(d["panels"]["cols"], min(4, joints))
            self.assertEqual(d["panels"]["rows"], -(-joints // 4))
            self.assertEqual(d["panels"]["legend_apart"], joints % 4 != 0 and joints > 4)
            drawn.append("plot_histories")
        else:
            self.assertNotEqual(rc, 0)
        rc, d, err = self.plot("plot_convergence", h5, expect_ok=bool(ikh))
        if ikh:
            self.assertTrue(set(int(r) for r in d["runs"]) <= set(ikh))
            drawn.append("plot_convergence")
        else:
            self.assertNotEqual(rc, 0)
        # plot_cases: rows with a preset.
        presets = [p for p, done in zip(runs_column(f["runs"]["preset"]), f["runs"]["done"][()])
                   if done and p] if "preset" in f["runs"] else []
        rc, d, err = self.plot("plot_cases", h5, expect_ok=bool(presets))
        if presets:
            self.assertEqual(d["cases"], list(dict.fromkeys(presets)))
            drawn.append("plot_cases")
        else:
            self.assertNotEqual(rc, 0)
            self.assertIn("no Table 4 preset rows", err)
            self.assertIn("thesis_table4.toml", err)
        return drawn

    def test_compare_landscapes(self):
        trios = [["redundancy_3r", "redundancy_4r", "redundancy_5r"], ["examples_landscape", "landscape_alpha_k"]]
        for names in trios:
            png = os.path.join(self.tmp.name, "png", f"compare_{names[0]}.png")
            r = self.command("compare_landscapes", *[self.files[n] for n in names], "-o", png,
                             "--fix", "method=local_weighted", "--print-data")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.check_png(png, None)
            self.assertEqual(len(json.loads(r.stdout)["minima"]), len(names))
        # optimize_polish's first landscape (k_1b) has no alpha1A: the first one over (alpha1A, k) is used.
        png = os.path.join(self.tmp.name, "png", "compare_polish.png")
        r = self.command("compare_landscapes", self.files["optimize_polish"], "-o", png, "--print-data")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.check_png(png, None)

    # --- the commands' choices, checked against the file ----------------------------------------
    def test_blocks_in_file_order(self):
        sys.path.insert(0, os.path.join(ROOT, "analysis"))
        from kinesweep import read as ksread
        for name in ("ik_scara", "optimize_polish", "arm7_square", "random_axes"):
            with h5py.File(self.files[name], "r") as f:
                want = file_blocks(f)
                lands = ordered_landscapes(f)
            with ksread.open_results(self.files[name]) as r:
                self.assertEqual(r.blocks(), want)
                self.assertEqual(r.landscapes(), lands)
        with h5py.File(self.files["ik_scara"], "r") as f:
            self.assertNotEqual(file_blocks(f), sorted(file_blocks(f)), "ik_scara's blocks should not be sorted")

    def test_log_spaced_axes(self):
        h5 = self.files["ik_scara"]
        with h5py.File(h5, "r") as f:
            lam = f["landscapes"]["damped"]["lambda"][()]
        self.assertGreaterEqual(lam.max() / lam.min(), 100)
        np.testing.assert_allclose(np.diff(np.log10(lam)), np.log10(lam[1] / lam[0]))  # evenly spaced in log
        _, d, _ = self.plot("plot_landscape", h5, "--block", "damped", "--metric", "iterations", "--x", "lambda",
                            "--y", "q0_1", "--fix", "method=lm", "--reduce", "mean")
        self.assertEqual((d["xscale"], d["yscale"]), ("log", "linear"))
        self.assertEqual(d["reduce"], "mean")
        _, d, _ = self.plot("plot_basins", h5, "--x", "lambda", "--y", "q0_1", "--fix", "q0_2=45", size=None)
        self.assertEqual((d["xscale"], d["yscale"]), ("log", "linear"))
        self.assertEqual(d["block"], "damped")
        # The default basins of ik_scara: the first block (damped), one row of panels per lambda.
        _, d, _ = self.plot("plot_basins", h5, size=None)
        self.assertEqual((d["block"], d["panel_axis"], d["rows"]), ("damped", "method", "lambda"))
        self.assertEqual(len(d["panels"]), 2 * len(lam))
        sys.path.insert(0, os.path.join(ROOT, "analysis"))
        from kinesweep import plotting as ksplot
        self.assertTrue(ksplot.is_log_spaced(lam))
        self.assertFalse(ksplot.is_log_spaced(np.linspace(1e-3, 100, 6)))
        self.assertFalse(ksplot.is_log_spaced([-1, 1, 10, 100]))
        self.assertFalse(ksplot.is_log_spaced([1, 3, 9]))  # less than 2 decades

    def test_joint_units(self):
        for name, block in (("planar3r_basins", "pose"), ("ik_basins", "basins")):
            with h5py.File(self.files[name], "r") as f:
                problem = {p for p, b in zip(runs_column(f["runs"]["problem"]), runs_column(f["runs"]["block"]))
                           if b == block}
                unit3 = h5str(f["runs"]["q_final_3"].attrs["unit"])
            _, d, _ = self.plot("plot_basins", self.files[name], size=None)
            self.assertTrue(d["solutions"])
            for text in d["solutions"].values():
                if problem == {"scara"}:
                    self.assertIn("mm", unit3)
                    self.assertRegex(text, r"d3 = [-\d.]+ mm")
                else:
                    self.assertNotIn("mm", text)
                    self.assertRegex(text, r"θ3 = [-\d.]+°")

    def test_facets_and_reduce(self):
        h5 = self.files["landscape_alpha_k"]
        _, d, _ = self.plot("plot_landscape", h5, size=(1200, 500))
        with h5py.File(h5, "r") as f:
            g = f["landscapes"]["local"]
            labels = h5str(g[axis_dataset_name("method")].attrs["unit"])[len("labels:"):].split(",")
            E = np.where(g["status_code"][()] == 0, g["E"][()], np.nan)
        self.assertEqual(d["facet"], "method")
        self.assertIsNone(d["reduce"])
        self.assertEqual([p["label"] for p in d["panels"]], labels)
        for m, p in enumerate(d["panels"]):
            got = np.array([[np.nan if v is None else v for v in row] for row in p["z"]], dtype=float)
            np.testing.assert_array_equal(got, E[m].T)
        # No facet possible (two remaining dims): exit 2 naming them and the options.
        r = self.command("plot_landscape", self.files["ik_scara"], "--metric", "iterations",
                         "-o", os.path.join(self.tmp.name, "x.png"))
        self.assertEqual(r.returncode, 2, r.stderr)
        for word in ("method", "q0_2", "--fix", "--reduce"):
            self.assertIn(word, r.stderr)
        # --fix keeps its meaning; --reduce is said in the data (and the title).
        _, d, _ = self.plot("plot_landscape", h5, "--fix", "method=local_unweighted")
        self.assertIsNone(d["facet"])
        np.testing.assert_array_equal(np.array([[np.nan if v is None else v for v in row] for row in d["z"]],
                                               dtype=float), E[labels.index("local_unweighted")].T)

    def test_round_levels_and_log_colour_bar(self):
        _, d, _ = self.plot("plot_landscape", self.files["examples_landscape"], "--fix", "method=local_weighted")
        lv = np.array(d["levels"])
        self.assertGreaterEqual(len(lv), 3)
        step = np.diff(lv)
        np.testing.assert_allclose(step, step[0])
        mant = step[0] / 10 ** math.floor(math.log10(step[0]))
        self.assertTrue(any(abs(mant - m) < 1e-9 for m in (1, 2, 2.5, 5)), step[0])
        np.testing.assert_allclose(lv / step[0], np.round(lv / step[0]), atol=1e-9)  # multiples of the step
        # Integer metric: integer levels.
        _, d, _ = self.plot("plot_landscape", self.files["examples_basins"], "--metric", "iterations",
                            "--fix", "method=newton")
        self.assertTrue(d["levels"])
        self.assertTrue(all(float(v).is_integer() for v in d["levels"]), d["levels"])
        # Log colour scale: several labelled ticks, each 1, 2 or 5 (or 1..9) times a power of ten.
        _, d, _ = self.plot("plot_landscape", self.files["examples_landscape"], "--fix", "method=local_weighted",
                            "--log", "--metric", "tau_inf")
        ticks = d["colorbar"]["ticks"]
        self.assertGreaterEqual(len(ticks), 3, d["colorbar"])
        self.assertGreaterEqual(len(d["colorbar"]["labels"]), 3, d["colorbar"])
        for t in ticks:
            m = t / 10 ** math.floor(math.log10(t) + 1e-12)
            self.assertAlmostEqual(m, round(m), places=9)

    def test_convergence_identical_histories_drawn_once(self):
        """ik_scara's default convergence plot: lm_adaptive ignores lambda, so its first run at each
        lambda (the same start) has the same history: one line for them, labelled with every run, a
        note on stderr; no two drawn lines hold the same data, and runs drawn on separate lines have
        histories that differ (read with h5py)."""
        h5 = self.files["ik_scara"]
        _, d, err = self.plot("plot_convergence", h5)
        lines = d["lines"]
        drawn = [(tuple(ln["x"]), tuple(ln["y"])) for ln in lines]
        self.assertEqual(len(drawn), len(set(drawn)), "two drawn lines hold identical data")
        self.assertEqual(sorted(r for ln in lines for r in ln["runs"]), sorted(int(r) for r in d["runs"]))
        grouped = [ln for ln in lines if len(ln["runs"]) > 1]
        self.assertTrue(grouped, "ik_scara's lm_adaptive runs from one start should be drawn as one line")
        with h5py.File(h5, "r") as f:
            method = runs_column(f["runs"]["method"])
            hist = Histories(f)
            norm_f = {r: {a: v for a, v, _ in hist.read(r)}["norm_F"][:, 0] for ln in lines for r in ln["runs"]}
        for ln in grouped:
            self.assertIn("runs " + ",".join(map(str, ln["runs"])) + " (identical)", ln["label"])
            self.assertIn(f"kinesweep.plot_convergence: note: runs {','.join(map(str, ln['runs']))} have identical", err)
            self.assertTrue(all(method[r] == "lm_adaptive" for r in ln["runs"]), ln["runs"])
            for r in ln["runs"]:
                self.assertEqual(norm_f[r].tobytes(), norm_f[ln["runs"][0]].tobytes())
                self.assertEqual(d["runs"][str(r)]["label"], ln["label"])
        firsts = [norm_f[ln["runs"][0]].tobytes() for ln in lines]
        self.assertEqual(len(firsts), len(set(firsts)))

    def test_convergence_runs_own_colours(self):
        h5 = self.files["ik_scara"]
        _, d, _ = self.plot("plot_convergence", h5, "--runs", "0,1,2")
        with h5py.File(h5, "r") as f:
            method = runs_column(f["runs"]["method"])[:3].tolist()
            q01 = f["runs"]["q0_1"][:3] * 180 / math.pi
        runs = d["runs"]
        self.assertEqual(sorted(runs), ["0", "1", "2"])
        self.assertEqual(len({r["colour"] for r in runs.values()}), 3)
        self.assertEqual(len({r["label"] for r in runs.values()}), 3)
        for i in range(3):
            self.assertIn(f"run {i}", runs[str(i)]["label"])
            self.assertIn(method[i], runs[str(i)]["label"])
            self.assertIn(f"{q01[i]:.4g}°", runs[str(i)]["label"])

    def test_cases_without_presets(self):
        for name in ("examples_landscape", "ik_scara"):
            r = self.command("plot_cases", self.files[name], "-o", os.path.join(self.tmp.name, "c.png"))
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("no Table 4 preset rows", r.stderr)
            self.assertIn("thesis_table4.toml", r.stderr)
            self.assertFalse(os.path.exists(os.path.join(self.tmp.name, "c.png")))


if __name__ == "__main__":
    KS, ROOT = sys.argv[1], sys.argv[2]
    rest = sys.argv[3:]
    if rest and rest[0] == "--shipped":
        SHIPPED, rest = rest[1], rest[2:]
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
