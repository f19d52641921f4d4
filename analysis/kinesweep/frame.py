"""The /runs table as a pandas.DataFrame at the speed of the reads: numeric columns read straight
into the frame's own arrays, labelled text columns (HDF5 enums) as categoricals built from their
codes, other text as str objects. Memory: the frame itself plus one column (and, when some rows are
not done and done_only is set, a second copy of the frame while the done rows are taken).
Run with Debian's interpreter: /usr/bin/python3.
"""
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


def runs_frame(g, names, done, roles, kinds, degrees=False):
    """The columns `names` of the /runs group `g` (h5py) as a DataFrame, rows where `done` (a bool
    array, or None for every row). df.attrs: units, descriptions, roles, kinds (per column)."""
    import pandas as pd  # optional dependency
    n = len(g["done"]) if done is None else len(done)
    floats = [c for c in names if g[c].dtype.kind == "f"]
    block = np.empty((len(floats), n), dtype=np.float64)  # the frame's float block, column-major
    units = {c: _s(g[c].attrs.get("unit", "")) for c in names}
    for i, c in enumerate(floats):
        if n:
            g[c].read_direct(block[i])
        if degrees and units[c] == "rad":
            block[i] *= RAD2DEG
    df = pd.DataFrame(block.T, columns=floats, copy=False)
    for at, c in enumerate(names):
        if c in df.columns:
            continue
        d = g[c]
        labels = enum_labels(d)
        v = categorical(d[()], labels) if labels is not None else d[()]
        if labels is None and v.dtype.kind in "OSU":
            v = text_values(d, v)
        df.insert(at, c, v)
    if degrees:
        units = {c: "deg" if u == "rad" and g[c].dtype.kind == "f" else u for c, u in units.items()}
    if done is not None and not done.all():
        df = df[done].reset_index(drop=True)
    df.attrs["units"] = units
    df.attrs["descriptions"] = {c: _s(g[c].attrs.get("description", "")) for c in names}
    df.attrs["roles"] = {c: roles.get(c, "bookkeeping") for c in names}
    df.attrs["kinds"] = {c: list(kinds.get(c, [])) for c in names}
    return df
