"""The tables of kinesweep.report: the file's metadata and run counts, status counts per block, and
the best runs of each block (parameters and metrics, units in the headers, angles in degrees).
Run with /usr/bin/python3."""
import numpy as np

from kinesweep.chunks import one_value
from kinesweep.kinds import enum_labels, text_values
from kinesweep.read import RAD2DEG
from kinesweep.report_page import esc, fmt, table


POINT_READ_ROWS = 4096  # up to this many rows are read by index; more, as whole columns
SCAN_ROWS = 1 << 16     # rows of the file per slice when a column is scanned (RunsView.chunks)


class RunsView:
    """The /runs rows the report reads, a column at a time: the done flags and the block and status
    codes (a byte or two per row) are held; every other column is read when asked, for the rows
    asked (by index for a few rows, else the whole column), so the report's memory is a few columns
    whatever the row count. Angles in degrees; a row's run id is its index."""

    def __init__(self, res):
        self.res = res
        self.g = res.f["runs"]
        self.done = self.g["done"][()].astype(bool)
        self.n = len(self.done)
        self.units = {c: ("deg" if u == "rad" else u) for c, u in res.units().items()}
        self.block_codes, self.block_labels = self._codes("block")
        self.status_codes, self.status_labels = self._codes("status")
        if self.n and "block" in self.g and one_value(self.g["block"]):  # one code in every row: not sorted
            self.block_names = [self.block_labels[int(self.block_codes[0])]]
        else:
            order = np.unique(self.block_codes, return_index=True)
            self.block_names = [self.block_labels[c] for c in order[0][np.argsort(order[1])]]

    def _codes(self, c):
        """A text column as (codes per row, labels by code): its enum codes (format 4, the missing value
        as the label ""), or codes of its distinct strings (format 3); ([0] * n, [""]) without it."""
        if c not in self.g:
            return np.zeros(self.n, dtype=np.int64), [""]
        d = self.g[c]
        labels = enum_labels(d)
        if labels is not None:
            return d[()], labels + [""] * (256 ** d.dtype.itemsize - len(labels))
        names, codes = np.unique(text_values(d), return_inverse=True)
        return codes.astype(np.int64), [str(x) for x in names]

    def is_text(self, c):
        d = self.g[c]
        return enum_labels(d) is not None or d.dtype.kind in "OSU"

    def values(self, c, rows):
        """Column c at `rows` (an index array): floats in degrees where stored in radians, text as str."""
        d = self.g[c]
        rows = np.asarray(rows, dtype=np.int64)
        if len(rows) == 0:
            v = d[0:0]
        elif len(rows) <= POINT_READ_ROWS:
            uniq, inverse = np.unique(rows, return_inverse=True)
            v = d[uniq][inverse]
        elif rows[-1] - rows[0] + 1 == len(rows) and np.all(np.diff(rows) == 1):
            v = d[int(rows[0]):int(rows[-1]) + 1]
        else:
            v = d[()][rows]
        if enum_labels(d) is not None or v.dtype.kind in "OSU":
            return text_values(d, v)
        if self.units.get(c) == "deg" and v.dtype.kind == "f":
            v = v * RAD2DEG
        return v

    def chunks(self, c, rows, size=SCAN_ROWS):
        """Column c at ascending `rows` (or a BlockRows), as values() gives them, a piece at a time:
        each piece the rows within `size` consecutive rows of the file, read as one slice (memory: one
        slice)."""
        d = self.g[c]
        text = enum_labels(d) is not None or d.dtype.kind in "OSU"
        deg = self.units.get(c) == "deg"
        if isinstance(rows, BlockRows):
            for a, idx in rows.slices(size):
                if len(idx):
                    yield self._convert(d, d[a + int(idx[0]):a + int(idx[-1]) + 1][idx - idx[0]], text, deg)
            return
        rows = np.asarray(rows, dtype=np.int64)
        lo = 0
        while lo < len(rows):
            start = int(rows[lo])
            hi = int(np.searchsorted(rows, start + size))
            yield self._convert(d, d[start:int(rows[hi - 1]) + 1][rows[lo:hi] - start], text, deg)
            lo = hi

    @staticmethod
    def _convert(d, v, text, deg):
        if text:
            return text_values(d, v)
        return v * RAD2DEG if deg and v.dtype.kind == "f" else v

    def column(self, c, rows):
        """Column c at ascending `rows` read a slice at a time (chunks), as one array."""
        parts = list(self.chunks(c, rows))
        return np.concatenate(parts) if parts else self.values(c, rows)

    def status_counts(self):
        """(runs per block code, done runs per block code and status code): counted a slice of the
        file at a time (no index of every row)."""
        if getattr(self, "_status_counts", None) is None:
            nb, ns = len(self.block_labels), len(self.status_labels)
            every, done = np.zeros(nb, dtype=np.int64), np.zeros(nb * ns, dtype=np.int64)
            for a in range(0, self.n, SCAN_ROWS):
                b = self.block_codes[a:a + SCAN_ROWS].astype(np.int64)
                every += np.bincount(b, minlength=nb)
                d = self.done[a:a + SCAN_ROWS]
                done += np.bincount(b[d] * ns + self.status_codes[a:a + SCAN_ROWS][d], minlength=nb * ns)
            self._status_counts = every, done.reshape(nb, ns)
        return self._status_counts

    def value(self, c, row):
        return self.values(c, [row])[0]

    def status(self, rows):
        return np.asarray(self.status_labels, dtype=object)[self.status_codes[rows]]

    def rows(self, block, done=True):
        code = self.block_labels.index(block)
        m = self.block_codes == code
        return np.flatnonzero(m & self.done) if done else np.flatnonzero(m)

    def row_kind(self, row):
        return self.res.row_kinds(rows=[int(row)])[0]

    def kind(self, block):
        """The run kind of the block's runs (of its first done row; a block's runs are of one kind)."""
        first = BlockRows(self, block, count=False).first
        k = self.row_kind(first) if first is not None else ""
        if k:
            return k
        k = self.res.run_kinds()
        return k[0] if len(k) == 1 else ""

    def ranked(self, block, limit=None):
        """The block's done rows of good status, best first by the kind's ranking (the file's /kinds:
        trajectory by E, IK by iterations then error); ties by run id. Returns (row indices, the
        ranking metric names, how many rows the whole ranking has). limit: the first `limit` rows of
        it only (sorted among the rows whose first key is at most the limit-th smallest: the same
        rows, without sorting them all; found a slice of the file at a time, keeping those rows)."""
        meaning = self.res.kind_meaning(self.kind(block))
        keys = [k for k in meaning.get("ranking", []) if k in self.g]
        good = [i for i, s in enumerate(self.status_labels) if s in meaning.get("good_statuses", [])]

        def key(k, rows):
            return np.nan_to_num(np.asarray(self.column(k, rows), dtype=float), nan=np.inf)

        if limit is None or not keys:
            rows = self.rows(block)
            rows = rows[np.isin(self.status_codes[rows], good)]
            total = len(rows)
            first = key(keys[0], rows) if keys else None
            cols = [rows] + [key(k, rows) for k in reversed(keys[1:])] + ([first] if keys else [])
            return rows[np.lexsort(cols)][:limit], keys, total
        # the best `limit` by the whole ranking, kept from slice to slice (it is a total order)
        m, best, total = max(limit, 1), None, 0
        for a, idx in BlockRows(self, block, count=False).slices():
            idx = a + idx[np.isin(self.status_codes[a + idx], good)]
            total += len(idx)
            if not len(idx):
                continue
            f = key(keys[0], idx)
            if best is not None and len(best[0]) >= m:  # none past the kept rows' largest first key enters
                keep = f <= best[-1].max()
                idx, f = idx[keep], f[keep]
                if not len(idx):
                    continue
            cols = [idx] + [key(k, idx) for k in reversed(keys[1:])] + [f]
            if best is not None:
                cols = [np.concatenate([b, c]) for b, c in zip(best, cols)]
            best = [c[np.lexsort(cols)[:m]] for c in cols]
        return (best[0] if best else np.zeros(0, dtype=np.int64))[:limit], keys, total


