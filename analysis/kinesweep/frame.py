"""The /runs table as a pandas.DataFrame at the speed of the reads: numeric columns read straight
into the frame's own arrays, labelled text columns (HDF5 enums) as categoricals built from their
codes, other text as str objects. Memory: the frame itself plus one column, whatever rows are
selected.
Run with Debian's interpreter: /usr/bin/python3.
"""
from collections.abc import Mapping

import numpy as np

from kinesweep.kinds import _s, enum_labels, text_values

RAD2DEG = 180.0 / np.pi


def categorical(codes, labels):
    """A pandas Categorical of enum codes: categories the labels, then "" when a code has no label
    (the missing value): the values text_values() gives, without a str object per row."""
    import pandas as pd  # optional dependency
    codes = np.asarray(codes).astype(np.int32)
    missing = codes >= len(labels)
    cats = list(labels)
    if missing.any():
        codes[missing] = len(cats)
        cats.append("")
    return pd.Categorical.from_codes(codes, categories=cats)


def runs_frame(g, names, rows, roles, kinds, degrees=False):
    """The columns `names` of the /runs group `g` (h5py) as a DataFrame, the rows where `rows` (a bool
    array, or None for every row) is set: each column is read whole and its selected rows copied into
    the frame (memory: the frame plus one column). df.attrs: units, descriptions, roles, kinds."""
    import pandas as pd  # optional dependency
    every = rows is None or rows.all()
    n = len(g["done"]) if rows is None else int(rows.sum())
    floats = [c for c in names if g[c].dtype.kind == "f"]
    block = np.empty((len(floats), n), dtype=np.float64)  # the frame's float block, column-major
    units = {c: _s(g[c].attrs.get("unit", "")) for c in names}
    for i, c in enumerate(floats):
        if n and every:
            g[c].read_direct(block[i])
        elif n:
            block[i] = g[c][()][rows]
        if degrees and units[c] == "rad":
            block[i] *= RAD2DEG
    df = pd.DataFrame(block.T, columns=floats, copy=False)
    for at, c in enumerate(names):
        if c in df.columns:
            continue
        d = g[c]
        labels = enum_labels(d)
        v = d[()] if every else d[()][rows]
        if labels is not None:
            v = categorical(v, labels)
        elif v.dtype.kind in "OSU":
            v = text_values(d, v)
        df.insert(at, c, v)
    if degrees:
        units = {c: "deg" if u == "rad" and g[c].dtype.kind == "f" else u for c, u in units.items()}
    df.attrs["units"] = units
    df.attrs["descriptions"] = {c: _s(g[c].attrs.get("description", "")) for c in names}
    df.attrs["roles"] = {c: roles.get(c, "bookkeeping") for c in names}
    df.attrs["kinds"] = {c: list(kinds.get(c, [])) for c in names}
    return df


class LazyColumns(Mapping):
    """The /runs columns by name, each read when asked (text as str objects, numbers as stored, each
    column's unit in .units): what kinesweep.where.select reads a filter's columns from."""

    def __init__(self, g, names):
        self._g, self._names = g, list(names)
        self.units = {c: _s(g[c].attrs.get("unit", "")) for c in self._names}

    def __getitem__(self, name):
        if name not in self._names:
            raise KeyError(name)
        d = self._g[name]
        v = d[()]
        return text_values(d, v) if enum_labels(d) is not None or v.dtype.kind in "OSU" else v

    def __iter__(self):
        return iter(self._names)

    def __len__(self):
        return len(self._names)
