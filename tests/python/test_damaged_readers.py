"""Readers of a damaged results file refuse it, naming the object, instead of crashing or printing
numbers of other rows: a /designs group whose rows run past /runs or off its block (`kinesweep
sensitivity` exit 1; kinesweep.read's sensitivity() raises ValueError), a landscape grid of another
shape than its axes (`kinesweep info` exit 1; landscape() raises), a history index past its
datasets (`kinesweep query --run` exit 1). The files are forged with h5py from good ones; every
read-only command leaves the file byte-identical (SHA-256).

Also `kinesweep sensitivity` on integer metrics (the IK kind's `iterations` and every numeric metric
the kind lists): the indices equal Saltelli 2010 / Jansen estimators computed here with numpy from
the rows h5py reads, and the samples left out for a failed run are counted (table and JSON) with the
statement that the indices are conditional on success. And the minor refusals: `sensitivity --seed
-1`, `kinesweep robot` given a results file, a Saltelli axis with a bad bound.

usage: /usr/bin/python3 test_damaged_readers.py KINESWEEP_BINARY SOURCE_DIR
"""
import hashlib
import json
import os
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import TempDirTest, runs_column

KS = None
SOURCE = None

# A grid block before the design's block: the design's rows start past row 0, with rows of another
# block before them.
DESIGN = """
[study]
name = "forge"
histories = "every=10"

[[block]]
name = "grid"
kind = "trajectory"
[block.axes]
k = [0, 0.5, 1]

[[block]]
name = "local"
kind = "trajectory"
saltelli = { count = 16, seed = 3 }
[block.axes]
alpha1A = { saltelli = { from = -30, to = 35 } }
k = { saltelli = { from = 0, to = 1 } }

[[block]]
name = "after"
kind = "trajectory"
[block.axes]
alpha1A = [-20, 0, 20]
k = [0, 0.5]
"""

IK = """
[study]
name = "salt_ik"
histories = "none"

[[block]]
name = "d"
kind = "ik"
problem = "scara"
method = "lm"
target_x = 50.0
target_y = -80.0
target_z = 10.0
q0_3 = 50.0
saltelli = { count = 64, seed = 1 }

[block.axes]
q0_1 = { saltelli = { from = -180, to = 180 } }
q0_2 = { saltelli = { from = -180, to = 180 } }
lambda = { saltelli = { from = 0.01, to = 1 } }
"""


def run(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True, timeout=300)


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def estimate(a, b, ab):
    """Saltelli 2010's first-order and Jansen's total estimators over the rows with finite values."""
    keep = np.isfinite(a) & np.isfinite(b) & np.all(np.isfinite(ab), axis=0)
    a, b, ab = a[keep], b[keep], ab[:, keep]
    y = np.concatenate([a, b])
    v = y.var(ddof=1)
    return np.mean((b - y.mean()) * (ab - a), axis=1) / v, np.mean((a - ab) ** 2, axis=1) / 2 / v, int(keep.sum())


def python_package():
    sys.path.insert(0, os.path.join(SOURCE, "analysis"))
    from kinesweep.read import open_results
    return open_results


