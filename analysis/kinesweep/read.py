"""Read kinesweep results files (HDF5, layout in engine/store/FORMAT.md) with h5py and numpy.

    from kinesweep import read as ksread
    r = ksread.open_results("results/thesis_table4.h5")
    runs = r.runs()                      # dict of numpy arrays (done rows only), .units / .descriptions
    runs["E"], runs.units["E"]           # array, "Nm"
    r.parameters(), r.metrics("ik")      # column names by role (and run kind), from the file's attributes
    r.row_kinds()                        # each (done) row's run kind: "trajectory", "ik"
    df = r.to_pandas()                   # the same as a pandas.DataFrame (units in df.attrs)
    h = r.history(3)                     # dict of 2-D arrays (rows x components) with .units
    r.has_history(3)                     # whether run 3 has a history
    r.history_arrays(3)                  # its array names in the run's order: ["t", "q", "qd", ...]
    r.history_ids(), r.history_count()   # the run ids that have a history (ascending), how many
    ls = r.landscape("local")            # axes (name, unit, values, labels) and gridded metrics
    ds = r.to_xarray("local")            # the same as an xarray.Dataset: named dimensions, coordinates, units
    o = r.optimization("1h", degrees=True)   # an [[optimize]] block: evaluations, stages, local paths, best
    o.evaluations["x"], o.units          # n x d points, one unit per variable ("deg" for angles here)

Angles are stored in radians (unit "rad"); pass degrees=True to runs()/history()/landscape()/optimization() to get
them in degrees (their unit then reads "deg"). Run with Debian's interpreter: /usr/bin/python3.

Column roles (parameter, metric, bookkeeping) and the run kinds a column applies to are the /runs
datasets' `role` and `kinds` attributes (FORMAT.md, format_version 2 to 4); files of format_version 1
lack them and are refused with FormatVersionError (kinesweep info / query still read them), as are
versions newer than 4. Versions 2 and 3 differ in the /histories layout only, which kshistory reads;
in version 4 the text columns with few distinct values are HDF5 enums (read here as the same str
values, and by to_pandas() as pandas categoricals).
"""
import os

import h5py
import numpy as np

from kinesweep import frame
from kinesweep.chunks import one_value
from kinesweep import history as kshistory
from kinesweep import live as kslive
from kinesweep import where as kswhere
from kinesweep.optimization import Optimization  # noqa: F401 (part of this module's interface)
from kinesweep.solutions import cluster_solutions  # noqa: F401 (part of this module's interface)
from kinesweep.kinds import FormatVersionError  # noqa: F401 (the same)
from kinesweep.kinds import (GOOD_STATUSES, IK_STATUSES, KIND_MEANING, METRIC_LABELS, OTHER_SOLUTION_COLOUR,  # noqa: F401
                             STATUS_COLOURS, THESIS_TABLE4, TRAJECTORY_STATUSES, Axis, Landscape, Table, _s,
                             axis_dataset_name, display_name, enum_labels, text_values)
from kinesweep.kinds import _grid, _Grids  # noqa: F401 (a landscape's grids, read when asked for)

RAD2DEG = 180.0 / np.pi
FORMAT_VERSIONS = (2, 3, 4, 5)  # the results formats this module reads (engine/store/FORMAT.md)
ROLES = ("parameter", "metric", "bookkeeping")

# The thesis' optimised points on the (alpha1A, k) landscape of each local method:
# the global optimum (1h / 2h) and the partial optima (k or alpha1A optimised alone).
THESIS_OPTIMA = {
    "local_weighted": {"global": "1h", "partial": ["1d", "1f", "1g"]},
    "local_unweighted": {"global": "2h", "partial": ["2d", "2f", "2g"]},
}


