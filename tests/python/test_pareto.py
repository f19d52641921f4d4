"""End-to-end tests of Pareto fronts: `kinesweep query --pareto` (and --hypervolume) on a results file
of trajectory and IK runs against a brute-force front computed here from the file as h5py reads it,
against kinesweep.pareto's pareto_front() and hypervolume() run for run, kinesweep.plot_pareto's
front, the report's Pareto section, and the errors of bad arguments (exit 2, a located message).

usage: /usr/bin/python3 test_pareto.py KINESWEEP_BINARY REPO_ROOT
"""
import csv
import io
import json
import math
import os
import subprocess
import sys
import unittest

import numpy as np

from e2e_common import ANALYSIS, StudyFileTest, analysis_command

KS = None
D = 180.0 / math.pi
ENV = dict(os.environ, PYTHONPATH=ANALYSIS)

STUDY = """
[study]
name = "pareto_e2e"
histories = "none"

[[block]]
name = "local"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { from = -30, to = 30, step = 5 }
k = { from = 0, to = 1, count = 6 }

[[block]]
name = "basin"
kind = "ik"
problem = "scara"
method = "newton"
[block.axes]
q0_1 = { from = -180, to = 180, count = 9 }
q0_2 = { from = -180, to = 180, count = 9 }
"""

GOOD = {"trajectory": "ok", "ik": "converged"}


def ks(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True)


def csv_ids(text):
    rows = list(csv.reader(io.StringIO(text)))
    return [int(r[rows[0].index("run_id")]) for r in rows[1:]]


def brute_front(values, senses, eligible):
    """The definition, O(n^2): eligible NaN-free rows no other such row dominates."""
    v = np.array(values, dtype=float)
    for k, s in enumerate(senses):
        if s == "max":
            v[:, k] = -v[:, k]
    ok = eligible & ~np.isnan(v).any(axis=1)
    out = []
    for i in np.flatnonzero(ok):
        others = v[ok]
        dom = np.all(others <= v[i], axis=1) & np.any(others < v[i], axis=1)
        if not dom.any():
            out.append(int(i))
    return out


