"""Results files as netCDF-4 / CF-1.10 files, read by netCDF-C's own tools: runs a small study of
every landscape shape (a grid with a string axis, an axis given out of order, a Latin hypercube,
zipped random draws, a Saltelli design; trajectory and IK blocks, histories) and two shipped studies
(examples_lhs, ik_scara), then checks

- `ncdump -h` and netCDF4-python (netCDF-C) list every /runs column h5py lists (the labelled ones
  included: committed enum types), with flag_values / flag_meanings on the labelled ones, and the
  labels netCDF-C decodes are the ones kinesweep.read decodes; a full `ncdump` prints every value;
- CF: `Conventions = "CF-1.10"` at the root; every coordinate variable (a 1-D variable named like
  its dimension) strictly monotonic and without _FillValue; no '+' in any dimension name; no
  `sample_dimension` (no ragged-array declaration); landscape status grids integer codes with
  flag_values / flag_meanings; /runs/run_id an int64 index in xarray;
- a sampled design's landscape has the dimension `sample` with every parameter a coordinate along it:
  xarray's .sel over `sample`, and a selection by each parameter's value through a boolean mask,
  return the cells whose /runs rows (run id = the block's first run + sample index) hold that value.

usage: /usr/bin/python3 test_netcdf_conformance.py KINESWEEP STUDIES_DIR
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import h5py
import netCDF4
import numpy as np
import xarray as xr

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
from kinesweep.kinds import text_values  # noqa: E402

EXE = STUDIES = None
NCDUMP = shutil.which("ncdump")

SHAPES = """
[study]
name = "cf_shapes"
histories = "full"

[[block]]
name = "grid"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = [-10, 0, 10]
k = [0.0, 0.5]

[[block]]
name = "unordered"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = [10, -10, 0]

[[block]]
name = "lhs"
kind = "trajectory"
method = "local_unweighted"
lhs = { count = 6, seed = 3 }
[block.axes]
alpha1A = { lhs = { from = -30, to = 35 } }
k = { lhs = { from = 0, to = 1 } }

[[block]]
name = "random"
kind = "ik"
problem = "scara"
method = "lm"
zip = [["q0_1", "q0_2"]]
[block.axes]
lambda = [0.01, 1.0]
q0_1 = { random = { from = -180, to = 180, count = 5, seed = 5 } }
q0_2 = { random = { from = -180, to = 180, count = 5, seed = 6 } }