class DamagedFiles(TempDirTest):
    @classmethod
    def setUpClass(cls):
        import tempfile
        cls.tmp_cls = tempfile.TemporaryDirectory()
        study = os.path.join(cls.tmp_cls.name, "forge.toml")
        with open(study, "w") as f:
            f.write(DESIGN)
        cls.good = os.path.join(cls.tmp_cls.name, "good.h5")
        r = run("run", study, "-o", cls.good, "-q")
        assert r.returncode == 0, r.stderr
        with h5py.File(cls.good, "r") as f:
            cls.first_run = int(f["designs"]["local"].attrs["first_run"])
            cls.n_runs = len(f["runs"]["done"])

    @classmethod
    def tearDownClass(cls):
        cls.tmp_cls.cleanup()

    def forged(self, name, edit):
        out = os.path.join(self.dir, name)
        with open(self.good, "rb") as src, open(out, "wb") as dst:
            dst.write(src.read())
        with h5py.File(out, "r+") as f:
            edit(f)
        return out

    def refused(self, out, args, expect):
        before = digest(out)
        r = run(*args)
        self.assertEqual(r.returncode, 1, f"{args}: {r.stdout}{r.stderr}")
        self.assertIn(expect, r.stderr)
        self.assertEqual(digest(out), before)

    def test_good_file_reads(self):
        r = run("sensitivity", self.good, "--bootstrap", "10")
        self.assertEqual(r.returncode, 0, r.stderr)
        with python_package()(self.good) as res:
            self.assertEqual(len(res.sensitivity()), 1)

    def test_design_rows_off_runs_or_off_its_block(self):
        runs = 16 * 4  # base samples x (2 factors + 2)
        self.assertEqual(self.first_run, 3)
        cases = [self.first_run + 1, self.first_run - 1, 0, self.n_runs - runs, self.n_runs - runs + 1, 16384, -1,
                 2 ** 62]
        for first_run in cases:
            with self.subTest(first_run=first_run):
                out = self.forged(f"fr{first_run}.h5", lambda f: f["designs"]["local"].attrs.__setitem__(
                    "first_run", np.int64(first_run)))
                self.refused(out, ["sensitivity", out, "--bootstrap", "10"], "/designs/local")
                with python_package()(out) as res:
                    with self.assertRaisesRegex(ValueError, "/designs/local"):
                        res.sensitivity()
        # the report (which lists the designs) refuses the file as well: exit 1, the object named
        out = os.path.join(self.dir, f"fr{self.first_run + 1}.h5")
        r = subprocess.run([sys.executable, "-m", "kinesweep.report", out, "-o", os.path.join(self.dir, "r.html")],
                           capture_output=True, text=True, timeout=300,
                           env=dict(os.environ, PYTHONPATH=os.path.join(SOURCE, "analysis")))
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertIn("/designs/local", r.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.dir, "r.html")))

    def test_design_sizes_past_runs(self):
        for sizes in ([16 * 4 * 1000], [0], [-64], [2 ** 40 * 64]):
            with self.subTest(sizes=sizes):
                def edit(f):
                    a = f["designs"]["local"].attrs
                    a["sizes"] = np.array(sizes, dtype=np.int64)
                    a["base_samples"] = np.int64(max(1, sizes[0] // 4))
                out = self.forged(f"sz{sizes[0]}.h5", edit)
                self.refused(out, ["sensitivity", out, "--bootstrap", "10"], "/designs/local")
                with python_package()(out) as res:
                    with self.assertRaisesRegex(ValueError, "/designs/local"):
                        res.sensitivity()

    def test_landscape_grid_of_another_shape(self):
        def edit(f):
            g = f["landscapes"]["grid"]
            name = [m.decode() if isinstance(m, bytes) else m for m in g.attrs["metrics"]][0]
            attrs = dict(g[name].attrs)
            del g[name]
            d = g.create_dataset(name, data=np.zeros(2))
            for k, v in attrs.items():
                if k not in ("DIMENSION_LIST", "REFERENCE_LIST"):
                    d.attrs[k] = v
            f.attrs["forged_metric"] = name
        out = self.forged("land.h5", edit)
        with h5py.File(out, "r") as f:
            metric = f.attrs["forged_metric"]
        self.refused(out, ["info", out], f"/landscapes/grid/{metric}")
        with python_package()(out) as res:
            with self.assertRaisesRegex(ValueError, f"/landscapes/grid/{metric}"):
                res.landscape("grid")

    def test_history_index_past_its_datasets(self):
        with h5py.File(self.good, "r") as f:
            layout = f["histories"]["layout"][()]
            run_id = int(np.flatnonzero(layout >= 0)[0])
        for start in (10 ** 9, -5):
            with self.subTest(start=start):
                out = self.forged(f"hist{start}.h5", lambda f: f["histories"]["start"].__setitem__(run_id, start))
                r_before = digest(out)
                r = run("query", out, "--run", str(run_id))
                self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
                self.assertIn("/histories", r.stderr)
                self.assertEqual(digest(out), r_before)
                with python_package()(out) as res:
                    with self.assertRaisesRegex(ValueError, "/histories"):
                        res.history(run_id)


class IntegerMetrics(TempDirTest):
    def test_every_numeric_ik_metric(self):
        study = self.write("salt_ik.toml", IK)
        out = os.path.join(self.dir, "salt_ik.h5")
        r = run("run", study, "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        with h5py.File(out, "r") as f:
            runs = f["runs"]
            metrics = [c for c in runs if c != "done" and runs[c].attrs.get("role", b"") in (b"metric", "metric")
                       and "ik" in str(runs[c].attrs.get("kinds", "")) and runs[c].dtype.kind in "fiu"
                       and "flag_meanings" not in runs[c].attrs]
            integer = [m for m in metrics if runs[m].dtype.kind in "iu"]
            status = runs_column(runs["status"])
            cols = {m: runs[m][()] for m in metrics}
            d = f["designs"]["d"].attrs
            n, first = int(d["base_samples"]), int(d["first_run"])
        self.assertIn("iterations", integer)
        # the default metric (the kind's ranking objective, an integer column), as a table
        r = run("sensitivity", out, "--bootstrap", "20")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("metric iterations", r.stdout)
        r = run("sensitivity", out, "--bootstrap", "20", "--format", "json", "--metric", *metrics)
        self.assertEqual(r.returncode, 0, r.stderr)
        got = json.loads(r.stdout)["results"]
        self.assertEqual([g["metric"] for g in got], metrics)
        ids = first + np.arange(5 * n)
        good = got[0]["good_status"]
        self.assertNotIn(good, got[0]["failed_runs"])
        bad = (status[ids] != good).reshape(5, n)  # points A, B, AB_0, AB_1, AB_2 of each sample row
        failed_samples = int(bad.any(axis=0).sum())
        self.assertGreater(failed_samples, 0)  # the IK design has failed runs: the count matters
        for g in got:
            self.assertEqual(g["failed_samples"], failed_samples)
            self.assertEqual(g["not_done_samples"], 0)
            self.assertTrue(g["conditional_on_success"])
            y = cols[g["metric"]][ids].astype(float)
            y[status[ids] != good] = np.nan
            pts = y.reshape(5, n)
            if not np.isfinite(pts).all(axis=0).any() or np.nanvar(pts[:2]) == 0:
                continue  # no variance: no indices to compare
            first_o, total_o, used = estimate(pts[0], pts[1], pts[2:])
            self.assertEqual(g["samples"], used)
            for i, fac in enumerate(g["factors"]):
                self.assertAlmostEqual(fac["first"], first_o[i], delta=1e-6 * max(1, abs(first_o[i])))
                self.assertAlmostEqual(fac["total"], total_o[i], delta=1e-6 * max(1, abs(total_o[i])))
        r = run("sensitivity", out, "--bootstrap", "0", "--metric", "iterations")
        self.assertIn(f"failed samples {failed_samples} of {n}", r.stdout)
        self.assertIn("conditional on success", r.stdout)
        with python_package()(out) as res:  # kinesweep.read: the same counts for the integer metric
            py = res.sensitivity(metric="iterations")
        self.assertEqual([(p["failed_samples"], p["not_done_samples"], p["good_status"]) for p in py],
                         [(failed_samples, 0, good)])
        cli_first = got[metrics.index("iterations")]["factors"][0]["first"]
        self.assertAlmostEqual(py[0]["first"][0], cli_first, delta=1e-5 * max(1, abs(cli_first)))


class MinorRefusals(TempDirTest):
    def test_negative_seed(self):
        r = run("sensitivity", "whatever.h5", "--seed", "-1")
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        self.assertIn("--seed", r.stdout + r.stderr)

    def test_robot_given_a_results_file(self):
        study = self.write("s.toml", IK.replace("count = 64", "count = 2"))
        out = os.path.join(self.dir, "r.h5")
        self.assertEqual(run("run", study, "-o", out, "-q").returncode, 0)
        for name in (out, out.replace(".h5", ".urdf")):
            if name != out:
                os.rename(out, name)
            with self.subTest(name=name):
                r = run("robot", name)
                self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
                self.assertIn("HDF5", r.stderr)
                self.assertNotIn("TOML", r.stderr.split("HDF5")[0])

    def test_saltelli_axis_with_a_bad_bound(self):
        for axis, expect in (('k = { saltelli = { from = 1, to = 0 } }', "from = 1 > to = 0"),
                             ('alpha1A = { saltelli = { from = -30 } }', "lacks from or to")):
            with self.subTest(axis=axis):
                study = self.write("bad.toml", f"""
[study]
name = "bad"
[[block]]
name = "b"
kind = "trajectory"
saltelli = {{ count = 4, seed = 1 }}
[block.axes]
{axis}
""")
                r = run("run", study, "-o", os.path.join(self.dir, "bad.h5"), "-q")
                self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
                self.assertIn(expect, r.stderr)
                self.assertNotIn("no axis uses them", r.stderr)


if __name__ == "__main__":
    KS = sys.argv.pop(1)
    SOURCE = sys.argv.pop(1)
    unittest.main()
