"""The plain data types kinesweep.read returns: Table (a /runs table or a history), Axis and Landscape (a
block's gridded metrics), with their conversions to pandas and xarray (each an optional dependency,
imported when asked for), and FormatVersionError (a file of a format_version the readers do not read).
Run with Debian's interpreter: /usr/bin/python3.
"""
from collections.abc import Mapping

import numpy as np

TRAJECTORY_STATUSES = ["ok", "unreachable_start", "singular", "diverged", "undersampled", "off_path",
                       "out_of_limits", "max_evaluations", "not_converged", "infeasible", "singular_extension",
                       "out_of_reach"]
IK_STATUSES = ["converged", "stalled", "singular", "max_iter", "cycle", "diverged", "unsupported", "no_solution",
               "out_of_limits"]
# What each run kind means, for files written before the engine recorded it under /kinds (the engine's
# declarations, schema/params.hpp; tests/python/test_kinds.py checks a new file's /kinds against them).
KIND_MEANING = {
    "trajectory": {"statuses": TRAJECTORY_STATUSES, "good_statuses": ["ok"], "ranking": ["E"],
                   "key_metrics": ["E", "E_M", "tau_inf"],
                   "history_arrays": ["t", "q", "qd", "qdd", "tau", "x", "alpha"],
                   "resume_context": ["robot", "task", "settings"]},
    "ik": {"statuses": IK_STATUSES, "good_statuses": ["converged"], "ranking": ["iterations", "error"],
           "key_metrics": ["iterations", "error", "solution"],
           "history_arrays": ["k", "q", "F", "norm_F", "step", "lambda"],
           "resume_context": ["robot", "settings"]},
}
GOOD_STATUSES = [s for m in KIND_MEANING.values() for s in m["good_statuses"]]
# Keywords of xarray's Dataset.sel: a landscape axis of one of these names is stored (and is a
# dimension) under the name with "_" appended (store/h5util.hpp axis_dataset_name), so that
# ds.sel(method_="lm") selects along it.
SEL_KEYWORDS = ("method", "tolerance", "drop", "indexers")


def is_netcdf_dimension(dataset):
    """True for a dataset that only names a netCDF dimension (no values: /histories' run_id and
    history_row, /optimizations' evaluation, variable, ...; FORMAT.md)."""
    return b"This is a netCDF dimension but not a netCDF variable" in bytes(dataset.attrs.get("NAME", b""))


def axis_dataset_name(axis):
    """The dataset and dimension name of landscape axis `axis` (see SEL_KEYWORDS)."""
    return axis + "_" if axis in SEL_KEYWORDS else axis
# Display labels of metrics for files written before the engine recorded them (the attribute
# `display_name` of each metric column and landscape metric, from the kind's metric table); a metric
# not listed shows its name. "convergence" is the fraction of converged runs the plots derive.
METRIC_LABELS = {"E": "E (mean ‖τ‖)", "E_M": "E_M (mean ‖τ‖ in M⁻¹ norm)", "tau_inf": "‖τ‖∞",
                 "tau1_inf": "‖τ1‖∞", "tau2_inf": "‖τ2‖∞", "tau3_inf": "‖τ3‖∞",
                 "iterations": "iterations", "convergence": "convergence fraction", "error": "final ‖F‖",
                 "min_manipulability": "min manipulability", "max_tracking_error": "max tracking error",
                 "peak_joint_power": "peak joint power"}

# The colour of each failed status in every plot and the report (good runs are drawn by their metric).
STATUS_COLOURS = {"unreachable_start": "#b0b0b0", "singular": "#7b3294", "diverged": "#202020",
                  "undersampled": "#8c6d31", "off_path": "#c51b7d",
                  "stalled": "#e08214", "max_iter": "#d7191c", "cycle": "#f4a582", "unsupported": "#6a6a6a",
                  "no_solution": "#8f8f8f", "out_of_limits": "#fdae61",
                  "max_evaluations": "#b35806", "not_converged": "#fee090", "infeasible": "#4d4d4d",
                  "singular_extension": "#542788", "out_of_reach": "#969696"}