class BlockRows:
    """A block's rows (its done ones, or all), found a slice of the file at a time: len(), rows[0] and
    rows[:k], and RunsView.chunks over them, without an index of every row."""

    def __init__(self, view, block, done=True, count=True):
        self.view, self.code, self.done = view, view.block_labels.index(block), done
        self.n, self.first = 0, None
        for a, idx in self.slices():
            if self.first is None and len(idx):
                self.first = a + int(idx[0])
                if not count:
                    break
            self.n += len(idx)

    def slices(self, size=SCAN_ROWS):
        v = self.view
        for a in range(0, v.n, size):
            m = v.block_codes[a:a + size] == self.code
            if self.done:
                m &= v.done[a:a + size]
            yield a, np.flatnonzero(m)

    def __len__(self):
        return self.n

    def __getitem__(self, k):
        if k == 0 and self.first is not None:
            return self.first
        if isinstance(k, slice) and k.start in (None, 0) and k.step in (None, 1) and k.stop is not None:
            out = []
            for a, idx in self.slices():
                out += (a + idx[:k.stop - len(out)]).tolist()
                if len(out) >= k.stop:
                    break
            return np.array(out, dtype=np.int64)
        raise IndexError(k)


def metadata_section(res, view):
    m = res.meta
    n = len(view.done)
    done = int(view.done.sum())
    n_hist = res.history_count()
    items = [("study_name", m.get("study_name", "")), ("study file", res.f["study"].attrs.get("path", "")),
             ("engine_version", m.get("engine_version", "")), ("created", m.get("created", "")),
             ("format_version", m.get("format_version", "")), ("study_sha256", m.get("study_sha256", "")),
             ("runs", n), ("done", done), ("not done", n - done), ("blocks", len(view.block_names)),
             ("histories", n_hist), ("landscapes", len(res.landscapes())),
             ("optimizations", len(res.optimizations()))]
    items = [(k, v.decode() if isinstance(v, bytes) else v) for k, v in items]
    rows = "".join(f'<tr><th class="s">{esc(k)}</th><td class="s" data-key="{esc(k)}">{esc(fmt(v))}</td></tr>'
                   for k, v in items)
    note = ("" if done == n else f'<p class="caption capped">{n - done} of {n} runs are not done yet (a sweep still '
            "writing, or one that stopped): the report shows the done rows only.</p>")
    return (f'<div class="scroll"><table id="meta-table"><tbody>{rows}</tbody></table></div>{note}'
            f'<h3>Study file</h3><pre class="study" id="study-text">{esc(res.study_text)}</pre>')


