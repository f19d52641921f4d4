"""The IK basins figure's pass over a block's runs (kinesweep.report_basins), a block of grid cells and
their /runs rows at a time: each run's solution (/runs' solution index as the landscape grids it, or
the greedy clusters of kinesweep.solutions.cluster_solutions, built as the runs come), counted per
frame of the figure and overall, the drawn cells' solutions and statuses, and per solution an evenly
spaced sample of its final iterates (all of them up to MEDIAN_SAMPLE runs) for the joint values
that name it. Memory: a block of cells and its rows, the drawn cells and the samples, whatever the
run count; no final-iterate column is read whole. Run with /usr/bin/python3."""
import numpy as np

from kinesweep.chunks import one_value
from kinesweep.grid_blocks import blocks, flat_start, frame_parts, grid_source, read_block, take_drawn
from kinesweep.kinds import enum_labels, text_values
from kinesweep.solutions import cluster_solutions

SCAN_ROWS = 1 << 20      # rows of a text column read at a time when a block's rows are looked for
MEDIAN_SAMPLE = 20000    # final iterates kept per solution for its median joint values (every t-th beyond)


class Rows:
    """A block's rows of /runs in run-id order: a range (start, stop) when they are consecutive (the
    usual case), else an index array."""

    def __init__(self, start=0, stop=0, index=None):
        self.start, self.stop, self.index = start, stop, index

    def __len__(self):
        return len(self.index) if self.index is not None else self.stop - self.start

    def read(self, d, a, b):
        """The dataset d at the rows a..b-1 of the block."""
        if self.index is None:
            return d[self.start + a:self.start + b]
        idx = self.index[a:b]
        if not len(idx):
            return d[0:0]
        return d[int(idx[0]):int(idx[-1]) + 1][idx - idx[0]]


def block_rows(g, block):
    """The rows of `block` in /runs (group g), from its block column read a slice at a time."""
    n = g["done"].shape[0]
    if "block" not in g:
        return Rows(0, n)
    d = g["block"]
    labels = enum_labels(d)
    if labels is not None:
        if block not in labels:
            return Rows()
        code = labels.index(block)
        if n and one_value(d):
            return Rows(0, n) if int(d[0]) == code else Rows()

        def mine(v):
            return v == code
    else:
        def mine(v):
            return text_values(d, v) == block
    first, last, count = None, None, 0
    for a in range(0, n, SCAN_ROWS):
        idx = np.flatnonzero(mine(d[a:a + SCAN_ROWS]))
        if idx.size:
            first = a + int(idx[0]) if first is None else first
            last, count = a + int(idx[-1]), count + idx.size
    if not count:
        return Rows()
    if last - first + 1 == count:
        return Rows(first, last + 1)
    return Rows(index=np.concatenate([a + np.flatnonzero(mine(d[a:a + SCAN_ROWS])) for a in range(0, n, SCAN_ROWS)]))


def one_of(d, values):
    """A function of stored values of the text column d: which hold one of `values` (enum codes
    compared through a table, strings decoded)."""
    labels = enum_labels(d)
    if labels is None:
        return lambda v: np.isin(text_values(d, v), list(values))
    wanted = np.zeros(256 ** d.dtype.itemsize, dtype=bool)
    wanted[[i for i, x in enumerate(labels) if x in values]] = True
    return lambda v: wanted[v]


def any_row(g, column, rows, values):
    """Whether one of the block's rows holds one of `values` in the text column (read until one does)."""
    if column not in g or not len(rows):
        return False
    d = g[column]
    test = one_of(d, values)
    if one_value(d):
        return bool(test(rows.read(d, 0, 1)).any())
    return any(test(rows.read(d, a, a + SCAN_ROWS)).any() for a in range(0, len(rows), SCAN_ROWS))


class StreamClusters:
    """kinesweep.solutions.cluster_solutions over rows that come a piece at a time: a row joins the
    first cluster (lowest label) whose first member is within `tolerance` in the max-norm (revolute
    components mod 2 pi), else opens the next one; the same labels as one call on all the rows.
    limit: stop (over = True) once there are more clusters than that."""

    def __init__(self, revolute, tolerance, limit=None):
        self.rev = np.asarray(revolute, dtype=bool)
        self.tol, self.limit, self.over = tolerance, limit, False
        self.reps = np.zeros((0, len(self.rev)))

    def label(self, q):
        labels = np.full(len(q), -1, dtype=np.int64)
        rest = np.flatnonzero(np.all(np.isfinite(q), axis=1))
        for r, rep in enumerate(self.reps):  # the clusters opened by earlier pieces first
            if not rest.size:
                break
            d = q[rest] - rep
            d[:, self.rev] = np.remainder(d[:, self.rev] + np.pi, 2 * np.pi) - np.pi
            near = np.max(np.abs(d), axis=1) <= self.tol if d.shape[1] else np.ones(len(d), dtype=bool)
            labels[rest[near]] = r
            rest = rest[~near]
        if rest.size:  # the rest among themselves, after every earlier cluster
            new = cluster_solutions(q[rest], self.rev, self.tol)
            labels[rest] = new + len(self.reps)
            self.reps = np.concatenate([self.reps, q[rest[np.unique(new, return_index=True)[1]]]])
        if self.limit is not None and len(self.reps) > self.limit:
            self.over = True
        return labels