class Front(StudyFileTest):
    NAME, STUDY = "pareto", STUDY

    @classmethod
    def setUpClass(cls):
        cls.KS = KS
        super().setUpClass()
        sys.path.insert(0, ANALYSIS)
        from kinesweep import pareto
        cls.pareto = pareto
        t = cls.runs
        kind = np.where(np.isnan(t["E"]) & (t["iterations"] >= 0), "ik", "trajectory")
        cls.good = np.array([s == GOOD[k] for s, k in zip(t["status"], kind)]) & (t["done"] == 1)

    def expected(self, metrics, rows=None):
        """Run ids of the brute-force front of `metrics` [(name, sense)] among `rows` (default all)."""
        t = self.runs
        cols = []
        for name, _ in metrics:
            v = np.asarray(t[name], dtype=float)
            if t[name].dtype.kind in "iu":
                v[t[name] == -1] = np.nan
            cols.append(v * D if name == "alpha1A" else v)
        eligible = self.good & (rows if rows is not None else True)
        return sorted(t["run_id"][brute_front(np.column_stack(cols), [s for _, s in metrics], eligible)].tolist())

    def query_ids(self, *args):
        r = ks("query", self.h5, *args, "-f", "csv", "-c", "run_id")
        self.assertEqual(r.returncode, 0, r.stderr)
        return csv_ids(r.stdout)

    def test_fronts_agree(self):
        cases = [("E,peak_joint_power", [], None),
                 ("E,min_manipulability:max", [], None),
                 ("torque_sq_integral,min_manipulability:max", ["alpha1A<0"], self.runs["alpha1A"] * D < 0),
                 ("alpha1A:max,E", ["method=local_weighted"], self.runs["method"] == "local_weighted"),
                 ("E,tau_inf:min,min_manipulability:max", [], None),
                 ("torque_sq_integral,peak_joint_power,max_tracking_error:max", ["k<=0.6"], self.runs["k"] <= 0.6),
                 ("iterations,error", [], None),
                 ("iterations:max,error,solution", [], None)]
        sizes = []
        for spec, where, rows in cases:
            with self.subTest(spec):
                metrics = self.pareto.parse_metrics(spec)
                args = ["--pareto", spec] + [x for w in where for x in ("-w", w)]
                cli = self.query_ids(*args)
                py = self.pareto.pareto_front(self.h5, spec, where=where)
                self.assertEqual(cli, py["run_id"].tolist())  # run for run, in the same order
                self.assertEqual(sorted(cli), self.expected(metrics, rows))
                self.assertTrue(np.isin(py["status"], list(GOOD.values())).all())
                sizes.append(len(cli))
        self.assertGreater(max(sizes), 4)  # some fronts of several runs

    def test_front_excludes_failed_and_missing(self):
        t = self.runs
        ids = self.query_ids("--pareto", "iterations,error")
        self.assertTrue(all(t["status"][i] == "converged" for i in ids))
        self.assertTrue(all(np.isnan(t["E"][i]) for i in ids))  # the trajectory rows have no IK metrics
        # a failed run better than every good one is not on the front, and dominates nothing
        failed = [i for i in range(len(t["run_id"])) if t["done"][i] and not self.good[i] and t["iterations"][i] >= 0]
        self.assertTrue(failed)
        self.assertFalse(set(failed) & set(ids))

    def test_json_and_table(self):
        r = ks("query", self.h5, "--pareto", "E,peak_joint_power", "-f", "json")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = json.loads(r.stdout)["rows"]
        self.assertEqual([x["run_id"] for x in rows], self.query_ids("--pareto", "E,peak_joint_power"))
        self.assertIn("peak_joint_power", rows[0])
        r = ks("query", self.h5, "--pareto", "E,peak_joint_power")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("peak_joint_power [W]", r.stdout)
        self.assertIn("runs on the front; front of E min, peak_joint_power min over", r.stdout)

    def test_hypervolume_agrees(self):
        for spec, ref in (("E,min_manipulability:max", "80,0.5"), ("E,peak_joint_power", "100,5000"),
                          ("E,tau_inf,min_manipulability:max", "100,2000,0"), ("iterations,error", "50,1")):
            with self.subTest(spec):
                r = ks("query", self.h5, "--pareto", spec, "--hypervolume", ref, "-f", "json")
                self.assertEqual(r.returncode, 0, r.stderr)
                row = json.loads(r.stdout)["rows"][0]
                front = self.pareto.pareto_front(self.h5, spec)
                ref_v = [float(x) for x in ref.split(",")]
                hv = self.pareto.hypervolume(front, ref_v)
                self.assertGreater(hv, 0)
                self.assertAlmostEqual(row["hypervolume"], hv, delta=1e-9 * hv)
                self.assertEqual(row["front_runs"], len(front))
                # every good run gives the same volume as the front alone (dominated runs add nothing)
                runs = self.pareto.front_of_runs(self.h5, spec)
                names = [n for n, _ in self.pareto.parse_metrics(spec)]
                vals = self.pareto.metric_values(runs[0], names)[runs[2]]
                self.assertAlmostEqual(self.pareto.hypervolume(vals, ref_v, front.pareto_senses), hv, delta=1e-9 * hv)

    def test_bad_arguments_exit_2(self):
        r = ks("query", self.h5, "--pareto", "E,min_manipulabilty:max")
        self.assertEqual(r.returncode, 2)
        self.assertIn("unknown column 'min_manipulabilty' in --pareto 'E,min_manipulabilty:max'; "
                      "did you mean 'min_manipulability'?", r.stderr)
        self.assertIn("valid columns: run_id", r.stderr)
        with self.assertRaises(self.pareto.ParetoError) as e:
            self.pareto.pareto_front(self.h5, "E,min_manipulabilty:max")
        self.assertIn("did you mean 'min_manipulability'?", str(e.exception))
        for args, text in ((["--pareto", "E:maxx,tau_inf"], "did you mean 'E:max'?"),
                           (["--pareto", "E"], "a front needs 2 or 3"),
                           (["--pareto", "E,tau_inf,k,E_M"], "a front needs 2 or 3"),
                           (["--pareto", "E,E"], "E is named twice"),
                           (["--pareto", "E,method"], "column method holds text"),
                           (["--hypervolume", "1,2"], "--hypervolume needs --pareto"),
                           (["--pareto", "E,tau_inf", "--hypervolume", "1"], "1 value(s) for 2 --pareto metrics"),
                           (["--pareto", "E,tau_inf", "--hypervolume", "1,x"], "'x' is not a number"),
                           (["--pareto", "E,tau_inf", "--group-by", "method"], "--pareto prints the runs"),
                           (["--pareto", "E,tau_inf", "-w", "nosuch<3"], "unknown column 'nosuch' in --where")):
            with self.subTest(args):
                r = ks("query", self.h5, *args)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn(text, r.stderr)

    def test_plot_and_report(self):
        out = os.path.join(self.tmp.name, "front.png")
        for spec in ("E,peak_joint_power", "E,tau_inf,min_manipulability:max"):
            with self.subTest(spec):
                p = subprocess.run(analysis_command("plot_pareto", self.h5, "--metrics", spec, "-o", out,
                                                    "--print-data"), capture_output=True, text=True, env=ENV)
                self.assertEqual(p.returncode, 0, p.stderr)
                data = json.loads(p.stdout)
                self.assertEqual(sorted(data["front_run_ids"]), sorted(self.query_ids("--pareto", spec)))
                self.assertTrue(os.path.getsize(out) > 1000)
        p = subprocess.run(analysis_command("plot_pareto", self.h5, "--metrics", "E,nosuch", "-o", out),
                           capture_output=True, text=True, env=ENV)
        self.assertEqual(p.returncode, 2)
        self.assertIn("unknown column 'nosuch'", p.stderr)
        from kinesweep.report_pareto import pareto_section
        from kinesweep.read import open_results
        with open_results(self.h5) as res:
            html = pareto_section(res, "E,peak_joint_power")
            ids = [int(x) for x in self.query_ids("--pareto", "E,peak_joint_power")]
            for i in ids:
                self.assertIn(f'<td data-v="{i}">{i}</td>', html)
            self.assertEqual(pareto_section(res, "E,nosuch"), "")



