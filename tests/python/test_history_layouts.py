"""The /histories layouts of format_version 2 (one group per run) and 3 and 4 (one shared row space,
FORMAT.md) read the same through every Python reader: kinesweep.read (has_history, history_arrays, history_ids,
history_count, history, read_history), kinesweep.history, regression_hashes' per-array hashes, check_store's
history check, report_traces and the plot commands (plot_histories, plot_convergence).

The test writes the files itself with h5py, from histories it generates (the oracle): trajectory and
IK runs, an IK array of another column count (dataset `F.2` holding array F), a run without a history,
a run whose history has 0 rows, a history exactly one chunk long, a run not done, v3 runs stored in an
order other than their ids (NaN padding rows between them), one v3 file with spare rows past
`used_rows` and one without, and a v4 file (the v3 layout, its labelled /runs text columns HDF5
enums). Every reader's answer must equal the oracle, in every file.

usage: /usr/bin/python3 test_history_layouts.py [REPO_ROOT]
"""
import contextlib
import hashlib
import io
import json
import os
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
RAD2DEG = 180.0 / np.pi
C = 4          # chunk_rows of the v3 files
N = 10         # runs
STR = h5py.string_dtype()
MISSING_CODE = 255  # the missing value of a labelled column (FORMAT.md, "/runs"): no enum member
# The labels (by code) of the /runs text columns a v4 file stores as enums, as the engine declares them:
# every block, the methods of both kinds, the statuses of both kinds (some never held by a row).
LABELS = {
    "block": ["traj", "ik"],
    "method": ["local_weighted", "local_unweighted", "vertex_alpha", "newton", "lm", "lm_adaptive", "halley_thesis",
               "halley", "analytic"],
    "status": ["ok", "unreachable_start", "singular", "diverged", "undersampled", "off_path", "out_of_limits",
               "converged", "stalled", "max_iter", "cycle", "no_solution", "unsupported"],
}

# run id -> (kind, block, method, lambda, history layout or None, history rows, done)
#   "traj": t (1, s), q (3, rad), qd (3, rad/s), tau (3, Nm)
#   "ik3":  k (1), q (2, "rad, rad"), F (3), norm_F (1)      -> v3 datasets k, q.2, F, norm_F
#   "ik2":  k (1), q (2, "rad, rad"), F (2), norm_F (1)      -> v3 datasets k, q.2, F.2, norm_F
RUNS = {
    0: ("trajectory", "traj", "local_weighted", np.nan, "traj", 5, 1),
    1: ("trajectory", "traj", "local_weighted", np.nan, None, 0, 1),
    2: ("ik", "ik", "lm", 0.1, "ik3", 7, 1),
    3: ("trajectory", "traj", "local_unweighted", np.nan, "traj", 0, 1),
    4: ("ik", "ik", "newton", np.nan, "ik2", 4, 1),
    5: ("trajectory", "traj", "local_weighted", np.nan, "traj", 9, 1),
    6: ("ik", "ik", "lm", 0.1, "ik3", 1, 0),
    7: ("trajectory", "traj", "vertex_alpha", np.nan, "traj", C, 1),
    8: ("ik", "ik", "lm", 0.01, "ik2", 6, 1),
    9: ("ik", "ik", "lm_adaptive", 0.1, None, 0, 1),
}
ARRAYS = {
    "traj": [("t", 1, "s"), ("q", 3, "rad"), ("qd", 3, "rad/s"), ("tau", 3, "Nm")],
    "ik3": [("k", 1, ""), ("q", 2, "rad, rad"), ("F", 3, "problem units"), ("norm_F", 1, "problem units")],
    "ik2": [("k", 1, ""), ("q", 2, "rad, rad"), ("F", 2, "problem units"), ("norm_F", 1, "problem units")],
}