def status_section(view):
    """Runs per block and status (done rows), plus the rows not done yet."""
    statuses = []
    for kind in view.res.run_kinds():
        statuses += [s for s in view.res.kind_meaning(kind).get("statuses", []) if s not in statuses]
    present = {view.status_labels[c] for c in np.flatnonzero(view.status_counts()[1].sum(axis=0))}
    extra = sorted(s for s in present if s not in statuses and s)
    shown = [s for s in statuses if s in present] + extra
    columns = [("block", ""), ("kind", ""), ("runs", ""), ("done", "")] + [(s, "") for s in shown] + [("not done", "")]
    rows = []
    every, done = view.status_counts()
    for b in view.block_names:
        code = view.block_labels.index(b)
        count = done[code]
        by_name = {}
        for c, k in enumerate(count):
            by_name[view.status_labels[c]] = by_name.get(view.status_labels[c], 0) + int(k)
        n_all, n_done = int(every[code]), int(count.sum())
        rows.append([b, view.kind(b), n_all, n_done] + [by_name.get(s, 0) for s in shown] + [n_all - n_done])
    good = " and ".join(f"{'/'.join(view.res.kind_meaning(k).get('good_statuses', []))} ({k})"
                        for k in view.res.run_kinds())
    good = f"{good} are the successful statuses." if good else ""
    return table(columns, rows, "status-table", text_columns=("block", "kind")) + \
        f'<p class="caption">Runs per block and status, counted over the done rows. {good}</p>'


def held(v):
    """Which values of a column are values: not NaN, -1 (integers) or "" (the missing values of a
    column a block does not have, e.g. global_spline's in a block of local runs)."""
    return np.isfinite(v) if v.dtype.kind == "f" else (v != -1) if v.dtype.kind in "iu" else (v != "")


def varying_parameters(view, block, rows):
    """The block's parameters (of its kind) that take more than one value over its done rows, and the
    fixed ones; parameters without a value in any of the rows are neither. (Floats compare rounded to
    12 decimals; NaN is no value.) Read a slice at a time; a parameter stops being read at the first
    slice that shows two values."""
    kind = view.kind(block)
    varying, fixed = [], []
    for c in view.res.parameters(kind or None):
        if _varies(view, c, rows):
            varying.append(c)
        elif _held(view, c, rows):
            fixed.append(c)
    return varying, fixed


