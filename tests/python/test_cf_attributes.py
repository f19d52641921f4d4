"""Every shipped study's results file (the files the regression test wrote, its work dir) carries CF
attributes that other tools read: every `units` value (and every entry of a `column_units` list) is
accepted by UDUNITS-2's `udunits2` tool and by pint; categorical values (enum /runs columns,
landscape axes of labels) carry flag_values and flag_meanings and no units; integer /runs columns
carry their missing value, -1, as _FillValue. Every group opens in xarray (h5netcdf) without phony
dimensions, its numeric variables equal to what h5py reads, and selection works along every
dimension.

usage: /usr/bin/python3 test_cf_attributes.py RESULTS_DIR
"""
import os
import shutil
import subprocess
import sys
import unittest

import h5py
import numpy as np
import pint
import xarray as xr

from e2e_common import same, shipped_results

RESULTS = None
UDUNITS2 = shutil.which("udunits2")
# Attributes that hold units. /optimizations/<name>@units (a group's list, one entry per optimised
# variable) writes "" for a dimensionless variable; its other entries are checked like the rest.
UNIT_ATTRS = ("units", "column_units")


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def udunits2_accepts(unit):
    """Whether `udunits2` parses `unit` (-W '': print its definition, no prompt)."""
    p = subprocess.run([UDUNITS2, "-H", unit, "-W", ""], capture_output=True, text=True, timeout=30)
    return p.returncode == 0 and not p.stderr.strip()


def unit_values(path):
    """{unit string: [where it occurs]} over every object's units attributes in file `path`."""
    found = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            for attr in UNIT_ATTRS:
                if attr not in obj.attrs:
                    continue
                v = obj.attrs[attr]
                values = [text(x) for x in np.atleast_1d(v)] if not isinstance(v, (str, bytes)) else [text(v)]
                for u in values:
                    if u == "" and isinstance(obj, h5py.Group) and attr == "units":
                        continue  # an optimisation's dimensionless variable (see UNIT_ATTRS)
                    found.setdefault(u, []).append(f"{name}@{attr}")
        visit("/", f)
        f.visititems(visit)
    return found


def groups_of(path):
    with h5py.File(path, "r") as f:
        out = ["/"]
        f.visititems(lambda n, o: out.append("/" + n) if isinstance(o, h5py.Group) else None)
    return out


class CfAttributes(unittest.TestCase):
    def files(self):
        return shipped_results(self, RESULTS)

    @unittest.skipUnless(UDUNITS2, "udunits2 (Debian udunits-bin) not installed")
    def test_udunits2_rejects_what_it_cannot_parse(self):
        for good in ("N m", "rad", "1", "s-2", "m2", "W2 s"):
            self.assertTrue(udunits2_accepts(good), good)
        for bad in ("Nm", "problem units", "rad or mm", "rad, rad, mm", "labels:lm,lm_adaptive", "1/s"):
            self.assertFalse(udunits2_accepts(bad), bad)

    @unittest.skipUnless(UDUNITS2, "udunits2 (Debian udunits-bin) not installed")
    def test_every_units_value_parses_in_udunits2_and_pint(self):
        found = {}
        for path in self.files():
            for u, where in unit_values(path).items():
                found.setdefault(u, []).extend(f"{os.path.basename(path)}:{w}" for w in where)
        self.assertTrue("N m" in found, sorted(found))
        registry = pint.UnitRegistry()
        for u, where in sorted(found.items()):
            with self.subTest(unit=u, first=where[0]):
                self.assertTrue(udunits2_accepts(u), f"{u!r} at {where[:3]}")
                registry.parse_expression(u)  # raises on a unit pint does not know

    def test_categorical_values_carry_flags_not_units(self):
        labelled = 0
        for path in self.files():
            with h5py.File(path, "r") as f:
                def check(name, obj):
                    nonlocal labelled
                    if not isinstance(obj, h5py.Dataset):
                        return
                    unit = text(obj.attrs.get("unit", ""))
                    enum = h5py.check_enum_dtype(obj.dtype) is not None
                    if unit.startswith("labels:") or enum:
                        labelled += 1
                        with self.subTest(file=os.path.basename(path), dataset=name):
                            self.assertNotIn("units", obj.attrs)
                            meanings = text(obj.attrs["flag_meanings"]).split(" ")
                            self.assertEqual(len(np.atleast_1d(obj.attrs["flag_values"])), len(meanings))
                f.visititems(check)
        self.assertGreater(labelled, 5)

    def test_integer_runs_columns_carry_their_fill_value(self):
        for path in self.files():
            with h5py.File(path, "r") as f:
                for name, d in f["runs"].items():
                    if d.dtype.kind == "i" and h5py.check_enum_dtype(d.dtype) is None and name != "run_id":
                        with self.subTest(file=os.path.basename(path), column=name):
                            self.assertEqual(int(d.attrs["_FillValue"]), -1)

    def open_and_compare(self, path, group):
        with h5py.File(path, "r") as f, \
                xr.open_dataset(path, group=group, engine="h5netcdf", mask_and_scale=False,
                                decode_times=False) as ds:
            phony = [d for d in ds.dims if str(d).startswith("phony_dim")]
            self.assertEqual(phony, [], f"{group}: phony dimensions")
            g = f[group]
            for name, d in g.items():
                if isinstance(d, h5py.Dataset) and d.dtype.kind in "fiu" and name in ds.variables:
                    self.assertTrue(same(ds[name].values, d[()]), f"{group}/{name}")
            for dim in ds.dims:
                if dim in ds.coords and len(np.unique(ds[dim].values)) == ds.sizes[dim] and ds.sizes[dim]:
                    first = ds[dim].values[0]
                    self.assertEqual(ds.sel({dim: first})[dim].values.item(), first, f"{group}: {dim}")
                elif ds.sizes[dim]:
                    self.assertEqual(ds.isel({dim: 0}).sizes.get(dim), None, f"{group}: {dim}")

    def test_root_runs_landscapes_designs_open_in_xarray(self):
        opened = 0
        for path in self.files():
            for group in groups_of(path):
                if group.startswith(("/histories", "/optimizations")):
                    continue
                with self.subTest(file=os.path.basename(path), group=group):
                    self.open_and_compare(path, group)
                    opened += 1
        self.assertGreater(opened, 20)

    def test_histories_and_optimizations_open_in_xarray(self):
        """/histories (the rows of every run in one row space: dimensions history_row, run_id and
        <dataset>_column) and every group under /optimizations (evaluation, stage, start, variable,
        row) open with named dimensions only."""
        opened = 0
        for path in self.files():
            for group in groups_of(path):
                if group.startswith(("/histories", "/optimizations")):
                    with self.subTest(file=os.path.basename(path), group=group):
                        self.open_and_compare(path, group)
                        opened += 1
        self.assertGreater(opened, 5)


if __name__ == "__main__":
    RESULTS = os.path.abspath(sys.argv[1])
    unittest.main(argv=[sys.argv[0], "-v"])
