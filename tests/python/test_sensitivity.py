"""kinesweep sensitivity on a Saltelli design: the indices it prints are the Saltelli 2010 (first
order, centred) and Jansen (total) estimators computed here with numpy from the /runs rows h5py
reads (the design's matrices found from /designs); runs with a failed status counted by status;
its errors (no design, an unknown metric) and the study parser's (two designs in a block, second
order asked for, an axis of a design the block lacks). kinesweep.read's sensitivity() gives the
command's numbers at its default bootstrap, digit for digit (the indices `kinesweep run` stored in
/sensitivity). The report and plot_landscape draw no grid over a design's sampled
points (examples_lhs and the Saltelli study). And the shipped studies/sensitivity_seed.toml:
its indices of E and tau_inf contain those of a brute-force variance decomposition of the same
function on a 40^3 grid of cell midpoints over the same ranges.

usage: /usr/bin/python3 test_sensitivity.py KINESWEEP_BINARY SOURCE_DIR
"""
import json
import os
import tomllib
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import ANALYSIS_ENV, TempDirTest, analysis_command, report_page, runs_column

KS = None
SOURCE = None

STUDY = """
[study]
name = "sens"
histories = "none"

[[block]]
name = "grid"
kind = "trajectory"
alpha1A = -20
[block.axes]
k = [0, 0.5]

[[block]]
name = "local"
kind = "trajectory"
saltelli = {{ count = {n}, seed = 3 }}
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = {{ saltelli = {{ from = -30, to = 35 }} }}
k = {{ saltelli = {{ from = 0, to = 1 }} }}
K_N = {{ saltelli = {{ from = 5, to = 40 }} }}
"""


def run(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True, timeout=300)


def estimate(a, b, ab):
    keep = np.isfinite(a) & np.isfinite(b) & np.all(np.isfinite(ab), axis=0)
    a, b, ab = a[keep], b[keep], ab[:, keep]
    y = np.concatenate([a, b])
    v = y.var(ddof=1)
    first = np.mean((b - y.mean()) * (ab - a), axis=1) / v
    total = np.mean((a - ab) ** 2, axis=1) / 2 / v
    return first, total, int(keep.sum())