[[block]]
name = "saltelli"
kind = "ik"
problem = "scara"
method = "newton"
saltelli = { count = 8, seed = 1 }
[block.axes]
q0_1 = { saltelli = { from = 30, to = 90 } }
q0_2 = { saltelli = { from = 15, to = 75 } }
"""

WORK = None
FILES = {}


def setUpModule():
    global WORK
    WORK = tempfile.mkdtemp(prefix="ks_netcdf_")
    studies = {"cf_shapes": os.path.join(WORK, "cf_shapes.toml")}
    with open(studies["cf_shapes"], "w") as f:
        f.write(SHAPES)
    for name in ("examples_lhs", "ik_scara"):
        studies[name] = os.path.join(STUDIES, name + ".toml")
    for name, toml in studies.items():
        out = os.path.join(WORK, name + ".h5")
        r = subprocess.run([EXE, "run", toml, "-o", out, "-q", "--threads", "2"], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"kinesweep run {toml}: exit {r.returncode}\n{r.stderr}")
        FILES[name] = out


def tearDownModule():
    shutil.rmtree(WORK, ignore_errors=True)


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def columns(path):
    with h5py.File(path, "r") as f:
        return [text(c) for c in f["runs"].attrs["columns"]], {
            text(c) for c in f["runs"].attrs["columns"] if "flag_meanings" in f["runs"][text(c)].attrs}


def groups(ds, path="/"):
    """(path, netCDF4 group) of `ds` and every group under it."""
    yield path, ds
    for name, g in ds.groups.items():
        yield from groups(g, path.rstrip("/") + "/" + name)


class NetcdfTools(unittest.TestCase):
    @unittest.skipUnless(NCDUMP, "ncdump (Debian netcdf-bin) not installed")
    def test_ncdump_lists_every_runs_column_with_its_flags(self):
        labelled_seen = set()
        for name, path in FILES.items():
            cols, labelled = columns(path)
            labelled_seen |= labelled
            r = subprocess.run([NCDUMP, "-h", path], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            runs = r.stdout[r.stdout.index("group: runs {"):]
            runs = runs[:runs.index("} // group runs")]
            for c in cols:
                with self.subTest(file=name, column=c):
                    self.assertRegex(runs, rf"\s{re.escape(c)}\(run_id\) ;")
                    if c in labelled:
                        self.assertRegex(runs, rf"\s{re.escape(c)}:flag_values = ")
                        self.assertRegex(runs, rf"\sstring {re.escape(c)}:flag_meanings = ")
        # the labelled columns of both kinds
        self.assertTrue({"status", "method", "block", "preset", "integrator", "inertia", "on_violation", "problem",
                         "joint_limits", "z_mode"} <= labelled_seen, sorted(labelled_seen))

    @unittest.skipUnless(NCDUMP, "ncdump (Debian netcdf-bin) not installed")
    def test_full_ncdump_prints_every_value(self):
        r = subprocess.run([NCDUMP, FILES["cf_shapes"]], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])
        self.assertIn("status = ", r.stdout)

    def test_netcdf4_reads_every_runs_column_and_decodes_the_labels(self):
        for name, path in FILES.items():
            cols, labelled = columns(path)
            with netCDF4.Dataset(path) as nc, h5py.File(path, "r") as f:
                runs = nc["runs"]
                runs.set_auto_mask(False)
                self.assertEqual(sorted(set(runs.variables) - {"done"}), sorted(cols), name)
                for c in labelled:
                    with self.subTest(file=name, column=c):
                        v = runs[c]
                        self.assertTrue({"flag_values", "flag_meanings"} <= set(v.ncattrs()))
                        by_code = {code: label for label, code in v.datatype.enum_dict.items()}
                        fill = int(v.getncattr("_FillValue"))
                        got = [by_code[int(x)] if int(x) != fill else "" for x in v[:]]
                        meanings = v.getncattr("flag_meanings").split(" ")
                        self.assertEqual(len(meanings), len(v.getncattr("flag_values")))
                        want = [s.replace(" ", "_") for s in text_values(f["runs"][c])]
                        self.assertEqual([s.replace(" ", "_") for s in got], want)


class CfConventions(unittest.TestCase):
    def test_conventions_coordinates_and_dimension_names(self):
        coordinates = 0
        for name, path in FILES.items():
            with netCDF4.Dataset(path) as nc:
                self.assertEqual(nc.getncattr("Conventions"), "CF-1.10")
                for where, g in groups(nc):
                    for dim in g.dimensions:
                        self.assertNotIn("+", dim, f"{name}:{where}")
                    for vname, v in g.variables.items():
                        with self.subTest(file=name, variable=f"{where}/{vname}"):
                            self.assertNotIn("sample_dimension", v.ncattrs())
                            if v.dimensions != (vname,):
                                continue
                            coordinates += 1
                            self.assertNotIn("_FillValue", v.ncattrs())
                            v.set_auto_mask(False)
                            x = np.asarray(v[:], dtype=float)
                            d = np.diff(x)
                            self.assertTrue(len(x) < 2 or np.all(d > 0) or np.all(d < 0), x[:10])
        self.assertGreater(coordinates, 10)

    def test_status_grids_are_integer_codes_with_flags(self):
        seen = 0
        for name, path in FILES.items():
            with h5py.File(path, "r") as f:
                kinds = [[text(s) for s in k.attrs["statuses"]] for k in f["kinds"].values()]
                for block, g in f["landscapes"].items():
                    d = g["status_code"]
                    with self.subTest(file=name, block=block):
                        self.assertEqual(d.dtype.kind, "i")
                        statuses = text(d.attrs["flag_meanings"]).split(" ")
                        self.assertIn(statuses, kinds)
                        self.assertEqual(np.asarray(d.attrs["flag_values"]).tolist(), list(range(len(statuses))))
                        self.assertEqual(int(d.attrs["_FillValue"]), -1)
                        codes = d[()]
                        self.assertTrue(np.all((codes >= -1) & (codes < len(statuses))))
                        seen += 1
        self.assertGreater(seen, 5)

    def test_run_id_is_an_integer_index_in_xarray(self):
        for engine in ("h5netcdf", "netcdf4"):
            with xr.open_dataset(FILES["cf_shapes"], group="runs", engine=engine) as ds:
                self.assertEqual(ds.indexes["run_id"].dtype, np.int64, engine)
                self.assertEqual(int(ds.sel(run_id=7)["run_id"]), 7)


class SampledDesigns(unittest.TestCase):
    def check_block(self, block, params):
        path = FILES["cf_shapes"]
        with h5py.File(path, "r") as f:
            runs = f["runs"]
            names = text_values(runs["block"])
            ids = np.flatnonzero(names == block)
            status = text_values(runs["status"])
            stored = {p: runs[p][()] for p in params}
        for engine in ("h5netcdf", "netcdf4"):
            with xr.open_dataset(path, group=f"landscapes/{block}", engine=engine) as ds, \
                    self.subTest(block=block, engine=engine):
                self.assertIn("sample", ds.dims)
                for p in params:
                    self.assertEqual(ds[p].dims, ("sample",), p)
                    self.assertIn(p, ds.coords)
                n = ds.sizes["sample"]
                self.assertEqual(np.asarray(ds["sample"]).tolist(), list(range(n)))
                sample_dim = list(ds["status_code"].dims).index("sample")
                other = int(np.prod([ds.sizes[d] for d in ds["status_code"].dims if d != "sample"]))
                self.assertEqual(n * other, len(ids))
                for i in range(n):
                    cell = ds.sel(sample=i)
                    for p in params:
                        # the row of the sample's run(s) holds the coordinate's value
                        value = float(cell[p])
                        mask = ds[p] == value
                        chosen = ds.isel(sample=mask)
                        self.assertIn(i, np.asarray(chosen["sample"]).astype(int).tolist())
                        self.assertTrue(np.all(np.asarray(chosen[p]) == value))
                        for j in np.asarray(chosen["sample"]).astype(int).tolist():
                            for o in range(other):  # the run ids of sample j (the sample dimension first)
                                local = j * other + o if sample_dim == 0 else o * n + j
                                self.assertEqual(stored[p][ids[local]], value, (p, j, o))
                    if sample_dim == 0 and other == 1:
                        code = cell["status_code"].values.item()
                        want = status[ids[i]]
                        flags = ds["status_code"].attrs["flag_meanings"].split(" ")
                        self.assertEqual(flags[int(code)], want)

    def test_saltelli_design_selects_by_each_parameter(self):
        self.check_block("saltelli", ["q0_1", "q0_2"])

    def test_lhs_design_selects_by_each_parameter(self):
        self.check_block("lhs", ["alpha1A", "k"])

    def test_zipped_random_draws_select_by_each_parameter(self):
        self.check_block("random", ["q0_1", "q0_2"])

    def test_axis_given_out_of_order_is_a_sample_dimension(self):
        self.check_block("unordered", ["alpha1A"])

    def test_a_grid_keeps_its_axes_as_dimensions(self):
        with xr.open_dataset(FILES["cf_shapes"], group="landscapes/grid", engine="h5netcdf") as ds:
            self.assertEqual(list(ds["E"].dims), ["method_", "alpha1A", "k"])
            self.assertNotIn("sample", ds.dims)


if __name__ == "__main__":
    EXE, STUDIES = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"])
