"""Landscapes open in xarray with named, unit-carrying coordinates: straight from the file
(xarray.open_dataset(FILE, group="landscapes/BLOCK", engine="h5netcdf"), through HDF5 dimension
scales) and through ksread (to_xarray); ksread's to_pandas is the /runs table. Every value is
checked against h5py reading the same datasets.

usage: /usr/bin/python3 test_xarray.py KINESWEEP_BINARY ANALYSIS_DIR
"""
import sys
import unittest

import h5py
import numpy as np

from e2e_common import StudyFileTest, axis_dataset_name, bitwise_equal

STUDY = """
[study]
name = "xr"
histories = "none"

[[block]]
name = "local"
kind = "trajectory"
dt = 0.01
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { from = -20, to = 20, count = 5 }   # deg
k = [0.0, 0.1, 0.2]

[[block]]
name = "basins"
kind = "ik"
problem = "scara"
lambda = 0.1
target_x = 50.0
target_y = -80.0
target_z = 10.0
q0_3 = 50.0
[block.axes]
method = ["newton", "lm"]
q0_1 = { from = -180, to = 180, count = 7 }   # deg
q0_2 = { from = -180, to = 180, count = 6 }   # deg
"""


def stored(path, block):
    """The landscape as h5py reads it: axes [(name, unit, values)], metrics {name: (unit, array)}."""
    with h5py.File(path, "r") as f:
        g = f["landscapes"][block]
        axes = [(axis_dataset_name(a), g[axis_dataset_name(a)].attrs["unit"], g[axis_dataset_name(a)][()])
                for a in (x.decode() if isinstance(x, bytes) else str(x) for x in g.attrs["axes"])]
        metrics = {m: (g[m].attrs["unit"], g[m][()]) for m in g.attrs["metrics"]}
    return axes, metrics


class Xarray(StudyFileTest):
    NAME, STUDY = "xr", STUDY

    def test_open_dataset_names_every_dimension_after_its_axis(self):
        import xarray as xr
        for block in ("local", "basins"):
            axes, metrics = stored(self.h5, block)
            # the stored values (a status grid's int8 codes as they are: no _FillValue masking)
            with self.subTest(block=block), xr.open_dataset(self.h5, group="landscapes/" + block,
                                                            engine="h5netcdf", mask_and_scale=False) as ds:
                names = [a[0] for a in axes]
                self.assertEqual(list(ds.dims), names)  # no phony_dim_N
                for name, unit, values in axes:
                    self.assertIn(name, ds.coords)
                    self.assertTrue(bitwise_equal(ds[name].values, values), name)
                    self.assertEqual(ds[name].attrs["unit"], unit)  # (the engine's label; CF `units` beside it)
                self.assertEqual(set(ds.data_vars), set(metrics))
                for m, (unit, values) in metrics.items():
                    self.assertEqual(list(ds[m].dims), names)
                    self.assertTrue(bitwise_equal(ds[m].values, values), m)
                    self.assertEqual(ds[m].attrs["unit"], unit)
                # selecting by coordinate value: the grid cell of the first run of the block
                first = ds.isel({n: 0 for n in names})
                self.assertTrue(bitwise_equal(np.asarray(first[list(metrics)[0]].values),
                                              np.asarray(metrics[list(metrics)[0]][1].flat[0])))

    def test_ksread_to_xarray_has_labels_for_string_axes_and_units(self):
        from kinesweep import read as ksread
        with ksread.open_results(self.h5) as r:
            ds = r.to_xarray("local")
            deg = r.to_xarray("local", degrees=True)
        axes, metrics = stored(self.h5, "local")
        self.assertEqual(list(ds.dims), [a[0] for a in axes])
        self.assertEqual(list(ds["method_"].values), ["local_weighted", "local_unweighted"])
        self.assertEqual(ds["alpha1A"].attrs["units"], "rad")
        self.assertEqual(deg["alpha1A"].attrs["units"], "deg")
        self.assertTrue(np.allclose(deg["alpha1A"].values, [-20, -10, 0, 10, 20], rtol=0, atol=1e-12))
        self.assertEqual(ds["E"].attrs["units"], metrics["E"][0])
        self.assertTrue(bitwise_equal(ds["E"].values, metrics["E"][1]))
        self.assertEqual(ds.attrs["kind"], "trajectory")
        # one cell by its coordinates: method by name, alpha1A and k by value
        # (the axis `method` is the dimension `method_`: sel's own keyword is `method`)
        cell = ds["E"].sel(method_="local_unweighted", k=0.1).isel(alpha1A=2)
        i = ["local_weighted", "local_unweighted"].index("local_unweighted")
        self.assertTrue(bitwise_equal(np.asarray(cell.values), np.asarray(metrics["E"][1][i, 2, 1])))

    def test_ksread_to_pandas_is_the_runs_table(self):
        from kinesweep import read as ksread
        with ksread.open_results(self.h5) as r:
            df = r.to_pandas()
        done = self.runs["done"].astype(bool)
        self.assertEqual(len(df), int(done.sum()))
        for c in ("run_id", "E", "alpha1A", "iterations"):
            self.assertTrue(bitwise_equal(df[c].to_numpy(), self.runs[c][done]), c)
        self.assertEqual(list(df["block"]), list(self.runs["block"][done]))
        self.assertEqual(df.attrs["units"]["alpha1A"], "rad")


if __name__ == "__main__":
    StudyFileTest.KS = sys.argv[1]
    sys.path.insert(0, sys.argv[2])
    unittest.main(argv=sys.argv[:1], verbosity=2)
