"""What the end-to-end tests share: the small studies they run and how they compare results files.
Run with Debian's /usr/bin/python3 (h5py, numpy)."""
import os
import subprocess
import shutil
import sys
import tempfile
import unittest

import h5py
import numpy as np

ANALYSIS = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
sys.path.insert(0, ANALYSIS)
from kinesweep.history import Histories, group_name  # noqa: E402  the /histories layouts (format_version 1 to 4)
from kinesweep.kinds import enum_labels, text_values  # noqa: E402  /runs text columns (FORMAT.md, "/runs")

# A trajectory landscape (561 runs) and an IK basin (441 runs): about a second on 2 cores.
SWEEP = """
[study]
name = "e2e"
histories = "every=5"

[[block]]
name = "weighted"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { from = -20, to = 30, step = 1 }
k = { from = 0, to = 1, count = 11 }

[[block]]
name = "newton_basin"
kind = "ik"
problem = "scara"
method = "newton"
[block.axes]
q0_1 = { from = -180, to = 180, count = 21 }
q0_2 = { from = -180, to = 180, count = 21 }
"""

# A coarse landscape and an [[optimize]] block polishing from it (sweep, global and local stages).
OPTIMIZE = """
[study]
name = "e2e_optimize"
histories = "none"
[robot]
inertia = "thesis_m11"
[[block]]
name = "grid"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { from = -30, to = 10, step = 5 }
k = { from = 0, to = 1, step = 0.25 }
[[optimize]]
name = "h1"
preset = "1h"
variables = { alpha1A = [-30, 10], k = [0, 1] }
polish_from = { block = "grid", best = 2 }
[optimize.global]
algorithm = "GN_ESCH"
population = 10
max_evals = 40
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 30
"""


def axis_dataset_name(axis):
    """The dataset (and netCDF dimension) of landscape axis `axis`, as FORMAT.md states it: the axis
    name, with "_" appended to the keywords of xarray's Dataset.sel."""
    return axis + "_" if axis in ("method", "tolerance", "drop", "indexers") else axis


def same(a, b):
    """Equal shapes and values, NaN equal to NaN, numbers compared as float when either side is one
    (xarray's decoded values against h5py's)."""
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind in "fc" or b.dtype.kind in "fc":
        return a.shape == b.shape and np.array_equal(a.astype(float), b.astype(float), equal_nan=True)
    return a.shape == b.shape and np.array_equal(a, b)


def bitwise_equal(x, y):
    """Arrays equal bit for bit (NaN payloads included)."""
    if x.shape != y.shape:
        return False
    if x.dtype.kind == "f":
        return np.array_equal(x.view(np.uint64), y.view(np.uint64))
    return np.array_equal(x, y)


def history(f, run_id):
    """One run's history in an open results file, whatever its /histories layout: {array name: 2-D
    float64 array} in the order the run produced them. KeyError when the run has none."""
    return {name: a for name, a, _unit in Histories(f).read(run_id)}


def same_histories(test, fa, fb, unit=lambda u: u):
    """Assert that two open results files hold the same histories, bit for bit (NaN payloads included):
    the same runs, each with the same arrays in the same order, of the same units (as `unit` reads
    them)."""
    ha, hb = Histories(fa), Histories(fb)
    test.assertEqual(ha.ids().tolist(), hb.ids().tolist())
    for i in ha.ids():
        a, b = ha.read(i), hb.read(i)
        test.assertEqual([(n, unit(u)) for n, _, u in a], [(n, unit(u)) for n, _, u in b], f"run {i}")
        for (name, x, _), (_, y, _) in zip(a, b):
            test.assertTrue(bitwise_equal(x, y), f"run {i} {name}")


def is_text(d):
    """A /runs dataset holds text: labelled (an HDF5 enum, format_version 4) or free (strings)."""
    return enum_labels(d) is not None or d.dtype.kind in "OSU"


def runs_column(d):
    """A /runs dataset's values: text columns (labelled or free) as an object array of str, the
    missing value as ""; numbers as stored."""
    return text_values(d) if is_text(d) else d[()]


def runs_columns(f, skip=()):
    """Every /runs column of an open results file but those in `skip`, as runs_column reads them."""
    g = f["runs"]
    return {k: runs_column(g[k]) for k in g if k not in skip}


