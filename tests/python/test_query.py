"""End-to-end tests of `kinesweep query` and `kinesweep info` against the file as read by h5py.

usage: /usr/bin/python3 test_query.py KINESWEEP_BINARY REPO_ROOT
"""
import csv
import hashlib
import io
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import h5py
import numpy as np

from e2e_common import OPTIMIZE as OPTIMIZE_COMMON, history, make_v1, runs_columns

KS = None
ROOT = None
D = 180.0 / math.pi

STUDY = """
[study]
name = "query_e2e"
histories = "every=10"

[[block]]
name = "weighted"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { from = -25, to = 35, step = 5 }
k = { from = 0, to = 1, count = 6 }

[[block]]
name = "basin"
kind = "ik"
problem = "scara"
[block.axes]
method = ["newton", "lm"]
q0_1 = { from = -180, to = 180, count = 9 }
q0_2 = { from = -180, to = 180, count = 9 }
"""

LIVE = """
[study]
name = "query_live"
histories = "full"

[[block]]
name = "sweep"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { from = -20, to = 30, step = 0.5 }
k = { from = 0, to = 1, count = 11 }
"""

# A coarse landscape and an [[optimize]] block polishing from it (sweep, global and local stages; seconds).
OPTIMIZE = OPTIMIZE_COMMON.replace('name = "e2e_optimize"', 'name = "query_opt"')


def ks(*args):
    return subprocess.run([KS, *args], capture_output=True, text=True)


def h5table(path):
    with h5py.File(path, "r") as f:
        out = runs_columns(f)
        units = {k: f["runs"][k].attrs.get("unit", "") for k in f["runs"]}
        units = {k: (u.decode() if isinstance(u, bytes) else u) for k, u in units.items()}
        return out, units


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def import_ksread():
    sys.path.insert(0, os.path.join(ROOT, "analysis"))
    from kinesweep import read as ksread
    return ksread


def read_csv(text):
    rows = list(csv.reader(io.StringIO(text)))
    return rows[0], rows[1:]


class QueryTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        study = os.path.join(cls.tmp.name, "q.toml")
        with open(study, "w") as f:
            f.write(STUDY)
        cls.h5 = os.path.join(cls.tmp.name, "q.h5")
        r = ks("run", study, "-o", cls.h5, "-q")
        assert r.returncode == 0, r.stderr
        cls.t, cls.units = h5table(cls.h5)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_filter_range_sort_csv_equal_h5py(self):
        r = ks("query", self.h5, "--where", "block=weighted", "--where", "status=ok", "--where", "k<=0.4",
               "--where", "-20<=alpha1A<=10", "--sort", "E:desc", "--columns", "run_id,alpha1A,k,E", "--format", "csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        head, rows = read_csv(r.stdout)
        self.assertEqual(head, ["run_id", "alpha1A [deg]", "k", "E"])
        t = self.t
        a = t["alpha1A"] * D
        m = (t["done"] == 1) & (t["block"] == "weighted") & (t["status"] == "ok") & (t["k"] <= 0.4) & \
            (a >= -20 - 1e-9) & (a <= 10 + 1e-9)
        idx = np.nonzero(m)[0]
        idx = idx[np.argsort(-t["E"][idx], kind="stable")]
        self.assertGreater(len(idx), 5)
        self.assertEqual([int(x[0]) for x in rows], t["run_id"][idx].tolist())
        np.testing.assert_array_equal([float(x[3]) for x in rows], t["E"][idx])  # exact: round-trip text
        np.testing.assert_allclose([float(x[1]) for x in rows], t["alpha1A"][idx] * D, rtol=1e-14)
        np.testing.assert_array_equal([float(x[2]) for x in rows], t["k"][idx])

    def test_json_all_columns_equal_h5py(self):
        r = ks("query", self.h5, "-w", "block=basin", "-w", "iterations<10", "-w", "method=newton,lm",
               "-f", "json")
        self.assertEqual(r.returncode, 0, r.stderr)
        j = json.loads(r.stdout)
        t = self.t
        m = (t["done"] == 1) & (t["block"] == "basin") & (t["iterations"] < 10)
        idx = np.nonzero(m)[0]
        self.assertEqual([row["run_id"] for row in j["rows"]], t["run_id"][idx].tolist())
        cols = [c for c in t if c != "done"]
        self.assertEqual(set(j["columns"]), set(cols))
        for c in cols:
            angle = self.units[c] == "rad"
            self.assertEqual(j["units"][c], "deg" if angle else self.units[c], c)
            for row, i in zip(j["rows"], idx):
                v, want = row[c], t[c][i]
                if t[c].dtype.kind == "f":
                    want = want * D if angle else want
                    if math.isnan(want):
                        self.assertIsNone(v, c)
                    else:
                        self.assertAlmostEqual(v, want, delta=1e-12 * max(1, abs(want)), msg=c)
                else:
                    self.assertEqual(v, want.item() if hasattr(want, "item") else want, c)

    def test_not_in_range_and_not_equal(self):
        r = ks("query", self.h5, "-w", "block=basin", "-w", "q0_1!=-180..0", "-w", "status!=converged",
               "-c", "run_id", "-f", "csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        _, rows = read_csv(r.stdout)
        t = self.t
        q = t["q0_1"] * D
        m = (t["block"] == "basin") & ((q < -180 - 1e-9) | (q > 0 + 1e-9)) & (t["status"] != "converged")
        self.assertEqual([int(x[0]) for x in rows], t["run_id"][m].tolist())
        self.assertGreater(len(rows), 0)

    def test_limit_and_multi_key_sort(self):
        r = ks("query", self.h5, "-w", "block=basin", "--sort", "iterations,error:desc", "--limit", "4",
               "-c", "run_id,iterations,error", "-f", "csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        _, rows = read_csv(r.stdout)
        t = self.t
        idx = np.nonzero(t["block"] == "basin")[0]
        order = sorted(idx, key=lambda i: (t["iterations"][i], -t["error"][i]))
        self.assertEqual([int(x[0]) for x in rows], [int(t["run_id"][i]) for i in order[:4]])

    def test_table_says_degrees(self):
        r = ks("query", self.h5, "-w", "block=weighted", "--limit", "3")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("alpha1A [deg]", r.stdout)
        self.assertIn("E [Nm]", r.stdout)
        self.assertIn("angles in degrees", r.stdout)
        r = ks("query", self.h5, "-w", "block=weighted", "--radians", "-c", "run_id,alpha1A", "-f", "csv")
        head, rows = read_csv(r.stdout)
        self.assertEqual(head, ["run_id", "alpha1A"])
        ids = [int(x[0]) for x in rows]
        np.testing.assert_array_equal([float(x[1]) for x in rows], self.t["alpha1A"][ids])

    def test_unknown_column_names_valid_ones(self):
        for args in (["-w", "Ee<3"], ["--sort", "Ee"], ["--columns", "run_id,Ee"]):
            r = ks("query", self.h5, *args)
            self.assertEqual(r.returncode, 2, args)
            self.assertIn("unknown column 'Ee'", r.stderr)
            self.assertIn("did you mean 'E'", r.stderr)
            self.assertIn("valid columns:", r.stderr)
            self.assertIn("alpha1A", r.stderr)
            self.assertIn("iterations", r.stderr)

    def test_bad_arguments(self):
        for args in (["-w", "E<<3"], ["-w", "E<abc"], ["-w", "E"], ["--format", "xml"], ["--sort", "E:down"],
                     ["--run", "100000", "--history", "tau"]):
            r = ks("query", self.h5, *args)
            self.assertEqual(r.returncode, 2, (args, r.stderr))

    def test_file_errors(self):
        self.assertEqual(ks("query", os.path.join(self.tmp.name, "missing.h5")).returncode, 1)
        bogus = os.path.join(self.tmp.name, "bogus.h5")
        with open(bogus, "w") as f:
            f.write("not hdf5")
        self.assertEqual(ks("query", bogus).returncode, 1)
        self.assertEqual(ks("info", bogus).returncode, 1)

    def test_a_study_file_is_named_as_no_results_file(self):
        study = os.path.join(self.tmp.name, "x.toml")
        with open(study, "w") as f:
            f.write(STUDY)
        for cmd in ("query", "info"):
            t0 = time.time()
            r = ks(cmd, study)
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertEqual(r.stdout, "")
            lines = r.stderr.strip().splitlines()
            self.assertEqual(len(lines), 1, r.stderr)  # one line, no HDF5 error stack
            self.assertIn(study, lines[0])
            self.assertIn("not an HDF5 file", lines[0])
            self.assertIn("expected a kinesweep results file", lines[0])
            self.assertNotIn("HDF5-DIAG", r.stderr)
            self.assertLess(time.time() - t0, 1.0, "no retries for a file that is no results file")

    def test_negative_counts_are_rejected(self):
        for args in (["info", self.h5, "--best", "-1"], ["query", self.h5, "-n", "-3"],
                     ["query", self.h5, "--limit=-3"], ["query", self.h5, "--optimization", "x", "-n", "-1"]):
            r = ks(*args)
            self.assertEqual(r.returncode, 2, (args, r.stdout, r.stderr))
            self.assertIn("0 or more", r.stderr)
            self.assertEqual(r.stdout, "")
        self.assertEqual(ks("info", self.h5, "--best", "0").returncode, 0)
        r = ks("query", self.h5, "-n", "0", "-c", "run_id", "-f", "csv")
        self.assertEqual((r.returncode, r.stdout), (0, "run_id\n"))

    def test_value_no_row_holds_gets_a_hint(self):
        r = ks("query", self.h5, "-w", "method=local_weightd")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("(0 of 0 matching rows", r.stdout)
        self.assertIn("no row has method = 'local_weightd'; did you mean 'local_weighted'?", r.stderr)
        r = ks("query", self.h5, "-w", "block=weighted,basni", "-c", "run_id", "-f", "csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(len(read_csv(r.stdout)[1]), int((self.t["block"] == "weighted").sum()))
        self.assertIn("no row has block = 'basni'; did you mean 'basin'?", r.stderr)
        r = ks("query", self.h5, "-w", "status=zzz")
        self.assertIn("no row has status = 'zzz' (values: ", r.stderr)
        r = ks("query", self.h5, "-w", "method=newton", "-c", "run_id")  # a held value: no note
        self.assertEqual(r.stderr, "")

    def test_column_attributes_describe_every_column(self):
        """role / kinds / unit / description of every /runs column (h5py) against what the engine writes."""
        with h5py.File(self.h5, "r") as f:
            self.assertEqual(int(f.attrs["format_version"]), 5)
            runs = f["runs"]
            attrs = {k: {a: h5s(runs[k].attrs[a]) for a in ("role", "kinds", "unit", "description")} for k in runs}
        for c in ("run_id", "block", "status", "wall_time", "done"):
            self.assertEqual((attrs[c]["role"], attrs[c]["kinds"]), ("bookkeeping", ""), c)
        for c in ("preset", "alpha1A", "k", "K_N", "dt", "inertia", "vertex_alpha_2"):
            self.assertEqual((attrs[c]["role"], attrs[c]["kinds"]), ("parameter", "trajectory"), c)
        for c in ("problem", "q0_1", "q0_2", "q0_3", "max_iter", "z_mode"):
            self.assertEqual((attrs[c]["role"], attrs[c]["kinds"]), ("parameter", "ik"), c)
        self.assertEqual((attrs["method"]["role"], sorted(attrs["method"]["kinds"].split(","))),
                         ("parameter", ["ik", "trajectory"]))
        for c in ("E", "E_M", "tau_inf", "stop_time"):
            self.assertEqual((attrs[c]["role"], attrs[c]["kinds"]), ("metric", "trajectory"), c)
        for c in ("iterations", "error", "solution", "q_final_3"):
            self.assertEqual((attrs[c]["role"], attrs[c]["kinds"]), ("metric", "ik"), c)
        self.assertEqual((attrs["E"]["unit"], attrs["alpha1A"]["unit"], attrs["wall_time"]["unit"]), ("Nm", "rad", "s"))
        for c, a in attrs.items():
            self.assertIn(a["role"], ("parameter", "metric", "bookkeeping"), c)
            self.assertTrue(a["description"], c)
        # in a row of kind K, every column that does not apply to K holds the missing value
        t = self.t
        for c, a in attrs.items():
            if not a["kinds"]:
                continue
            for kind, block in (("trajectory", "weighted"), ("ik", "basin")):
                if kind in a["kinds"].split(","):
                    continue
                v = t[c][t["block"] == block]
                missing = np.isnan(v) if v.dtype.kind == "f" else (v == -1) if v.dtype.kind == "i" else (v == "")
                self.assertTrue(np.all(missing), (c, block))
        # ksread reads the same roles and each row's kind
        ksread = import_ksread()
        with ksread.open_results(self.h5) as r:
            self.assertEqual(r.roles(), {c: a["role"] for c, a in attrs.items() if c != "done"})
            self.assertEqual(r.metrics("ik"), ["iterations", "error", "solution", "rejected", "min_rcond",
                                               "restarts_used", "q_final_1", "q_final_2", "q_final_3"])
            self.assertIn("method", r.parameters("trajectory"))
            self.assertIn("method", r.parameters("ik"))
            self.assertEqual(r.bookkeeping(), ["run_id", "block", "status", "wall_time"])
            runs = r.runs(columns=["block"])
            kinds = r.row_kinds()
            self.assertEqual(set(zip(runs["block"], kinds)), {("weighted", "trajectory"), ("basin", "ik")})
            self.assertEqual(runs.roles["block"], "bookkeeping")
            self.assertEqual((r.landscape("weighted").kind, r.landscape("basin").kind), ("trajectory", "ik"))

    def test_trajectory_history_csv(self):
        t = self.t
        run = int(np.nonzero((t["block"] == "weighted") & (t["status"] == "ok"))[0][3])
        r = ks("query", self.h5, "--run", str(run), "--history", "tau,q")
        self.assertEqual(r.returncode, 0, r.stderr)
        head, rows = read_csv(r.stdout)
        self.assertEqual(head, ["t", "tau_1", "tau_2", "tau_3", "q_1 [deg]", "q_2 [deg]", "q_3 [deg]"])
        a = np.array(rows, dtype=float)
        with h5py.File(self.h5, "r") as f:
            h = history(f, run)
            np.testing.assert_array_equal(a[:, 0], h["t"][:, 0])
            np.testing.assert_array_equal(a[:, 1:4], h["tau"])
            np.testing.assert_allclose(a[:, 4:7], h["q"] * D, rtol=1e-14, atol=1e-12)

    def test_ik_history_json(self):
        t = self.t
        run = int(np.nonzero((t["block"] == "basin") & (t["iterations"] > 5))[0][0])
        r = ks("query", self.h5, "--run", str(run), "--history", "norm_F", "--format", "json")
        self.assertEqual(r.returncode, 0, r.stderr)
        j = json.loads(r.stdout)
        self.assertEqual(j["columns"], ["k", "norm_F"])
        with h5py.File(self.h5, "r") as f:
            h = history(f, run)
            self.assertEqual([row["k"] for row in j["rows"]], h["k"][:, 0].astype(int).tolist())
            np.testing.assert_array_equal([row["norm_F"] for row in j["rows"]], h["norm_F"][:, 0])
        r = ks("query", self.h5, "--run", str(run), "--history", "tau")
        self.assertEqual(r.returncode, 2)
        self.assertIn("valid arrays", r.stderr)

    def test_info(self):
        r = ks("info", self.h5)
        self.assertEqual(r.returncode, 0, r.stderr)
        out = r.stdout
        t = self.t
        with h5py.File(self.h5, "r") as f:
            a = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
            landscapes = list(f["landscapes"])
        for key in ("study_name", "study_sha256", "engine_version"):
            self.assertIn(str(a[key]), out)
        self.assertIn(f"{int(t['done'].sum())} of {len(t['done'])} done", out)
        lines = out.splitlines()
        for b in ("weighted", "basin"):
            line = next(x for x in lines if x.startswith(b + " "))
            m = t["block"] == b
            self.assertIn(f" {int(m.sum())} ", line)
            for st in set(t["status"][m]):
                self.assertIn(f"{st} {int((t['status'][m] == st).sum())}", line)
        ok = np.nonzero((t["block"] == "weighted") & (t["status"] == "ok"))[0]
        best = ok[np.argmin(t["E"][ok])]
        best_line = next(x for x in lines if x.strip().startswith("weighted") and " run " in x)
        self.assertIn(f"run {best:>6}", best_line)
        self.assertIn(f"E = {t['E'][best]:.6g}", best_line)
        for name in landscapes:
            self.assertIn(name + ":", out)
        self.assertIn("histories", out)
        self.assertNotIn("optimizations", out)  # the file has none: no section

    def test_live_file_while_sweep_writes(self):
        study = os.path.join(self.tmp.name, "live.toml")
        with open(study, "w") as f:
            f.write(LIVE)
        out = os.path.join(self.tmp.name, "live.h5")
        p = subprocess.Popen([KS, "run", study, "-o", out, "--threads", "1", "-q"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        seen = []
        try:
            deadline = time.time() + 120
            while p.poll() is None and time.time() < deadline:
                if not os.path.exists(out):
                    time.sleep(0.02)
                    continue
                r = ks("query", out, "-c", "run_id,E", "-f", "csv")
                self.assertEqual(r.returncode, 0, r.stderr)
                _, rows = read_csv(r.stdout)
                seen.append(rows)
                i = ks("info", out)
                self.assertEqual(i.returncode, 0, i.stderr)
                if rows:
                    h = ks("query", out, "--run", rows[-1][0], "--history", "tau", "--limit", "2")
                    self.assertEqual(h.returncode, 0, h.stderr)
        finally:
            p.wait(timeout=300)
        self.assertEqual(p.returncode, 0)
        final, _ = h5table(out)
        for rows in seen:  # every row seen during the sweep is the final row
            ids = [int(x[0]) for x in rows]
            self.assertTrue(np.all(final["done"][ids] == 1))
            np.testing.assert_array_equal([float(x[1]) for x in rows], final["E"][ids])
        self.assertGreater(len(seen), 0)
        partial = [len(s) for s in seen if len(s) < len(final["done"])]
        print(f"\n  live: {len(seen)} reads during the sweep, {len(partial)} of a partial file "
              f"({min(partial) if partial else '-'}..{max(partial) if partial else '-'} of {len(final['done'])} rows)",
              file=sys.stderr)


class Version1FileTest(unittest.TestCase):
    """A results file of format_version 1 (no role / kinds attributes): info and query still read it,
    with the roles of the engine's tables; ksread and --resume refuse it, naming the version."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.study = os.path.join(cls.tmp.name, "q.toml")
        with open(cls.study, "w") as f:
            f.write(STUDY)
        cls.v2 = os.path.join(cls.tmp.name, "v2.h5")
        r = ks("run", cls.study, "-o", cls.v2, "-q")
        assert r.returncode == 0, r.stderr
        cls.v1 = os.path.join(cls.tmp.name, "v1.h5")
        make_v1(cls.v2, cls.v1)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_query_reads_it_as_the_v2_file(self):
        for args in ([], ["-w", "block=basin", "-n", "5"], ["-w", "block=weighted", "--sort", "E"],
                     ["-f", "csv", "-w", "status=ok"], ["-f", "json", "-n", "7"]):
            a, b = ks("query", self.v1, *args), ks("query", self.v2, *args)
            self.assertEqual(a.returncode, 0, a.stderr)
            self.assertEqual(a.stdout, b.stdout, args)  # same compact columns: same roles and kinds
        self.assertIn("iterations", ks("query", self.v1, "-w", "block=basin", "-n", "1").stdout)

    def test_info_reads_it_and_says_where_the_roles_come_from(self):
        a, b = ks("info", self.v1), ks("info", self.v2)
        self.assertEqual(a.returncode, 0, a.stderr)
        self.assertIn("format kinesweep-results v1", a.stdout)
        self.assertIn("format v1 stores no column roles", a.stdout)
        drop = ("file ", "engine ", "note ")
        same = lambda out: [x for x in out.splitlines() if not x.startswith(drop)]
        self.assertEqual(same(a.stdout), same(b.stdout))
        self.assertIn("weighted  trajectory", a.stdout)
        self.assertIn("basin     ik", a.stdout)

    def test_ksread_refuses_it_naming_the_version(self):
        ksread = import_ksread()
        with self.assertRaises(ksread.FormatVersionError) as e:
            ksread.open_results(self.v1)
        msg = str(e.exception)
        self.assertIn(self.v1, msg)
        self.assertIn("format v1", msg)
        self.assertIn("kinesweep query", msg)
        self.assertIn("--overwrite", msg)
        with ksread.open_results(self.v2) as r:  # the v2 file opens
            self.assertGreater(len(r.runs()), 0)

    def test_resume_is_refused_and_the_file_untouched(self):
        before = sha256(self.v1), os.stat(self.v1).st_mtime_ns
        r = ks("run", self.study, "-o", self.v1, "--resume", "-q")
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("results file format v1 (written by kinesweep ", r.stderr)
        self.assertIn("); this kinesweep resumes v3 to v5: rerun with --overwrite", r.stderr)
        self.assertEqual((sha256(self.v1), os.stat(self.v1).st_mtime_ns), before)
        self.assertFalse(os.path.exists(self.v1 + ".journal"))
        self.assertEqual(sorted(os.listdir(self.tmp.name)), ["q.toml", "v1.h5", "v2.h5"])


def h5s(v):
    return v.decode() if isinstance(v, bytes) else str(v)


class OptimizationQueryTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        study = os.path.join(cls.tmp.name, "opt.toml")
        with open(study, "w") as f:
            f.write(OPTIMIZE)
        cls.h5 = os.path.join(cls.tmp.name, "opt.h5")
        r = ks("run", study, "-o", cls.h5, "-q")
        assert r.returncode == 0, r.stderr
        with h5py.File(cls.h5, "r") as f:
            g = f["optimizations"]["h1"]
            cls.a = {k: (h5s(v) if isinstance(v, (bytes, str)) else v) for k, v in g.attrs.items()}
            cls.variables = [h5s(v) for v in g.attrs["variables"]]
            cls.units = [h5s(v) for v in g.attrs["units"]]
            e = g["evaluations"]
            cls.ev = {"x": e["x"][()], "objective": e["objective"][()], "constraint": e["constraint"][()],
                      "stage": [h5s(v) for v in e["stage"][()]], "status": [h5s(v) for v in e["status"][()]],
                      "start": e["start"][()]}
            cls.stages = [h5s(v) for v in g["stages"]["name"][()]]
            cls.algorithms = [h5s(v) for v in g["stages"]["algorithm"][()]]

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_info_shows_the_optimization(self):
        r = ks("info", self.h5)
        self.assertEqual(r.returncode, 0, r.stderr)
        out = r.stdout
        sec = out[out.index("optimizations 1"):]
        self.assertIn("h1: trajectory, preset 1h, minimise E", sec)
        self.assertIn("alpha1A in [-30, 10] deg, k in [0, 1]", sec)
        self.assertIn(f"evaluations {len(self.ev['objective'])} in", sec)
        best = next(x for x in sec.splitlines() if x.strip().startswith("best "))
        self.assertIn(f"E = {self.a['best_objective']:.6g} [{self.a['best_status']}, stage {self.a['best_stage']}]",
                      best)
        self.assertIn(f"alpha1A = {self.a['best_x'][0] * D:.6g} deg", best)
        self.assertEqual(self.stages, ["sweep", "global", "local"])
        stage_lines = [x.replace("stages", "", 1).split() for x in sec.splitlines() if " evals " in x]
        self.assertEqual([x[0] for x in stage_lines], self.stages)  # one line per stage, in order
        self.assertEqual([x[1] for x in stage_lines], [a or "-" for a in self.algorithms])
        self.assertIn(f"E = {self.a['reference_thesis_E']:.6g} at alpha1A = "
                      f"{self.a['reference_thesis_alpha1A'] * D:.6g} deg, k = {self.a['reference_thesis_k']:.6g}", sec)
        self.assertIn(f"E at the thesis point = {self.a['reference_objective_at_thesis_x']:.6g}", sec)
        self.assertIn("best run    E = ", sec)

    def check_rows(self, idx, got_x, got):
        ev = self.ev
        np.testing.assert_array_equal([g["index"] for g in got], idx)
        self.assertEqual([g["stage"] for g in got], [ev["stage"][i] for i in idx])
        self.assertEqual([g["status"] for g in got], [ev["status"][i] for i in idx])
        np.testing.assert_array_equal([g["start"] for g in got], ev["start"][idx])
        np.testing.assert_array_equal([g["objective"] for g in got], ev["objective"][idx])
        c = np.array([np.nan if g["constraint"] is None else g["constraint"] for g in got], dtype=float)
        np.testing.assert_array_equal(c, ev["constraint"][idx])
        scale = np.array([D if u == "rad" else 1.0 for u in self.units])
        np.testing.assert_allclose(got_x, ev["x"][idx] * scale, rtol=1e-14, atol=1e-14)

    def test_query_csv_equals_h5py(self):
        r = ks("query", self.h5, "--optimization", "h1", "--format", "csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        head, rows = read_csv(r.stdout)
        self.assertEqual(head, ["index", "stage", "start", "alpha1A [deg]", "k", "objective", "constraint", "status"])
        self.assertEqual(len(rows), len(self.ev["objective"]))
        got = [{"index": int(x[0]), "stage": x[1], "start": int(x[2]), "objective": float(x[5]),
                "constraint": None if x[6] == "" else float(x[6]), "status": x[7]} for x in rows]
        self.check_rows(np.arange(len(rows)), np.array([[float(x[3]), float(x[4])] for x in rows]), got)
        self.assertEqual(set(self.ev["stage"]), {"sweep", "global", "local"})

    def test_query_json_limit_and_table(self):
        r = ks("query", self.h5, "--optimization", "h1", "-f", "json", "--limit", "20")
        self.assertEqual(r.returncode, 0, r.stderr)
        j = json.loads(r.stdout)
        self.assertEqual(j["units"]["alpha1A"], "deg")
        self.assertEqual(len(j["rows"]), 20)
        self.check_rows(np.arange(20), np.array([[g["alpha1A"], g["k"]] for g in j["rows"]]), j["rows"])
        r = ks("query", self.h5, "--optimization", "h1", "--radians", "-f", "json")
        j = json.loads(r.stdout)
        np.testing.assert_array_equal([g["alpha1A"] for g in j["rows"]], self.ev["x"][:, 0])
        r = ks("query", self.h5, "--optimization", "h1", "-n", "3")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("alpha1A [deg]", r.stdout)
        self.assertIn(f"(3 of {len(self.ev['objective'])} evaluations of optimization h1", r.stdout)

    def test_unknown_optimization(self):
        r = ks("query", self.h5, "--optimization", "h2")
        self.assertEqual(r.returncode, 2)
        self.assertIn("no optimization 'h2'", r.stderr)
        self.assertIn("valid optimizations: h1", r.stderr)
        r = ks("query", self.h5, "--optimization", "h1", "--where", "E<3")
        self.assertEqual(r.returncode, 2)


if __name__ == "__main__":
    KS, ROOT = sys.argv[1], sys.argv[2]
    unittest.main(argv=[sys.argv[0]] + sys.argv[3:], verbosity=2)