# Seed 000, Table 4 (copied from engine/methods/closed_form/seed_cases.cpp, checked against it by the tests):
# case -> (method, k, alpha1A [deg], thesis E [Nm], thesis (|tau1|inf, |tau2|inf, |tau3|inf) [Nm]).
THESIS_TABLE4 = {
    "1a": ("local_weighted", 0.0, 0.0, 51.03, (82.63, 32.31, 8.77)),
    "1b": ("local_weighted", 0.0, 0.0, 51.03, (82.63, 32.31, 8.77)),
    "1c": ("local_weighted", 0.0, 15.0, 55.77, (79.09, 33.26, 8.41)),
    "1d": ("local_weighted", 0.57, 15.0, 51.70, (627.76, 111.32, 12.21)),
    "1e": ("local_weighted", 0.0, 30.0, 62.27, (93.33, 42.30, 7.21)),
    "1f": ("local_weighted", 0.16, 30.0, 54.32, (215.59, 50.28, 9.52)),
    "1g": ("local_weighted", 0.0, -23.5, 38.63, (101.39, 45.40, 8.78)),
    "1h": ("local_weighted", 0.13, -24.1, 37.79, (109.44, 48.33, 8.79)),
    "2a": ("local_unweighted", 0.0, 0.0, 48.63, (50.33, 30.00, 8.71)),
    "2b": ("local_unweighted", 0.0, 0.0, 48.63, (50.33, 30.00, 8.71)),
    "2c": ("local_unweighted", 0.0, 15.0, 54.09, (57.32, 29.14, 8.61)),
    "2d": ("local_unweighted", 0.75, 15.0, 54.07, (5301.60, 2135.90, 263.50)),
    "2e": ("local_unweighted", 0.0, 30.0, 61.04, (387.90, 153.58, 22.35)),
    "2f": ("local_unweighted", 0.18, 30.0, 54.83, (1076.50, 401.30, 49.40)),
    "2g": ("local_unweighted", 0.0, -20.1, 39.41, (59.77, 51.65, 8.95)),
    "2h": ("local_unweighted", 0.06, -23.5, 37.41, (90.23, 60.75, 10.30)),
    "3": ("vertex_alpha", 0.0, -18.9, 53.58, (139.75, 35.49, 8.56)),
    "4": ("vertex_alpha", 0.0, -18.3, 48.39, (116.40, 30.83, 8.58)),
    "5a": ("vertex_alpha", 0.0, 0.0, 66.65, (178.82, 28.20, 8.26)),
    "5b": ("vertex_alpha", 0.0, 15.0, 60.81, (121.11, 28.22, 8.26)),
    "5c": ("vertex_alpha", 0.0, 30.0, 60.05, (107.88, 28.23, 8.26)),
}

# A converged run that reached none of the solutions a basin plot names.
OTHER_SOLUTION_COLOUR = "#c7c7c7"


class FormatVersionError(ValueError):
    """A results file of a format_version the reader does not read."""