def oracle_histories(seed=7):
    """run id -> [(array name, rows x cols float64, unit)] for the runs with a history."""
    rng = np.random.default_rng(seed)
    out = {}
    for i, (_, _, _, _, layout, n, _) in RUNS.items():
        if layout is None:
            continue
        arrays = []
        for name, cols, unit in ARRAYS[layout]:
            if name in ("t", "k"):
                v = np.arange(n, dtype=float).reshape(n, 1) * (0.01 if name == "t" else 1.0)
            elif name == "norm_F":
                v = np.exp(-rng.uniform(0.5, 2.0) * np.arange(n)).reshape(n, 1)
            else:
                v = rng.normal(0.0, 2.0, (n, cols))
            arrays.append((name, v, unit))
        out[i] = arrays
    # values that only a bit-exact copy keeps: a NaN with a payload, -0, a subnormal
    qd = out[5][2][1]
    qd[1, 0] = np.frombuffer(np.uint64(0x7FF8000000000123).tobytes(), dtype="<f8")[0]
    qd[2, 1], qd[3, 2] = -0.0, 5e-324
    return out


# --- writing the files -------------------------------------------------------------------------

def write_common(f, version):
    f.attrs["format"] = "kinesweep-results"
    f.attrs["format_version"] = np.int64(version)
    f.attrs["engine_version"] = "test"
    f.attrs["study_sha256"] = "0" * 64
    f.attrs["created"] = "2000-01-01T00:00:00Z"
    f.attrs["study_name"] = "layouts"
    f.create_dataset("study/text", data="[study]\nname = \"layouts\"\n", dtype=STR)
    f["study"].attrs["path"] = "layouts.toml"
    kinds = [RUNS[i][0] for i in range(N)]
    ik = np.array([k == "ik" for k in kinds])
    cols = [  # name, values, unit, type, role, kinds
        ("run_id", np.arange(N, dtype=np.int64), "", "i64", "bookkeeping", ""),
        ("block", [RUNS[i][1] for i in range(N)], "", "str", "bookkeeping", ""),
        ("method", [RUNS[i][2] for i in range(N)], "", "str", "parameter", "trajectory,ik"),
        ("alpha1A", np.where(ik, np.nan, np.arange(N) * 0.1), "rad", "f64", "parameter", "trajectory"),
        ("lambda", np.array([RUNS[i][3] for i in range(N)]), "", "f64", "parameter", "ik"),
        ("q0_1", np.where(ik, np.arange(N) * 0.2, np.nan), "rad", "f64", "parameter", "ik"),
        ("q0_2", np.where(ik, -np.arange(N) * 0.3, np.nan), "rad", "f64", "parameter", "ik"),
        ("E", np.where(ik, np.nan, np.arange(N) + 40.0), "Nm", "f64", "metric", "trajectory"),
        ("iterations", np.where(ik, np.arange(N) + 3, -1).astype(np.int64), "", "i64", "metric", "ik"),
        ("status", ["converged" if k == "ik" else "ok" for k in kinds], "", "str", "bookkeeping", ""),
        ("wall_time", np.full(N, 0.001), "s", "f64", "bookkeeping", ""),
    ]
    runs = f.create_group("runs")
    runs.attrs["columns"] = np.array([c[0] for c in cols], dtype=STR)
    runs.attrs["n_runs"] = np.int64(N)
    for name, values, unit, typ, role, kind in cols + [("done", np.array([RUNS[i][6] for i in range(N)], dtype=np.uint8),
                                                        "", "u8", "bookkeeping", "")]:
        if version >= 4 and name in LABELS:
            d = create_labelled(runs, name, values, LABELS[name])
        else:
            d = runs.create_dataset(name, data=values, dtype=STR if typ == "str" else None)
        d.attrs.update({"unit": unit, "description": name, "type": typ, "role": role, "kinds": kind})


def create_labelled(runs, name, values, labels):
    """A labelled text column of format_version 4 (FORMAT.md, "/runs"): an enum over uint8, label =
    code 0..L-1, "" stored as the missing code; chunked through shuffle + deflate; CF attributes."""
    codes = np.array([labels.index(v) if v else MISSING_CODE for v in values], dtype=np.uint8)
    dt = h5py.enum_dtype({label: code for code, label in enumerate(labels)}, basetype=np.uint8)
    d = runs.create_dataset(name, data=codes, dtype=dt, chunks=(len(codes),), shuffle=True, compression="gzip",
                            fillvalue=MISSING_CODE)
    d.attrs["flag_values"] = np.arange(len(labels), dtype=np.uint8)
    d.attrs["flag_meanings"] = " ".join(label.replace(" ", "_") for label in labels)
    d.attrs["_FillValue"] = np.uint8(MISSING_CODE)
    return d