def _varies(view, c, rows):
    if one_value(view.g[c]):  # one value in every row of the file: in these rows too
        return False
    first = lo = hi = None
    for v in view.chunks(c, rows):
        if v.dtype.kind == "f":
            f = np.round(v[np.isfinite(v)], 12)
            if f.size:
                lo = f.min() if lo is None else min(lo, f.min())
                hi = f.max() if hi is None else max(hi, f.max())
                if lo != hi:
                    return True
        elif len(v):
            first = v[0] if first is None else first
            if not np.all(v == first):
                return True
    return False


def _held(view, c, rows):
    """Whether the column holds a value in one of `rows` (or `rows` is empty), read until it does."""
    if not len(rows):
        return True
    if one_value(view.g[c]):  # one value in every row: held or not in all of them
        return bool(held(np.asarray(view.values(c, rows[:1]))).any())
    return any(held(v).any() for v in view.chunks(c, rows))


def shown_metrics(view, block, rows):
    """The metrics of the block's kind that hold a value in one of `rows` at least (each read until
    it does)."""
    kind = view.kind(block)
    return [c for c in view.res.metrics(kind or None) if len(rows) and _held(view, c, rows)]


def best_section(view, n_best):
    parts = []
    for b in view.block_names:
        top, keys, n_ranked = view.ranked(b, limit=n_best)
        rows_done = BlockRows(view, b)
        if not len(rows_done):
            continue
        kind = view.kind(b)
        good = "/".join(view.res.kind_meaning(kind).get("good_statuses", []))
        varying, fixed = varying_parameters(view, b, rows_done)
        metrics = shown_metrics(view, b, rows_done)
        columns = [("rank", ""), ("run_id", ""), ("status", "")] + [(c, view.units[c]) for c in varying] + \
                  [(c, view.units[c]) for c in metrics]
        cells = {c: view.values(c, top) for c in varying + metrics}
        status = view.status(top)
        rows = [[i + 1, int(r), status[i]] + [cells[c][i] for c in varying] + [cells[c][i] for c in metrics]
                for i, r in enumerate(top)]
        first = rows_done[0]
        fixed_values = [(c, fmt(view.value(c, first))) for c in fixed]
        fixed_text = ", ".join(f"{c} = {v}{(' ' + view.units[c]) if view.units[c] not in ('', '1') else ''}"
                               for c, v in fixed_values if v not in ("", "–"))
        order = " then ".join(keys) if keys else "run id"
        cap = (f"The {len(top)} best of the block's {n_ranked} {good} runs ({len(rows_done)} done), "
               f"smallest {order} first. " if len(top) else f"No {good} run among the block's {len(rows_done)} "
               "done runs. ")
        if fixed_text:
            cap += f"Fixed in this block: {esc(fixed_text)}."
        parts.append(f'<h3>Block {esc(b)} ({esc(kind)})</h3>'
                     + (table(columns, rows, f"best-{b}", text_columns=("status",) + tuple(
                         c for c in varying if view.is_text(c))) if len(top) else "")
                     + f'<p class="caption">{cap}</p>')
    return "".join(parts)


def verdicts_section(res):
    """`kinesweep compare`'s verdict table (kinesweep.compare.compare: the best good run per method,
    per end condition and metric, its GCI and its margin to the next method) for the files whose
    best runs were verified against their grid (a /verification group); "" otherwise."""
    from kinesweep.compare import compare
    if "verification" not in res.f:
        return ""
    metrics = [m for m in ("E", "torque_sq_integral") if m in res.columns()]
    try:
        rows = compare(res, metrics=metrics or None)
    except KeyError:
        return ""
    if not rows:
        return ""
    keys = ["kind", "end", "metric", "unit", "rank", "method", "run", "value", "grid", "gci", "uncertainty",
            "next", "margin", "margin_uncertainty", "verdict"]
    keys = [k for k in keys if k in rows[0]]
    columns = [(k, "%" if k == "gci" else "") for k in keys]
    body = [[r[k] if r[k] is not None else float("nan") for k in keys] for r in rows]
    text = ("kind", "end", "metric", "unit", "method", "grid", "next", "verdict")
    return table(columns, body, "verdict-table", text_columns=text) + (
        '<p class="caption">Like for like (<code>kinesweep compare</code>): per end condition (at rest, free) and '
        "metric, the best run of a good status of each method; grid: how its value behaves at dt/2, dt/4 (and 2K, "
        "4K knots); gci: Roache's grid convergence index of the value; margin: to the next method, with the sum of "
        "both uncertainties (GCI x value). A verdict holds over these runs, this end condition and this metric "
        "only.</p>")