class Results:
    """An open results file (read-only). Safe on a file a sweep is writing: every call reads one
    committed state, the newest when it starts (kslive: retried from a fresh open when a commit lands
    under it), so run counts never go backwards."""

    def __init__(self, path):
        if not os.path.exists(path):
            raise FileNotFoundError(path)
        self.path = path
        self.f, self._stamp = kslive.open_snapshot(path, self._open_file)

    def _reopen(self):
        """A fresh handle on the file's newest committed state (kslive.consistent calls it)."""
        self.f.close()
        self.f, self._stamp = kslive.open_snapshot(self.path, lambda: h5py.File(self.path, "r"))

    def _open_file(self):
        """Open the file and read what every call needs (format, roles and kinds of the columns)."""
        path = self.path
        f = h5py.File(path, "r")
        try:
            a = f.attrs
            if _s(a.get("format", "")) != "kinesweep-results":
                raise ValueError(f"{path}: not a kinesweep results file")
            self.meta = {k: (_s(v) if isinstance(v, (bytes, str)) else v.item() if hasattr(v, "item") else v)
                         for k, v in a.items()}
            version = int(self.meta.get("format_version", -1))
            if version not in FORMAT_VERSIONS:
                engine = self.meta.get("engine_version", "?")
                what = (f"{path}: results file format v{version} (written by kinesweep {engine}); kinesweep.read reads "
                        f"v{min(FORMAT_VERSIONS)} to v{max(FORMAT_VERSIONS)} only")
                if version < min(FORMAT_VERSIONS):
                    what += (" (v1 files have no role/kinds attributes on their /runs columns). `kinesweep query` "
                             "and `kinesweep info` still read this file; to use it here, rerun its study: "
                             "kinesweep run STUDY.toml --overwrite")
                raise FormatVersionError(what)
            self.study_text = _s(f["study"]["text"][()])
            self._roles, self._kinds = {}, {}
            for c in (_s(x) for x in f["runs"].attrs["columns"]):
                attrs = f["runs"][c].attrs
                role = _s(attrs.get("role", ""))
                if role not in ROLES or "kinds" not in attrs:
                    raise ValueError(f"{path}: /runs/{c} has no valid role/kinds attributes (role {role!r})")
                self._roles[c] = role
                self._kinds[c] = [k for k in _s(attrs["kinds"]).split(",") if k]
        except Exception:
            f.close()
            raise
        return f

    def close(self):
        self.f.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @property
    @kslive.consistent
    def n_runs(self):
        return int(self.f["runs"].attrs.get("n_runs", len(self.f["runs"]["done"])))

    @kslive.consistent
    def columns(self):
        return [_s(c) for c in self.f["runs"].attrs["columns"]]

    @kslive.consistent
    def units(self):
        return {c: _s(self.f["runs"][c].attrs.get("unit", "")) for c in self.columns()}

    def roles(self):
        """column -> "parameter" | "metric" | "bookkeeping" (the /runs datasets' role attribute)."""
        return dict(self._roles)

    def kinds(self):
        """column -> the run kinds it applies to (its kinds attribute split at commas; [] = every run)."""
        return {c: list(k) for c, k in self._kinds.items()}

    def sensitivity(self, **kw):
        """Sobol' indices of the blocks run as a Saltelli design (kinesweep.sensitivity.sensitivity)."""
        from kinesweep.sensitivity import sensitivity
        return sensitivity(self, **kw)

    def importance(self, **kw):
        """Permutation importance of a block's swept parameters from a random-forest fit
        (kinesweep.importance.permutation_importance; needs python3-sklearn)."""
        from kinesweep.importance import permutation_importance
        return permutation_importance(self, **kw)

    @kslive.consistent
    def kind_meaning(self, kind):
        """What runs of `kind` mean, as the file records it (/kinds/<kind>): {"statuses": in code
        order, "good_statuses", "ranking": [objective, tie...] (best = lowest among good runs, then
        by run id), "key_metrics", "objectives", "history_arrays", ...}, each a list of str. Files
        from before /kinds: the engine's declarations (kinesweep.kinds.KIND_MEANING); {} for an unknown kind."""
        g = self.f.get("kinds")
        if g is not None and kind in g:
            return {k: [_s(x) for x in v] for k, v in g[kind].attrs.items()}
        return {k: list(v) for k, v in KIND_MEANING.get(kind, {}).items()}

    def run_kinds(self):
        """The run kinds the columns name ("trajectory", "ik"), first seen first."""
        out = []
        for ks in self._kinds.values():
            out += [k for k in ks if k not in out]
        return out

    def _by_role(self, role, kind):
        return [c for c in self.columns() if self._roles[c] == role and (kind is None or not self._kinds[c]
                                                                        or kind in self._kinds[c])]

    def parameters(self, kind=None):
        """Parameter columns in file order (of one run kind, when given)."""
        return self._by_role("parameter", kind)

    def metrics(self, kind=None):
        """Metric columns in file order (of one run kind, when given)."""
        return self._by_role("metric", kind)

    def bookkeeping(self):
        """The bookkeeping columns (run_id, block, status, wall_time)."""
        return self._by_role("bookkeeping", None)

    @kslive.consistent
    def row_kinds(self, done_only=True, rows=None):
        """Each row's run kind, an object array aligned with runs(done_only=...): the kind of the
        single-kind parameter (else metric) columns that hold a value in the row; "" when none does
        (a row not done yet). A file of one kind: that kind for every row. With `rows` (ascending
        row indices): the kinds of those rows only, done or not, read by index."""
        g = self.f["runs"]
        if rows is not None:
            rows = np.asarray(rows, dtype=np.int64)
            done_only = False
        done = g["done"][()].astype(bool) if rows is None else np.ones(len(rows), dtype=bool)
        kinds = self.run_kinds()
        out = np.full(len(done), kinds[0] if len(kinds) == 1 else "", dtype=object)
        if len(kinds) > 1 and len(done):
            for role in ("parameter", "metric"):
                for c in self._by_role(role, None):
                    if len(self._kinds[c]) != 1:
                        continue
                    v = g[c][()] if rows is None else g[c][rows]
                    labels = enum_labels(g[c])
                    if labels is not None:
                        held = v < len(labels)
                    elif v.dtype.kind == "f":
                        held = ~np.isnan(v)
                    elif v.dtype.kind in "iu":
                        held = v != -1
                    else:
                        held = np.array([len(x) > 0 for x in v], dtype=bool)
                    out[(out == "") & held] = self._kinds[c][0]
        return out[done] if done_only else out

    def row_kind(self, run_id):
        """The run kind of one row (see row_kinds)."""
        return self.row_kinds(done_only=False)[int(run_id)]

    @kslive.consistent
    def runs(self, columns=None, done_only=True, degrees=False, pandas=False, where=None):
        """The /runs table: Table (dict of arrays; strings as str objects) or a pandas DataFrame
        (to_pandas()); `where` selects rows as in to_pandas()."""
        if pandas:
            return self.to_pandas(columns, done_only=done_only, degrees=degrees, where=where)
        g = self.f["runs"]
        done = g["done"][()].astype(bool)  # before the columns (a writer may be committing)
        names = self.columns() if columns is None else list(columns)
        rows = self._where_rows(where, done, done_only)
        t = Table()
        for c in names:
            if c not in g:
                raise KeyError(f"no column {c!r}; columns: {', '.join(self.columns())}")
            d = g[c]
            v = d[()]
            labels = enum_labels(d)
            if labels is not None or v.dtype.kind in "OSU":
                v = text_values(d, v)
            unit = _s(d.attrs.get("unit", ""))
            if degrees and unit == "rad":
                v, unit = v * RAD2DEG, "deg"
            t[c] = v if rows is None else v[rows]
            t.units[c] = unit
            t.descriptions[c] = _s(d.attrs.get("description", ""))
            t.display_names[c] = display_name(d, c)
            t.roles[c] = self._roles[c]
            t.kinds[c] = list(self._kinds[c])
        if not done_only:
            t["done"] = done if rows is None else done[rows]
            t.units["done"] = ""
            t.roles["done"], t.kinds["done"] = "bookkeeping", []
        return t

    def _where_rows(self, where, done, done_only):
        """The rows to read: done ones (done_only) where every expression of `where` holds (None or a
        str or list of str, `kinesweep query --where` syntax, angles in degrees); None for all rows.
        Only the columns the expressions name are read."""
        rows = done if done_only else None
        if where:
            exprs = [where] if isinstance(where, str) else list(where)
            g = self.f["runs"]
            text = [c for c in self.columns() if enum_labels(g[c]) is not None or g[c].dtype.kind in "OSU"]
            mask = kswhere.select(frame.LazyColumns(g, self.columns()), exprs, degrees=True, text_columns=text,
                                  rows=len(done))
            rows = mask if rows is None else rows & mask
        return rows

    @kslive.consistent
    def to_pandas(self, columns=None, done_only=True, degrees=False, where=None):
        """The /runs table (or its `columns`) as a pandas.DataFrame: numbers read straight into the
        frame, labelled text as categoricals (kinesweep.frame); df.attrs["units"], ["descriptions"],
        ["roles"], ["kinds"]. With done_only=False a bool column `done` is added. `where`: a row
        filter, one expression or a list, in `kinesweep query --where` syntax (angles in degrees):
        the columns it names are read first, then only the selected rows of the others are kept
        (memory: the frame plus one column). Raises kinesweep.where.WhereError for a bad one."""
        g = self.f["runs"]
        done = g["done"][()].astype(bool)  # before the columns (a writer may be committing)
        names = self.columns() if columns is None else list(columns)
        for c in names:
            if c not in g:
                raise KeyError(f"no column {c!r}; columns: {', '.join(self.columns())}")
        rows = self._where_rows(where, done, done_only)
        df = frame.runs_frame(g, names, rows, self._roles, self._kinds, degrees)
        if not done_only:
            df["done"] = done if rows is None else done[rows]
            df.attrs["units"]["done"] = ""
        return df

    def to_xarray(self, block=None, degrees=False):
        """A block's landscape (default: the first) as an xarray.Dataset (Landscape.to_xarray)."""
        return self.landscape(block, degrees=degrees).to_xarray()

    def _histories(self):
        """The kshistory reader of the current handle (a fresh one after each reopen)."""
        if getattr(self, "_hist", None) is None or self._hist.f is not self.f:
            self._hist = kshistory.Histories(self.f)
        return self._hist

    @kslive.consistent
    def has_history(self, run_id):
        """Whether run run_id has a history (one of 0 rows included)."""
        return self._histories().has(run_id)

    @kslive.consistent
    def history_arrays(self, run_id):
        """The names of the run's history arrays in the order the run produced them ([] without one)."""
        return self._histories().names(run_id)

    @kslive.consistent
    def history_ids(self):
        """The run ids that have a history, ascending (int64 array)."""
        return self._histories().ids()

    @kslive.consistent
    def history_count(self):
        """The number of runs that have a history."""
        return self._histories().count()

    @kslive.consistent
    def history(self, run_id, degrees=False):
        """One run's history: Table of name -> 2-D array (rows x components), .units per array
        (IK q: "rad, rad, mm" -- one unit per component). KeyError when the run has none."""
        if not self.has_history(run_id):
            raise KeyError(f"run {run_id} has no history in {self.path}")
        h = Table()
        for a, v, unit in self._histories().read(run_id):
            if degrees:
                parts = [p.strip() for p in unit.split(",")]
                if len(parts) == v.shape[1] and "rad" in parts:
                    v = v.copy()
                    for j, p in enumerate(parts):
                        if p == "rad":
                            v[:, j] *= RAD2DEG
                            parts[j] = "deg"
                    unit = ", ".join(parts)
                elif unit == "rad":
                    v, unit = v * RAD2DEG, "deg"
            h[a] = v
            h.units[a] = unit
        return h

    @kslive.consistent
    def blocks(self):
        """The block names in file order: order of first appearance in the /runs `block` column."""
        if "block" not in self.f["runs"]:
            return []
        d = self.f["runs"]["block"]
        labels = enum_labels(d)
        if labels is not None and one_value(d):  # one block (its code in every row): no row decoded
            c = int(d[0])
            return [labels[c]] if c < len(labels) else []
        if labels is not None:  # in order of first appearance, as for strings
            codes = d[()]
            present, first = np.unique(codes, return_index=True)
            return [labels[c] for c, _ in sorted(zip(present, first), key=lambda p: p[1]) if c < len(labels)]
        names = [_s(x) for x in d[()]]
        return [b for b in dict.fromkeys(names) if b]

    @kslive.consistent
    def landscapes(self):
        """The /landscapes groups in block order (blocks()), any other after them."""
        if "landscapes" not in self.f:
            return []
        have = list(self.f["landscapes"])
        order = [b for b in self.blocks() if b in have]
        return order + [b for b in have if b not in order]

    @kslive.consistent
    def landscape(self, block=None, degrees=False):
        names = self.landscapes()
        if not names:
            raise KeyError(f"{self.path} holds no landscapes")
        if block is None:
            block = names[0]
        if block not in names:
            raise KeyError(f"no landscape {block!r}; landscapes: {', '.join(names)}")
        g = self.f["landscapes"][block]
        def axis(a):
            d = g[axis_dataset_name(a)] if axis_dataset_name(a) in g else g[a]  # (older files: g[a])
            unit = _s(d.attrs.get("unit", ""))
            vals = np.array(d[()], dtype=float)
            labels = None
            if unit.startswith("labels:"):
                labels, unit = unit[len("labels:"):].split(","), ""
            elif degrees and unit == "rad":
                vals, unit = vals * RAD2DEG, "deg"
            # a sampled dimension (format 5): its parameters, coordinates along it
            along = [axis(_s(p)) for p in np.atleast_1d(d.attrs.get("parameters", []))]
            return Axis(a, unit, vals, labels, along)

        axes = [axis(_s(x)) for x in g.attrs["axes"]]
        units, desc, shown = {}, {}, {}
        names = [_s(x) for x in g.attrs["metrics"]]
        shape = tuple(len(a.values) for a in axes)
        for m in names:
            if m not in g or g[m].shape != shape:
                raise ValueError(f"{self.path}: /landscapes/{block}/{m} has shape "
                                 f"{g[m].shape if m in g else 'none (absent)'}; its axes make {shape}")
            units[m] = _s(g[m].attrs.get("unit", ""))
            desc[m] = _s(g[m].attrs.get("description", ""))
            shown[m] = display_name(g[m], m)
        metrics = _Grids(names, lambda m: _grid(self.f["landscapes"][block][m]),
                         lambda m: self.f["landscapes"][block][m])
        kind = self._block_kind(block)
        return Landscape(block, axes, metrics, units, desc, kind, self.kind_meaning(kind), shown)

    def _block_kind(self, block):
        """The run kind of a block's (done) rows, "" when it has none: its first done row's (a block's
        runs are of one kind), that row read by index."""
        if "block" not in self._roles:
            return self.run_kinds()[0] if len(self.run_kinds()) == 1 else ""
        d, done = self.f["runs"]["block"], self.f["runs"]["done"]
        labels = enum_labels(d)
        if labels is not None and block not in labels:
            return ""
        step = 1 << 16  # the first done row is looked for a slice at a time (usually in the first)
        for a in range(0, d.shape[0], step):
            codes = d[a:a + step]
            mine = codes == labels.index(block) if labels is not None else text_values(d, codes) == block
            rows = np.flatnonzero(mine & done[a:a + len(codes)].astype(bool))
            if len(rows):
                return self.row_kinds(rows=[a + int(rows[0])])[0]
        return ""


    @kslive.consistent
    def optimizations(self):
        """Names of the /optimizations groups (empty when the file has none)."""
        return list(self.f["optimizations"]) if "optimizations" in self.f else []

    @kslive.consistent
    def optimization(self, name=None, degrees=False):
        """One /optimizations group as an Optimization (default: the first)."""
        names = self.optimizations()
        if not names:
            raise KeyError(f"{self.path} holds no optimizations")
        if name is None:
            name = names[0]
        if name not in names:
            raise KeyError(f"no optimization {name!r}; optimizations: {', '.join(names)}")
        return Optimization(name, self.f["optimizations"][name], degrees=degrees)


def open_results(path):
    return Results(path)


def read_runs(path, **kw):
    with Results(path) as r:
        return r.runs(**kw)


def read_history(path, run_id, **kw):
    with Results(path) as r:
        return r.history(run_id, **kw)


def read_landscape(path, block=None, **kw):
    with Results(path) as r:
        ls = r.landscape(block, **kw)
        ls.metrics = {m: ls.metrics[m] for m in ls.metrics}  # every grid, before the file closes
        return ls


def read_optimization(path, name=None, **kw):
    with Results(path) as r:
        return r.optimization(name, **kw)
