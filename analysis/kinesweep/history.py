"""The /histories layouts of a results file (engine/store/FORMAT.md). The only module that knows them:
kinesweep.read's Results (has_history, history_arrays, history_ids, history) and the test helpers read
histories through Histories. Run with Debian's interpreter: /usr/bin/python3.

format_version 1 and 2: one group per run with a history, /histories/<zero-padded run id>/<array>,
  group attribute `arrays` = the array names in the order the run produced them.
format_version 3 to 5: one row space shared by every history dataset. /histories/start, /rows, /layout
  (int64, indexed by run id): run i's arrays are rows [start[i], start[i] + rows[i]) of the datasets
  named in the group attribute layouts[layout[i]] (comma-separated); layout -1 = no history. A
  dataset's `array` attribute names its array (`q.2` holds an array q of another column count or unit).

    h = Histories(f)                    # f: an open h5py.File
    h.has(3), h.names(3)                # ["t", "q", ...] in the run's order ([] without a history)
    h.read(3)                           # [(array name, rows x cols float64 array, unit), ...]
    h.ids(), h.count()                  # run ids with a history (ascending), their number
    for run_id, arrays in h.items(): ...   # every history, in run-id order
"""
import numpy as np

from kinesweep.kinds import FormatVersionError, _s

GROUP_VERSIONS = (1, 2)  # one group per run
RAGGED_VERSIONS = (3, 4, 5)  # one shared row space
NEWEST_VERSION = 4


def group_name(run_id, n_runs):
    """Zero-padded group name of a run under /histories in the group layout: 6 digits, wider when
    n_runs needs it."""
    width = max(6, len(str(max(int(n_runs) - 1, 0))))
    return str(int(run_id)).zfill(width)


def _as_2d(v):
    v = np.asarray(v, dtype=float)
    return v.reshape(v.shape[0], -1) if v.ndim == 1 else v


class Histories:
    """The histories of one open h5py.File (format_version 1 to 5). Reads nothing until asked."""

    def __init__(self, f):
        self.f = f
        self.version = int(f.attrs.get("format_version", -1))
        if self.version not in GROUP_VERSIONS + RAGGED_VERSIONS:
            raise FormatVersionError(f"{f.filename}: results file format v{self.version}: its /histories layout is "
                                     f"unknown to this reader (it reads v1 to v{NEWEST_VERSION})")
        self.ragged = self.version in RAGGED_VERSIONS
        self.g = f["histories"] if "histories" in f else None
        if self.ragged and self.g is not None and "layout" not in self.g:
            self.g = None  # v3 / v4 without the index datasets: no run has a history
        self._layouts = None   # ragged: list of dataset-name lists, from the `layouts` attribute
        self._datasets = {}    # ragged: dataset name -> (array name, unit)

    # --- the group layout (v1, v2) ---

    def _group(self, run_id):
        """The run's group, or None."""
        if self.g is None or int(run_id) < 0:
            return None
        runs = self.f["runs"]
        n = int(runs.attrs.get("n_runs", len(runs["done"])))
        return self.g.get(group_name(run_id, n))

    @staticmethod
    def _group_names(grp):
        return [_s(x) for x in grp.attrs["arrays"]] if "arrays" in grp.attrs else list(grp)

    def _group_read(self, grp):
        return [(a, _as_2d(grp[a][()]), _s(grp[a].attrs.get("unit", ""))) for a in self._group_names(grp)]

    # --- the ragged layout (v3, v4) ---

    def _index(self, name, run_id):
        """Entry run_id of /histories/start, rows or layout; -1 for a run id outside it."""
        ds = self.g[name]
        i = int(run_id)
        return int(ds[i]) if 0 <= i < ds.shape[0] else -1

    def _layout(self, j):
        if self._layouts is None or j >= len(self._layouts):
            self._layouts = [_s(x).split(",") for x in self.g.attrs["layouts"]]
        if not 0 <= j < len(self._layouts):
            raise ValueError(f"{self.f.filename}: /histories/layout names layout {j}; the file has "
                             f"{len(self._layouts)}")
        return self._layouts[j]

    def _dataset(self, name):
        """(array name, unit) of a history dataset."""
        if name not in self._datasets:
            a = self.g[name].attrs
            self._datasets[name] = (_s(a.get("array", name)), _s(a.get("unit", "")))
        return self._datasets[name]

    def _ragged_read(self, run_id, start, rows, layout):
        out = []
        for name in self._layout(layout):
            ds = self.g[name]
            if ds.ndim == 2 and ds.shape[1] == 0:  # an array of no columns: a fixed (0 x 0) dataset
                array, unit = self._dataset(name)
                out.append((array, np.zeros((rows, 0)), unit))
                continue
            if start < 0 or start + rows > ds.shape[0]:
                raise ValueError(f"{self.f.filename}: run {run_id}'s history rows [{start}, {start + rows}) "
                                 f"are outside /histories/{name} ({ds.shape[0]} rows)")
            v = ds[start:start + rows] if rows else np.zeros((0,) + ds.shape[1:])
            array, unit = self._dataset(name)
            out.append((array, _as_2d(v), unit))
        return out

    # --- both ---

    def has(self, run_id):
        """Whether run run_id has a history (one of 0 rows included)."""
        if self.g is None:
            return False
        if self.ragged:
            return self._index("layout", run_id) >= 0
        return self._group(run_id) is not None

    def names(self, run_id):
        """The run's array names in the order the run produced them ([] when it has no history)."""
        if self.ragged:
            j = self._index("layout", run_id) if self.g is not None else -1
            return [self._dataset(d)[0] for d in self._layout(j)] if j >= 0 else []
        grp = self._group(run_id)
        return self._group_names(grp) if grp is not None else []

    def read(self, run_id):
        """The run's history: [(array name, 2-D float64 array (rows x cols), unit)] in the run's order.
        KeyError when the run has no history."""
        if not self.has(run_id):
            raise KeyError(f"run {run_id} has no history in {self.f.filename}")
        if self.ragged:
            return self._ragged_read(int(run_id), self._index("start", run_id), self._index("rows", run_id),
                                     self._index("layout", run_id))
        return self._group_read(self._group(run_id))

    def ids(self):
        """The run ids that have a history, ascending (int64 array)."""
        if self.g is None:
            return np.zeros(0, dtype=np.int64)
        if self.ragged:
            return np.flatnonzero(self.g["layout"][()] >= 0).astype(np.int64)
        return np.array(sorted(int(k) for k in self.g), dtype=np.int64)

    def count(self):
        """The number of runs that have a history."""
        if self.g is None:
            return 0
        if self.ragged:
            return int(np.count_nonzero(self.g["layout"][()] >= 0))
        return len(self.g)

    def items(self):
        """(run id, read(run id)) for every run with a history, in run-id order."""
        if self.g is None:
            return
        if not self.ragged:
            for key in sorted(self.g, key=int):
                yield int(key), self._group_read(self.g[key])
            return
        start, rows, layout = (self.g[k][()] for k in ("start", "rows", "layout"))
        for i in np.flatnonzero(layout >= 0):
            yield int(i), self._ragged_read(int(i), int(start[i]), int(rows[i]), int(layout[i]))