class Sensitivity(TempDirTest):
    def test_indices_equal_the_estimators_on_the_rows_h5py_reads(self):
        n = 64
        study = self.write("sens.toml", STUDY.format(n=n))
        out = os.path.join(self.dir, "sens.h5")
        r = run("run", study, "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        r = run("sensitivity", out, "--metric", "E", "tau2_inf", "--format", "json", "--bootstrap", "200")
        self.assertEqual(r.returncode, 0, r.stderr)
        got = json.loads(r.stdout)["results"]
        self.assertEqual(len(got), 4)  # 2 metrics x 2 methods
        with h5py.File(out, "r") as f:
            d = f["designs"]["local"].attrs
            self.assertEqual(list(d["factors"]), ["alpha1A", "k", "K_N"])
            self.assertEqual(int(d["base_samples"]), n)
            sizes, dim, first_run = [int(s) for s in d["sizes"]], int(d["dim"]), int(d["first_run"])
            self.assertEqual(sizes[dim], n * 5)
            ids = first_run + np.arange(int(np.prod(sizes)))
            status = runs_column(f["runs"]["status"])[ids]
            method = runs_column(f["runs"]["method"])[ids]
            for res in got:
                y = f["runs"][res["metric"]][()][ids].astype(float)
                y[status != "ok"] = np.nan
                at = res["at"].split("=")[1]
                grid = y.reshape(sizes)
                other = [k for k in range(len(sizes)) if k != dim][0]
                m_index = [i for i in range(sizes[other]) if method.reshape(sizes).take(i, axis=other).flat[0] == at][0]
                pts = grid.take(m_index, axis=other)
                a, b = pts[:n], pts[n:2 * n]
                ab = np.stack([pts[(2 + m) * n:(3 + m) * n] for m in range(3)])
                first, total, used = estimate(a, b, ab)
                self.assertEqual(res["samples"], used)
                self.assertEqual(res["samples"] + res["dropped"], n)
                self.assertEqual(sum(res["failed_runs"].values()), int(np.sum(status.reshape(sizes).take(m_index, axis=other) != "ok")))
                for i, fac in enumerate(res["factors"]):
                    self.assertAlmostEqual(fac["first"], first[i], delta=1e-5 * max(1, abs(first[i])))
                    self.assertAlmostEqual(fac["total"], total[i], delta=1e-5 * max(1, abs(total[i])))
                    self.assertLessEqual(fac["first_lo"], fac["first_hi"])
                    self.assertLessEqual(fac["total_lo"], fac["total_hi"])
        # kinesweep.read: the indices `kinesweep run` stored in /sensitivity are the command's at its
        # default bootstrap, digit for digit, for every numeric metric, with the same counts
        full = run("sensitivity", out, "--metric", "E", "tau2_inf", "--format", "json")
        self.assertEqual(full.returncode, 0, full.stderr)
        cli = json.loads(full.stdout)["results"]  # metric by metric, combinations in run order, as py
        sys.path.insert(0, os.path.join(SOURCE, "analysis"))
        from kinesweep.read import open_results
        with open_results(out) as res:
            py = res.sensitivity(metric="E") + res.sensitivity(metric="tau2_inf")
        self.assertEqual([f"method={p['at']['method']}" for p in py], [c["at"] for c in cli])
        for p, c in zip(py, cli):
            self.assertEqual((p["metric"], p["samples"], p["dropped"], p["failed_runs"], p["bootstrap"]),
                             (c["metric"], c["samples"], c["dropped"], c["failed_runs"], 1000))
            self.assertEqual(p["variance"], c["variance"])
            for i, fac in enumerate(c["factors"]):
                self.assertEqual(p["factors"][i], fac["name"])
                for key in ("first", "first_lo", "first_hi", "total", "total_lo", "total_hi"):
                    self.assertEqual(p[key][i], fac[key], f"{p['metric']} {fac['name']} {key}")
        with h5py.File(out, "r") as f:  # every numeric trajectory metric is stored, 3 factors x 2 methods each
            stored = runs_column(f["sensitivity"]["metric"])
            self.assertEqual(len(stored), 3 * 2 * len(set(stored)))
            for name in ("E", "tau_inf", "torque_sq_integral", "min_manipulability", "iterations"):
                self.assertEqual(name in set(stored), name != "iterations", name)
        with self.assertRaisesRegex(ValueError, "no indices of 'status'"):
            with open_results(out) as res:
                res.sensitivity(metric="status")
        # a file written before /sensitivity was stored: the reader says how to add it; a resume adds it
        with h5py.File(out, "r+") as f:
            del f["sensitivity"]
        with self.assertRaisesRegex(ValueError, "no /sensitivity.*--resume"):
            with open_results(out) as res:
                res.sensitivity()
        r = run("run", study, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open_results(out) as res:
            again = res.sensitivity(metric="E")
        self.assertEqual([list(p["first"]) for p in again], [list(p["first"]) for p in py[:2]])
        table = run("sensitivity", out, "--block", "local")
        self.assertEqual(table.returncode, 0, table.stderr)
        self.assertIn("at method=local_weighted", table.stdout)
        self.assertIn("alpha1A", table.stdout)

    def test_errors(self):
        study = self.write("grid.toml", STUDY.format(n=4).split("[[block]]\nname = \"local\"")[0])
        out = os.path.join(self.dir, "grid.h5")
        self.assertEqual(run("run", study, "-o", out, "-q").returncode, 0)
        r = run("sensitivity", out)
        self.assertEqual(r.returncode, 1)
        self.assertIn("holds no Saltelli design", r.stderr)
        study = self.write("s.toml", STUDY.format(n=4))
        out = os.path.join(self.dir, "s.h5")
        self.assertEqual(run("run", study, "-o", out, "-q").returncode, 0)
        r = run("sensitivity", out, "--metric", "tau2_inff")
        self.assertEqual(r.returncode, 2)
        self.assertIn("did you mean 'tau2_inf'", r.stderr)
        r = run("sensitivity", out, "--block", "grid")
        self.assertEqual(r.returncode, 2)
        for bad, message in [
            ('saltelli = { count = 4, seed = 3 }', None),
            ('saltelli = { count = 4, seed = 3, second_order = true }', "second_order"),
            ('lhs = { count = 4, seed = 1 }\nsaltelli = { count = 4, seed = 3 }', "both lhs and saltelli"),
            ('lhs = { count = 4, seed = 1 }', "uses saltelli but the block has no saltelli settings"),
        ]:
            text = STUDY.format(n=4).replace("saltelli = { count = 4, seed = 3 }", bad)
            r = run("run", self.write("bad.toml", text), "-o", os.path.join(self.dir, "bad.h5"), "--overwrite",
                    "--dry-run")
            if message is None:
                self.assertEqual(r.returncode, 0, r.stderr)
                continue
            self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
            self.assertIn(message, r.stderr)
            self.assertRegex(r.stderr, r"bad\.toml:\d+:\d+")


    def test_the_shipped_study_agrees_with_a_brute_force_decomposition(self):
        path = os.path.join(SOURCE, "studies", "sensitivity_seed.toml")
        with open(path, "rb") as f:
            block = tomllib.load(f)["block"][0]
        out = os.path.join(self.dir, "sens.h5")
        self.assertEqual(run("run", path, "-o", out, "-q").returncode, 0)
        r = run("sensitivity", out, "--metric", "E", "tau_inf", "--format", "json")
        self.assertEqual(r.returncode, 0, r.stderr)
        results = json.loads(r.stdout)["results"]
        n = 40
        axes = []
        for name in ("alpha1A", "k", "K_N"):  # the design's factors, in its order
            lo, hi = block["axes"][name]["saltelli"]["from"], block["axes"][name]["saltelli"]["to"]
            h = (hi - lo) / n
            axes.append(f"{name} = {{ from = {lo + h / 2!r}, to = {hi - h / 2!r}, count = {n} }}")
        grid = self.write("grid.toml", f'[study]\nname = "grid"\nhistories = "none"\n[[block]]\nname = "grid"\n'
                                       f'kind = "trajectory"\nmethod = "{block["method"]}"\n[block.axes]\n' + "\n".join(axes))
        gout = os.path.join(self.dir, "grid.h5")
        self.assertEqual(run("run", grid, "-o", gout, "-q").returncode, 0)
        with h5py.File(gout, "r") as f:
            self.assertTrue(np.all(runs_column(f["runs"]["status"]) == "ok"))
            for res in results:
                self.assertEqual([x["name"] for x in res["factors"]], ["alpha1A", "k", "K_N"])
                self.assertEqual(res["dropped"], 0)
                y = f["runs"][res["metric"]][()].reshape(n, n, n)
                v = y.var()
                for i, fac in enumerate(res["factors"]):
                    other = tuple(a for a in range(3) if a != i)
                    first = y.mean(axis=other).var() / v  # Var(E[Y | X_i]) / Var(Y)
                    total = y.var(axis=i).mean() / v      # E[Var(Y | X_~i)] / Var(Y)
                    what = f"{res['metric']} {fac['name']}"
                    self.assertTrue(fac["first_lo"] <= first <= fac["first_hi"], f"{what} S1 {first} {fac}")
                    self.assertTrue(fac["total_lo"] <= total <= fac["total_hi"], f"{what} ST {total} {fac}")
        # the report's bar chart: the command's indices of the kind's objective (E)
        _, islands = report_page(self, out, self.dir)
        self.assertIn("sensitivity-0-data", islands)
        self.assertNotIn("importance-0-data", islands)  # a Saltelli design has indices, no forest fit
        fig = json.loads(islands["sensitivity-0-data"])
        e = [x for x in results if x["metric"] == "E"][0]
        self.assertEqual(fig["data"][0]["x"], ["alpha1A", "k", "K_N"])
        for bar, key in zip(fig["data"], ("first", "total")):
            for i, fac in enumerate(e["factors"]):
                self.assertAlmostEqual(bar["y"][i], fac[key], delta=1e-5)
                self.assertAlmostEqual(bar["y"][i] + bar["error_y"]["array"][i], fac[key + "_hi"], delta=0.05)


    def test_no_grid_is_drawn_over_sampled_points(self):
        """examples_lhs (a Latin hypercube, random initial guesses) and the Saltelli study: the report
        draws no heatmap over a dimension of sampled points (every heatmap's x and y are monotonic)
        and says why; plot_landscape refuses with the reason."""
        for study in ("examples_lhs.toml", "sensitivity_seed.toml"):
            out = os.path.join(self.dir, study.replace(".toml", ".h5"))
            self.assertEqual(run("run", os.path.join(SOURCE, "studies", study), "-o", out, "-q").returncode, 0)
            html, islands = report_page(self, out, self.dir)
            self.assertIn("holds sampled points", html)
            for fid, text in islands.items():
                fig = json.loads(text)
                for trace in fig.get("data", []) if isinstance(fig, dict) else []:
                    if trace.get("type") != "heatmap":
                        continue
                    for key in ("x", "y"):
                        v = [x for x in trace.get(key, []) if isinstance(x, (int, float))]
                        d = np.diff(v)
                        self.assertTrue(len(v) < 2 or np.all(d > 0) or np.all(d < 0), f"{study} {fid} {key}")
            r = subprocess.run(analysis_command("plot_landscape", out, "-o", os.path.join(self.dir, "p.png")),
                               capture_output=True, text=True, timeout=300, env=ANALYSIS_ENV)
            self.assertEqual(r.returncode, 1)
            self.assertIn("is not a grid axis", r.stderr)


if __name__ == "__main__":
    KS = os.path.abspath(sys.argv[1])
    SOURCE = os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"])