def _s(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def display_name(dset, name):
    """How plots name the column or landscape metric `name` stored in `dset`: its `display_name`
    attribute, else (older files) METRIC_LABELS, else the name."""
    v = dset.attrs.get("display_name")
    return _s(v) if v is not None else METRIC_LABELS.get(name, name)


def enum_labels(dset):
    """The labels of a labelled /runs text column by code (an HDF5 enum, format 4), else None."""
    import h5py  # here, not at the top: importing kinesweep.kinds does not import h5py
    e = h5py.check_enum_dtype(dset.dtype)
    if e is None:
        return None
    missing = 256 ** dset.dtype.itemsize - 1  # the missing code's member (format 5) names no label
    e = {name: int(code) for name, code in e.items() if int(code) != missing}
    labels = [""] * len(e)
    for name, code in e.items():
        labels[code] = name
    return labels


def text_values(dset, codes=None):
    """A text column (all rows, or the given enum `codes`) as an object array of str: enum codes
    through their labels (a code without one, the missing value, as ""), strings decoded."""
    labels = enum_labels(dset)
    if labels is None:
        return np.array([_s(x) for x in (dset[()] if codes is None else codes)], dtype=object)
    table = np.array(labels + [""] * (256 ** dset.dtype.itemsize - len(labels)), dtype=object)
    return table[dset[()] if codes is None else codes]


class Table(dict):
    """dict of column name -> 1-D numpy array, with .units, .descriptions and .display_names (how plots
    name a column) dicts (runs(): also .roles, column -> "parameter" | "metric" | "bookkeeping", and
    .kinds, column -> list of run kinds, [] = all)."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.units = {}
        self.descriptions = {}
        self.display_names = {}
        self.roles = {}
        self.kinds = {}

    def __len__(self):  # number of rows, as for a DataFrame
        return len(next(iter(self.values()))) if dict.__len__(self) else 0

    def columns(self):
        return list(self.keys())

    def to_pandas(self):
        import pandas as pd  # optional dependency
        df = pd.DataFrame(dict(self))
        df.attrs["units"] = dict(self.units)
        return df


class Axis:
    """A landscape dimension: name, unit, values, labels (a string axis), and for a sampled dimension
    (format 5: `sample`, values 0..n-1) its parameters along it, `coordinates` (list of Axis)."""

    def __init__(self, name, unit, values, labels=None, coordinates=None):
        self.name, self.unit, self.values, self.labels = name, unit, values, labels
        self.coordinates = coordinates or []

    @property
    def categorical(self):
        return self.labels is not None

    @property
    def sampled(self):
        """The points of a design, which no grid or heatmap can draw: a dimension of several axes
        advancing together ("a+b", an LHS group or a zip) whose values are not monotonic, or numeric
        values that repeat (a Saltelli design). A single random axis is a grid axis (sorted)."""
        if self.coordinates:
            return True
        if self.categorical or len(self.values) < 2:
            return False
        v = np.asarray(self.values, dtype=float)
        d = np.diff(v)
        return len(np.unique(v)) < len(v) or ("+" in self.name and not (np.all(d > 0) or np.all(d < 0)))

    def __repr__(self):
        return f"Axis({self.name!r}, {self.unit!r}, {len(self.values)} values)"


class Landscape:
    """A block's gridded metrics: .axes (list of Axis), .metrics (name -> N-D array, NaN = no value),
    .units / .descriptions / .display_names (name -> str; display_names: how plots name a metric),
    .kind (the block's run kind, from its /runs rows). metrics[m][i, j, ...] is at axes[0].values[i], ..."""

    def __init__(self, block, axes, metrics, units, descriptions, kind="", meaning=None, display_names=None):
        self.block, self.axes, self.metrics, self.units, self.descriptions = block, axes, metrics, units, descriptions
        self.display_names = display_names if display_names is not None else {m: METRIC_LABELS.get(m, m) for m in units}
        self._kind = kind
        # what the block's run kind means (ksread.Results.kind_meaning): statuses, ranking, ...
        self.meaning = meaning if meaning is not None else {k: list(v) for k, v in KIND_MEANING.get(kind, {}).items()}

    def label(self, metric):
        """How plots name `metric`: its display name, or a derived metric's ("convergence")."""
        return self.display_names.get(metric) or METRIC_LABELS.get(metric, metric)

    def axis(self, name):
        for a in self.axes:
            if a.name == name:
                return a
        raise KeyError(f"landscape {self.block} has no axis {name!r}; axes: {', '.join(a.name for a in self.axes)}")

    def axis_index(self, name):
        return [a.name for a in self.axes].index(self.axis(name).name)

    @property
    def kind(self):
        return self._kind

    @property
    def statuses(self):
        """The kind's statuses in code order (status_code indexes them; code 0 is the good one)."""
        return self.meaning.get("statuses", IK_STATUSES if self.kind == "ik" else TRAJECTORY_STATUSES)

    @property
    def objective(self):
        """The metric the kind's runs are ranked by (E; ik: iterations), or None."""
        return next(iter(self.meaning.get("ranking", [])), None)

    def status_grids(self):
        """The names of the grids of statuses (the good-status grid and status_code), not metrics."""
        return (self.statuses[0], "status_code")

    @staticmethod
    def _coordinate(a):
        """An axis' coordinate values: its values, or the label each value (0 .. n-1) indexes."""
        return np.array([a.labels[int(v)] for v in a.values], dtype=object) if a.categorical else a.values

    def to_xarray(self):
        """The landscape as an xarray.Dataset: one data variable per metric over the dimensions named
        after the axes (`method_` for `method`, as in the file: SEL_KEYWORDS), each axis a coordinate
        (its labels for a string axis such as `method`); units
        and descriptions in the variables' attrs ("units", "long_name"), block and kind in the Dataset's."""
        import xarray as xr  # optional dependency
        dims = [axis_dataset_name(a.name) for a in self.axes]
        coords = {d: (d, self._coordinate(a), {"units": a.unit}) for d, a in zip(dims, self.axes)}
        for d, a in zip(dims, self.axes):  # a sampled dimension's parameters, coordinates along it
            coords.update({axis_dataset_name(c.name): (d, self._coordinate(c), {"units": c.unit})
                           for c in a.coordinates})
        data = {m: (dims, v, {"units": self.units.get(m, ""), "long_name": self.descriptions.get(m, "")})
                for m, v in self.metrics.items()}
        return xr.Dataset(data, coords=coords, attrs={"block": self.block, "kind": self.kind})


def _grid(d):
    """A landscape grid as float64: a grid of codes (integer, format 5) with -1 (no run) as NaN."""
    v = np.asarray(d[()])  # a new array (0-d for a scalar dataset): float64 grids are not copied again
    v = v if v.dtype == np.float64 else v.astype(float)
    if d.dtype.kind in "iu":
        v[v == -1] = np.nan
    return v

class _Grids(Mapping):
    """A landscape's metric grids by name, each read from the file when first asked for (a
    3163 x 3163 landscape's 14 grids are 1.1 GB; a plot reads one or two), so while the Results
    that made it is open (read_landscape() reads them all)."""

    def __init__(self, names, read, dataset=None):
        self._names, self._read, self._grids, self._dataset = list(names), read, {}, dataset

    def __getitem__(self, name):
        if name not in self._names:
            raise KeyError(name)
        if name not in self._grids:
            self._grids[name] = self._read(name)
        return self._grids[name]

    def read(self, name):
        """The grid `name` without keeping it (the kept one when it was read before): for a caller
        that goes through every grid once and keeps less than all of them."""
        if name not in self._names:
            raise KeyError(name)
        return self._grids[name] if name in self._grids else self._read(name)

    def fresh(self, name):
        """The grid `name` read from the file again: a new array the caller may change."""
        if name not in self._names:
            raise KeyError(name)
        return self._read(name)

    def is_read(self, name):
        """Whether the grid `name` was read and kept (by metrics[name])."""
        return name in self._grids

    def dataset(self, name):
        """The grid's h5py dataset (kinesweep.grid_blocks reads it a block at a time), or its array
        when the landscape has no file behind it."""
        if name not in self._names:
            raise KeyError(name)
        return self._dataset(name) if self._dataset is not None else self[name]

    def __contains__(self, name):  # by name (Mapping's would read the grid and keep it)
        return name in self._names

    def __iter__(self):
        return iter(self._names)

    def __len__(self):
        return len(self._names)