class Medians:
    """Per label, every t-th of its rows in order (t = 1 while it has at most MEDIAN_SAMPLE, then
    doubled as needed), for the median of each column: all rows' medians up to that many rows."""

    def __init__(self, limit=MEDIAN_SAMPLE):
        self.limit, self.buf, self.seen, self.step = limit, {}, {}, {}

    def add(self, labels, q):
        ok = labels >= 0
        if not ok.any():
            return
        lab, q = labels[ok], q[ok]
        order = np.argsort(lab, kind="stable")
        lab, q = lab[order], q[order]
        present, start = np.unique(lab, return_index=True)
        for l, a, b in zip(present.tolist(), start.tolist(), start[1:].tolist() + [len(lab)]):
            seen, t = self.seen.get(l, 0), self.step.get(l, 1)
            keep = q[a:b][(seen + np.arange(b - a)) % t == 0]
            buf = np.concatenate([self.buf[l], keep]) if l in self.buf else keep
            while len(buf) > self.limit:
                buf, t = buf[::2], t * 2
            self.buf[l], self.seen[l], self.step[l] = buf, seen + b - a, t

    def median(self, label):
        return np.median(self.buf[label], axis=0)


class Source:
    """What a pass reads: the block's rows and landscape, the final-iterate columns and which
    rows converged (done, of a good status)."""

    def __init__(self, res, ls, rows, qcols):
        self.g, self.ls, self.rows, self.qcols = res.f["runs"], ls, rows, qcols
        self.status = grid_source(ls, "status_code")
        self.shape = self.status.shape
        self.good = one_of(self.g["status"], res.kind_meaning("ik")["good_statuses"])

    def pieces(self, joints):
        """Per block of cells: (lo, hi, status block, final iterates of its runs (NaN where the run did
        not converge), flat start)."""
        for lo, hi in blocks(self.shape):
            st = read_block(self.status, lo, hi)
            a = flat_start(lo, self.shape)
            b = a + st.size
            conv = self.rows.read(self.g["done"], a, b).astype(bool) & self.good(self.rows.read(self.g["status"], a, b))
            q = np.empty((b - a, len(joints)))
            for k, j in enumerate(joints):
                q[:, k] = self.rows.read(self.g[self.qcols[j]], a, b)
            q[~conv] = np.nan
            yield lo, hi, st, q


def joint_clusters(src, revolute, tolerance, limit):
    """The joints whose final values over the converged runs take at most `limit` distinct values
    (clusters within tolerance), each clustered alone (a pass over the runs)."""
    joints = list(range(len(src.qcols)))
    cl = [StreamClusters([revolute[j]], tolerance, limit) for j in joints]
    for _, _, _, q in src.pieces(joints):
        for j in joints:
            if not cl[j].over:
                cl[j].label(q[:, [j]])
    return [j for j in joints if not cl[j].over]


def scan(src, sel, s, shape, joints, labeler):
    """One pass over the runs: labeler(lo, hi, q) gives each run's solution (-1: none). Returns the
    counts per label, per frame the drawn labels and statuses and the counts of the labels (of the
    cells without a failed status), the failed codes and the converged runs without a solution, the
    failed codes present, whether a converged run has none, and the median samples."""
    nf = len(sel.frames)
    out = {"counts": np.zeros(0, dtype=np.int64), "labels": [np.full(shape, -1, dtype=np.int64) for _ in range(nf)],
           "status": [np.full(shape, np.nan) for _ in range(nf)],
           "frame_labels": [np.zeros(0, dtype=np.int64) for _ in range(nf)],
           "frame_status": [np.zeros(0, dtype=np.int64) for _ in range(nf)], "frame_unnamed": [0] * nf,
           "failed": set(), "unnamed": False, "medians": Medians()}
    for lo, hi, st, q in src.pieces(joints):
        lab = labeler(lo, hi, q)
        out["counts"] = _add(out["counts"], lab[lab >= 0])
        out["medians"].add(lab, q)
        failed = np.isfinite(st) & (st != 0)
        out["failed"].update(np.unique(st[failed]).astype(int).tolist())
        lab = lab.reshape(st.shape)
        unnamed = (st == 0) & (lab < 0)
        out["unnamed"] |= bool(unnamed.any())
        for (k, sp, y0, x0), (_, lp, _, _) in zip(frame_parts(sel, lo, hi, st), frame_parts(sel, lo, hi, lab)):
            fp = np.isfinite(sp) & (sp != 0)
            out["frame_labels"][k] = _add(out["frame_labels"][k], lp[~fp & (lp >= 0)])
            out["frame_status"][k] = _add(out["frame_status"][k], sp[fp].astype(np.int64))
            out["frame_unnamed"][k] += int(np.count_nonzero((sp == 0) & (lp < 0)))
            for target, part in ((out["status"], sp), (out["labels"], lp)):
                cells, r, c = take_drawn(part, y0, x0, s)
                target[k][r, c] = cells
    return out


def _add(counts, values):
    """counts (a bincount) plus the bincount of `values` (small non-negative integers)."""
    n = np.bincount(values, minlength=len(counts))
    n[:len(counts)] += counts
    return n
