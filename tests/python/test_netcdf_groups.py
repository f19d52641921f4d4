"""Every shipped study's results file (the files the regression test wrote, its work dir) opens in
xarray (h5netcdf) group by group without phony dimensions: /runs with one dimension, run_id, whose
coordinate is the run ids, every column equal to what h5py reads (labelled columns decoded through
their flag_values / flag_meanings), and netCDF-C (netCDF4-python, ncdump) lists every column;
each /landscapes/<block> with its axes as dimensions. Selection
by dimension works (a dimension named like an xarray keyword, such as `method`, by the dict form:
ds.sel({"method": 0})); a format 4 Saltelli dimension, whose coordinate repeats values, by
position (isel).

usage: /usr/bin/python3 test_netcdf_groups.py RESULTS_DIR
"""
import os
import sys
import unittest

import h5py
import numpy as np
import xarray as xr

from e2e_common import axis_dataset_name, runs_column, same, shipped_results

RESULTS = None


class NetcdfGroups(unittest.TestCase):
    def files(self):
        return shipped_results(self, RESULTS)

    def test_runs_open_with_run_id_as_their_dimension(self):
        for path in self.files():
            with self.subTest(file=os.path.basename(path)), h5py.File(path, "r") as f, \
                    xr.open_dataset(path, group="runs", engine="h5netcdf", mask_and_scale=False) as ds:
                n = f["runs"]["done"].shape[0]
                self.assertEqual(dict(ds.sizes), {"run_id": n})
                self.assertTrue(same(ds["run_id"].values, f["runs"]["run_id"][()]))
                for name in f["runs"]:
                    if name == "run_id":
                        continue
                    d = f["runs"][name]
                    if "flag_meanings" in d.attrs:  # a labelled column: codes, and their meanings
                        meanings = ds[name].attrs["flag_meanings"].split(" ")
                        codes = ds[name].values.astype(int)
                        values = np.array([meanings[c].replace("_", " ") if c < len(meanings) else "" for c in codes],
                                          dtype=object)
                        want = np.array([v.replace("_", " ") for v in runs_column(d)], dtype=object)
                        self.assertTrue(np.array_equal(values, want), name)
                        self.assertEqual(np.atleast_1d(ds[name].attrs["flag_values"]).tolist(), list(range(len(meanings))))
                    elif d.dtype.kind in "fiu":
                        self.assertTrue(same(ds[name].values, d[()]), name)
                if n:
                    k = int(f["runs"]["run_id"][n // 2])
                    self.assertEqual(int(ds.sel(run_id=k)["run_id"]), k)

    def test_netcdf_c_lists_every_runs_column_with_its_flags(self):
        """netCDF-C (netCDF4-python; `ncdump -h` when installed) sees every /runs column, the
        labelled ones (named enum types) with flag_values and flag_meanings."""
        import shutil
        import subprocess
        import netCDF4
        ncdump = shutil.which("ncdump")
        for path in self.files():
            with self.subTest(file=os.path.basename(path)), h5py.File(path, "r") as f, netCDF4.Dataset(path) as nc:
                columns = [c.decode() if isinstance(c, bytes) else str(c) for c in f["runs"].attrs["columns"]]
                self.assertEqual(set(nc["runs"].variables) - {"done"}, set(columns))
                header = subprocess.run([ncdump, "-h", path], capture_output=True, text=True, check=True).stdout \
                    if ncdump else ""
                for c in columns:
                    if "flag_meanings" in f["runs"][c].attrs:
                        self.assertTrue({"flag_values", "flag_meanings"} <= set(nc["runs"][c].ncattrs()), c)
                        self.assertTrue(not ncdump or f"{c}:flag_meanings" in header, c)
                    self.assertTrue(not ncdump or f" {c}(run_id) ;" in header, c)

    def test_landscapes_open_with_their_axes_as_dimensions(self):
        seen = 0
        for path in self.files():
            with h5py.File(path, "r") as f:
                blocks = list(f["landscapes"]) if "landscapes" in f else []
                for block in blocks:
                    g = f["landscapes"][block]
                    # the dimensions: the axes' datasets (`method_` for the axis `method`)
                    axes = [axis_dataset_name(a.decode() if isinstance(a, bytes) else str(a)) for a in g.attrs["axes"]]
                    with self.subTest(file=os.path.basename(path), block=block), \
                            xr.open_dataset(path, group=f"landscapes/{block}", engine="h5netcdf",
                                            mask_and_scale=False) as ds:
                        for m in g.attrs["metrics"]:
                            m = m.decode() if isinstance(m, bytes) else str(m)
                            if g[m].shape == ():
                                continue
                            self.assertEqual(list(ds[m].dims), axes, m)
                            self.assertTrue(same(ds[m].values, g[m][()]), m)
                        for a in axes:
                            values = ds[a].values
                            if len(np.unique(values)) < len(values):
                                # a Saltelli design's dimension repeats its first factor's values (A and
                                # AB_m share them): position, not value, selects there; format 5
                                # stores such points along `sample` instead
                                self.assertLess(int(f.attrs["format_version"]), 5, a)
                                self.assertIn(block, f["designs"], a)
                                continue
                            self.assertEqual(ds.sel({a: values[0]})[a].values.item(), values[0])
                            # and by keyword: no dimension is one of sel's own arguments
                            self.assertEqual(ds.sel(**{a: values[0]})[a].values.item(), values[0])
                        seen += 1
        self.assertGreater(seen, 5)


if __name__ == "__main__":
    RESULTS = os.path.abspath(sys.argv[1])
    unittest.main(argv=[sys.argv[0], "-v"])