class ManyPieces(StudyFileTest):
    """A file of more good runs than query holds before it reduces them to their front (4 pieces of
    16384 rows): the front read piece by piece is the front of all runs."""
    NAME = "pareto_pieces"
    STUDY = """
[study]
name = "pareto_pieces"
histories = "none"

[[block]]
name = "basin"
kind = "ik"
problem = "scara"
method = "lm"
[block.axes]
q0_1 = { from = -180, to = 180, count = 220 }
q0_2 = { from = -180, to = 180, count = 220 }
lambda = [0.01, 0.1]
"""

    @classmethod
    def setUpClass(cls):
        cls.KS = KS
        super().setUpClass()

    def test_front_over_pieces(self):
        from kinesweep import pareto
        self.assertGreater(int((self.runs["status"] == "converged").sum()), 4 * 16384)
        for spec in ("iterations,error", "iterations,error,min_rcond:max", "error:max,min_rcond"):
            with self.subTest(spec):
                r = ks("query", self.h5, "--pareto", spec, "-f", "csv", "-c", "run_id")
                self.assertEqual(r.returncode, 0, r.stderr)
                front = pareto.pareto_front(self.h5, spec)
                self.assertEqual(csv_ids(r.stdout), front["run_id"].tolist())
                self.assertGreater(len(front), 0)



if __name__ == "__main__":
    KS = sys.argv.pop(1)
    sys.argv.pop(1)  # the repository root (the package is found through e2e_common)
    unittest.main()