def write_v2(path, hist, version=2):
    """One group per run: /histories/<6-digit id>/<array>, attribute arrays; one chunk per array."""
    with h5py.File(path, "w") as f:
        write_common(f, version)
        g = f.create_group("histories")
        for i, arrays in hist.items():
            run = g.create_group(f"{i:06d}")
            run.attrs["arrays"] = np.array([a for a, _, _ in arrays], dtype=STR)
            for a, v, unit in arrays:
                kw = dict(chunks=v.shape, shuffle=True, compression="gzip") if v.size else {}
                run.create_dataset(a, data=v, dtype="<f8", **kw).attrs["unit"] = unit


def write_v3(path, hist, order, spare_chunks, compression, version=3):
    """The ragged layout of FORMAT.md, format_version 3 (or `version`: 4 has the same layout); runs
    stored in `order`, each from a chunk boundary; `spare_chunks` chunks of rows past used_rows."""
    first_cols, datasets, layouts, placed = {}, {}, [], {}
    end = 0
    for i in order:
        names = []
        for a, v, unit in hist[i]:
            cols = v.shape[1]
            d = a if first_cols.setdefault(a, cols) == cols else f"{a}.{cols}"
            datasets.setdefault(d, (a, cols, unit))
            names.append(d)
        key = ",".join(names)
        if key not in layouts:
            layouts.append(key)
        n = hist[i][0][1].shape[0]
        placed[i] = (end, n, layouts.index(key))
        end += -(-n // C) * C
    start, rows, layout = np.full(N, -1, np.int64), np.zeros(N, np.int64), np.full(N, -1, np.int64)
    for i, (s, n, j) in placed.items():
        start[i], rows[i], layout[i] = s, n, j
    with h5py.File(path, "w") as f:
        write_common(f, version)
        g = f.create_group("histories")
        g.attrs["chunk_rows"] = np.int64(C)
        g.attrs["layouts"] = np.array(layouts, dtype=STR)
        g.attrs["used_rows"] = np.int64(end)
        g["start"], g["rows"], g["layout"] = start, rows, layout
        filters = dict(shuffle=True, compression="gzip") if compression else {}
        for d, (a, cols, unit) in datasets.items():
            ds = g.create_dataset(d, shape=(end + spare_chunks * C, cols), maxshape=(None, cols), chunks=(C, cols),
                                  dtype="<f8", fillvalue=np.nan, **filters)
            ds.attrs["unit"], ds.attrs["array"] = unit, a
        for i, (s, n, j) in placed.items():
            for d, (_, v, _) in zip(layouts[j].split(","), hist[i]):
                if n:
                    g[d][s:s + n] = v
    return placed


def same_bits(x, y):
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return x.shape == y.shape and np.array_equal(x.view(np.uint64), y.view(np.uint64))


def in_degrees(v, unit):
    """An array and its unit with angles in degrees: one unit for every column, or one per column."""
    if unit == "rad":
        return v * RAD2DEG, "deg"
    parts = [p.strip() for p in unit.split(",")]
    if len(parts) == v.shape[1]:
        scale = np.array([RAD2DEG if p == "rad" else 1.0 for p in parts])
        return v * scale, ", ".join("deg" if p == "rad" else p for p in parts)
    return v, unit


class HistoryLayouts(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, os.path.join(ROOT, "analysis"))
        sys.path.insert(0, HERE)
        cls.tmp = tempfile.TemporaryDirectory()
        cls.hist = oracle_histories()
        d = cls.tmp.name
        cls.v2 = os.path.join(d, "v2.h5")
        write_v2(cls.v2, cls.hist)
        cls.v3 = os.path.join(d, "v3.h5")  # stored out of id order, a spare chunk past used_rows
        cls.placed = write_v3(cls.v3, cls.hist, [8, 2, 5, 3, 0, 4, 7, 6], spare_chunks=1, compression=True)
        cls.v3b = os.path.join(d, "v3b.h5")  # the 0-row run stored last, no spare rows, no filter
        cls.placed_b = write_v3(cls.v3b, cls.hist, [7, 6, 5, 4, 2, 0, 8, 3], spare_chunks=0, compression=False)
        cls.v4 = os.path.join(d, "v4.h5")  # as v3, its block, method and status columns enums
        write_v3(cls.v4, cls.hist, [8, 2, 5, 3, 0, 4, 7, 6], spare_chunks=1, compression=True, version=4)
        cls.files = {"v2": cls.v2, "v3": cls.v3, "v3b": cls.v3b, "v4": cls.v4}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_the_v3_files_are_as_the_test_means(self):
        """The layout the writer above produced: padding, a renamed dataset, the 0-row and empty runs."""
        with h5py.File(self.v3, "r") as f:  # run 8 (F and q of 2 columns) stored first
            g = f["histories"]
            self.assertEqual({d: g[d].attrs["array"] for d in ("F", "F.3", "q", "q.3")},
                             {"F": "F", "F.3": "F", "q": "q", "q.3": "q"})
            self.assertEqual((g["F"].shape[1], g["q"].shape[1]), (2, 2))
            self.assertEqual((g["start"][1], g["rows"][1], g["layout"][1]), (-1, 0, -1))
            self.assertEqual((g["rows"][3], g["layout"][3] >= 0), (0, True))
            s, n = int(g["start"][0]), int(g["rows"][0])
            self.assertTrue(s % C == 0 and n % C != 0 and np.all(np.isnan(g["tau"][s + n:s + n + C - n % C])))
            self.assertGreater(g["q"].shape[0], int(g.attrs["used_rows"]))
            self.assertNotEqual(sorted(self.placed, key=lambda i: self.placed[i][0]), sorted(self.placed))
        with h5py.File(self.v3b, "r") as f:  # run 7 (q of 3 columns) stored first, then run 6 (F of 3)
            g = f["histories"]
            self.assertEqual(sorted(d for d in g if "." in d), ["F.2", "q.2"])
            self.assertEqual(int(g["start"][3]), g["q"].shape[0])  # the 0-row run starts at the very end

    def test_ksread(self):
        from kinesweep import read as ksread
        want_ids = sorted(self.hist)
        for name, path in self.files.items():
            with self.subTest(file=name), ksread.open_results(path) as r:
                self.assertEqual(r.history_ids().tolist(), want_ids)
                self.assertEqual(r.history_count(), len(want_ids))
                for i in list(range(N)) + [N, N + 100, -1]:
                    want = self.hist.get(i)
                    self.assertEqual(r.has_history(i), want is not None, i)
                    self.assertEqual(r.history_arrays(i), [a for a, _, _ in want] if want else [], i)
                    if want is None:
                        with self.assertRaises(KeyError):
                            r.history(i)
                        continue
                    for degrees in (False, True):
                        h = r.history(i, degrees=degrees)
                        self.assertEqual(list(h), [a for a, _, _ in want])
                        for a, v, unit in want:
                            if degrees:
                                v, unit = in_degrees(v, unit)
                            self.assertTrue(same_bits(h[a], v), (i, a, degrees))
                            self.assertEqual(h.units[a], unit, (i, a))
                h = ksread.read_history(path, 5)
                self.assertTrue(same_bits(h["qd"], self.hist[5][2][1]))

    def test_ksread_runs_the_same_in_every_file(self):
        """/runs reads the same whatever the format: the v4 file's enum codes as their labels."""
        from kinesweep import read as ksread
        with h5py.File(self.v4, "r") as f:
            for name, labels in LABELS.items():
                self.assertIsNotNone(h5py.check_enum_dtype(f["runs"][name].dtype), name)
        want = {"block": [RUNS[i][1] for i in range(N)], "method": [RUNS[i][2] for i in range(N)],
                "status": ["converged" if RUNS[i][0] == "ik" else "ok" for i in range(N)]}
        for name, path in self.files.items():
            with self.subTest(file=name), ksread.open_results(path) as r:
                t = r.runs(done_only=False)
                for c, values in want.items():
                    self.assertEqual(t[c].tolist(), values, c)
                self.assertEqual(r.blocks(), ["traj", "ik"])
                self.assertEqual(r.row_kinds(done_only=False).tolist(), [RUNS[i][0] for i in range(N)])

    def test_kshistory_items_in_run_id_order(self):
        from kinesweep import history as kshistory
        for name, path in self.files.items():
            with self.subTest(file=name), h5py.File(path, "r") as f:
                items = list(kshistory.Histories(f).items())
                self.assertEqual([i for i, _ in items], sorted(self.hist))
                for i, arrays in items:
                    self.assertEqual([(a, u) for a, _, u in arrays], [(a, u) for a, _, u in self.hist[i]])
                    self.assertTrue(all(same_bits(x, y) for (_, x, _), (_, y, _) in zip(arrays, self.hist[i])))

    def test_regression_hashes_equal_for_both_layouts(self):
        """Per array name over the runs that have it in run-id order: run id, shape, values (the
        encoding regression_hashes documents), computed here from the oracle."""
        import regression_hashes
        want, counts = {}, {}
        for i in sorted(self.hist):
            for a, v, _ in self.hist[i]:
                h = want.setdefault(a, hashlib.sha256())
                h.update(np.int64(i).astype("<i8").tobytes() + np.array(v.shape, "<i8").tobytes() + v.astype("<f8").tobytes())
                counts[a] = counts.get(a, 0) + 1
        want = {f"histories/{a}": {"class": "f", "runs": counts[a], "sha256": h.hexdigest()} for a, h in want.items()}
        got = {n: regression_hashes.hash_results(p) for n, p in self.files.items()}
        for name, items in got.items():
            with self.subTest(file=name):
                self.assertEqual({k: v for k, v in items.items() if k.startswith("histories/")}, want)
                self.assertEqual(items, got["v2"])  # the /runs items too: the files differ in /histories only

    def test_check_store_history_check_accepts_both_and_catches_bad_padding(self):
        import check_store
        saved = check_store.expected_history
        want = {i: {a: (v, u) for a, v, u in arrays} for i, arrays in self.hist.items()}
        check_store.expected_history = lambda i: want.get(i)
        try:
            # the filtered ones (check_store wants deflate)
            for name, path in (("v2", self.v2), ("v3", self.v3), ("v4", self.v4)):
                with self.subTest(file=name), h5py.File(path, "r") as f:
                    del check_store.failures[:]
                    for i in range(N):
                        check_store.check_history(f, i)
                    self.assertEqual(check_store.failures, [])
            bad = os.path.join(self.tmp.name, "bad_padding.h5")
            write_v3(bad, self.hist, [8, 2, 5, 3, 0, 4, 7, 6], spare_chunks=1, compression=True)
            s, n, _ = self.placed[0]
            with h5py.File(bad, "r+") as f:
                f["histories/tau"][s + n] = 1.0
            with h5py.File(bad, "r") as f, contextlib.redirect_stdout(io.StringIO()):
                del check_store.failures[:]
                check_store.check_history(f, 0)
                self.assertEqual(len(check_store.failures), 1, check_store.failures)
                self.assertIn("padding", check_store.failures[0])
        finally:
            check_store.expected_history = saved
            del check_store.failures[:]

    def test_report_history_ids(self):
        from kinesweep import read as ksread
        from kinesweep import report_traces
        for name, path in self.files.items():
            with self.subTest(file=name), ksread.open_results(path) as r:
                self.assertEqual(report_traces.history_ids(r), set(self.hist))

    def plot(self, command, path, *extra):
        from e2e_common import ANALYSIS_ENV, analysis_command
        png = os.path.join(self.tmp.name, f"{command}_{os.path.basename(path)}.png")
        r = subprocess.run(analysis_command(command, path, "-o", png, "--size", "400x300", "--print-data", *extra),
                           capture_output=True, text=True, env=ANALYSIS_ENV)
        self.assertEqual(r.returncode, 0, r.stderr)
        d = json.loads(r.stdout)
        del d["file"], d["output"]
        return d

    @staticmethod
    def values(x):
        return np.array([np.nan if v is None else v for v in np.ravel(x)] if np.size(x) else [], dtype=float)

    def test_plot_histories(self):
        """Default runs: the first three done runs with a time array (0, 3 with 0 rows, 5; not 1: no
        history); then two runs named, arrays in degrees where their unit is rad."""
        for extra, ids in (((), [0, 3, 5]), (("--runs", "7,0", "--radians"), [7, 0])):
            got = {n: self.plot("plot_histories", p, "--what", "tau,q,qd", *extra) for n, p in self.files.items()}
            for name, d in got.items():
                with self.subTest(file=name, extra=extra):
                    self.assertEqual(d, got["v2"])
                    self.assertEqual([int(r) for r in d["runs"]], ids)
                    for r in ids:
                        h = {a: v for a, v, _ in self.hist[r]}
                        run = d["runs"][str(r)]
                        np.testing.assert_array_equal(self.values(run["t"]), h["t"][:, 0])
                        np.testing.assert_array_equal(self.values(run["tau"]), h["tau"].ravel())
                        np.testing.assert_array_equal(self.values(run["qd"]), h["qd"].ravel())
                        q = h["q"] if extra else h["q"] * RAD2DEG
                        np.testing.assert_array_equal(self.values(run["q"]), q.ravel())

    def test_plot_convergence(self):
        """One line per (method, lambda) among the done IK runs with a history: lm 0.1 -> run 2,
        newton -> 4, lm 0.01 -> 8 (lm_adaptive's run 9 has none; run 6 is not done)."""
        got = {n: self.plot("plot_convergence", p) for n, p in self.files.items()}
        for name, d in got.items():
            with self.subTest(file=name):
                self.assertEqual(d, got["v2"])
                self.assertEqual(sorted(int(r) for r in d["runs"]), [2, 4, 8])
                for r, run in d["runs"].items():
                    h = {a: v for a, v, _ in self.hist[int(r)]}
                    np.testing.assert_array_equal(self.values(run["k"]), h["k"][:, 0])
                    np.testing.assert_array_equal(self.values(run["norm_F"]), h["norm_F"][:, 0])

    def test_other_versions(self):
        """v1 keeps the group layout (kshistory reads it; ksread refuses v1 for its /runs); a version
        newer than 4 is refused by both, naming the version; a file without /histories has none."""
        from kinesweep import history as kshistory
        from kinesweep import read as ksread
        v1 = os.path.join(self.tmp.name, "v1.h5")
        write_v2(v1, self.hist, version=1)
        with h5py.File(v1, "r") as f:
            self.assertEqual([i for i, _ in kshistory.Histories(f).items()], sorted(self.hist))
        v6 = os.path.join(self.tmp.name, "v6.h5")
        write_v3(v6, self.hist, sorted(self.hist), spare_chunks=0, compression=False, version=4)
        with h5py.File(v6, "r+") as f:
            f.attrs["format_version"] = np.int64(6)
        with self.assertRaises(ksread.FormatVersionError) as e:
            ksread.open_results(v6)
        self.assertIn("format v6", str(e.exception))
        with h5py.File(v6, "r") as f, self.assertRaises(ksread.FormatVersionError) as e:
            kshistory.Histories(f)
        self.assertIn("format v6", str(e.exception))
        for version in (2, 3, 4, 5):
            path = os.path.join(self.tmp.name, f"none_v{version}.h5")
            with h5py.File(path, "w") as f:
                write_common(f, version)
            with ksread.open_results(path) as r:
                self.assertEqual((r.history_count(), r.history_ids().tolist(), r.has_history(0), r.history_arrays(0)),
                                 (0, [], False, []))


if __name__ == "__main__":
    if len(sys.argv) > 1:
        ROOT = sys.argv.pop(1)
    unittest.main(verbosity=2)