def runs_table(path):
    """Every /runs column but wall_time (the one column that varies between identical sweeps), text
    as str."""
    with h5py.File(path, "r") as f:
        return runs_columns(f, skip=("wall_time",))


def same_tables(a, b):
    return a.keys() == b.keys() and all(bitwise_equal(a[k], b[k]) for k in a)


def make_v1(src, dst):
    """A format_version 1 copy of a results file: text columns as variable-length strings (labelled
    columns of format_version 4 rewritten), no role / kinds attributes on /runs, histories in the
    group layout (one group per run), version 1."""
    shutil.copyfile(src, dst)
    with h5py.File(dst, "r+") as f:
        for k in list(f["runs"]):
            d = f["runs"][k]
            if enum_labels(d) is not None:
                values, attrs = text_values(d), dict(d.attrs)
                del f["runs"][k]
                d = f["runs"].create_dataset(k, data=values, dtype=h5py.string_dtype())
                for a, v in attrs.items():
                    if a not in ("flag_values", "flag_meanings", "_FillValue"):
                        d.attrs[a] = v
            for a in ("role", "kinds"):
                del d.attrs[a]
        hist = list(Histories(f).items())
        n = len(f["runs"]["done"])
        del f["histories"]
        g = f.create_group("histories")
        for run_id, arrays in hist:
            r = g.create_group(group_name(run_id, n))
            r.attrs["arrays"] = [name for name, _, _ in arrays]
            for name, a, unit in arrays:
                r.create_dataset(name, data=a).attrs["unit"] = unit
        f.attrs.modify("format_version", np.int64(1))


def run_study_text(ks, directory, name, text, *args):
    """Write `text` as DIRECTORY/NAME.toml, run it into DIRECTORY/NAME.h5 (extra `args` to `kinesweep
    run`) and return the results file's path; AssertionError with kinesweep's stderr when it fails."""
    study = os.path.join(directory, name + ".toml")
    with open(study, "w") as f:
        f.write(text)
    out = os.path.join(directory, name + ".h5")
    r = subprocess.run([ks, "run", study, "-o", out, "--overwrite", "-q", *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return out


def shipped_results(test, directory):
    """The results files the regression test wrote into its work dir `directory` (one per shipped
    study); the test fails when there are too few (the fixture did not run)."""
    import glob
    found = sorted(glob.glob(os.path.join(directory, "*.h5")))
    test.assertGreater(len(found), 5, f"no results files in {directory}")
    return found


def analysis_command(name, *args):
    """The command line of `python3 -m kinesweep.NAME ARGS...` under this interpreter (Debian's); run it
    with env=ANALYSIS_ENV."""
    return [sys.executable, "-m", "kinesweep." + name, *args]


# The environment of analysis_command: analysis/ first on PYTHONPATH (the source tree's package).
ANALYSIS_ENV = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [ANALYSIS, os.environ.get("PYTHONPATH")])))


def report_page(test, results, directory, *options):
    """kinesweep.report on `results` with `options` (the test fails unless it exits 0): the page's html
    and its figures' data islands, id -> the JSON text (gzip and base64 undone)."""
    import base64
    import gzip
    import re
    page = os.path.join(directory, "report.html")
    r = subprocess.run(analysis_command("report", results, "-o", page, *options), env=ANALYSIS_ENV, capture_output=True,
                       text=True, timeout=300)
    test.assertEqual(r.returncode, 0, r.stderr)
    with open(page, encoding="utf-8") as fh:
        html = fh.read()
    islands = {fid: gzip.decompress(base64.b64decode(data)).decode()
               for fid, data in re.findall(r'<script type="application/gzip" id="([^"]+-data)">([^<]*)</script>', html)}
    return html, islands


class TempDirTest(unittest.TestCase):
    """A test case with a temporary directory and a helper to write study files into it."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def write(self, name, text):
        p = os.path.join(self.dir, name)
        with open(p, "w") as f:
            f.write(text)
        return p


class StudyFileTest(unittest.TestCase):
    """A test case over one results file, run once for the class: subclasses set KS (the kinesweep
    binary), NAME and STUDY (the study text); cls.h5 is the file and cls.runs its /runs columns as
    read by h5py (text columns as object arrays of str: runs_column)."""
    KS = NAME = STUDY = None

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.h5 = run_study_text(cls.KS, cls.tmp.name, cls.NAME, cls.STUDY)
        with h5py.File(cls.h5, "r") as f:
            cls.runs = runs_columns(f)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()
