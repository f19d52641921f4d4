"""The grid plot_landscape draws: which axes go on x and y, which dims are fixed, faceted or reduced
(min or mean), and the grids read a band of cells at a time and reduced to what the picture can
show: a grid with more cells along an axis than the picture has pixels is drawn in blocks of s x s
cells, each drawn cell the minimum (the mean with --reduce mean, and for the convergence fraction)
of its block's values and, where none has a value, the most common failed status of its runs. The
minimum marked, the colour scale's range, the mean convergence fraction and the failed-cell counts
come from the full grid. Memory: a band of cells and the drawn ones (and with --print-data the full
grid, which it prints). Run with /usr/bin/python3."""
import sys
import warnings

import numpy as np

from kinesweep import plotting as ksplot
from kinesweep import read as ksread
from kinesweep.grid_blocks import as_grid, grid_source

MAX_PANELS = 6  # small multiples: at most this many panels, one per value of a categorical dim
BAND_CELLS = 1 << 20  # cells read at a time (a grid of at most this many per panel: in one piece)


def pick_index(axis, value):
    if axis.categorical:
        if value not in axis.labels:
            raise SystemExit(f"--fix {axis.name}={value}: not a value of the axis; values: {', '.join(axis.labels)}")
        return axis.labels.index(value)
    try:
        v = float(value)
    except ValueError:
        raise SystemExit(f"--fix {axis.name}={value}: expected a number")
    i = int(np.argmin(np.abs(axis.values - v)))
    span = np.ptp(axis.values) if len(axis.values) > 1 else 1.0
    if abs(axis.values[i] - v) > 1e-6 * max(span, 1.0) + 1e-9:
        vals = ", ".join(ksplot.fmt_num(x) for x in axis.values[:12])
        raise SystemExit(f"--fix {axis.name}={value}: not on the grid; values: {vals}{' ...' if len(axis.values) > 12 else ''}")
    return i


def usage_exit(msg):
    """A choice the user has to make: the message on stderr, exit status 2 (as argparse's usage errors)."""
    print(f"plot_landscape: {msg}", file=sys.stderr)
    raise SystemExit(2)


def numeric_axes(ls):
    """The axes a grid can be drawn over: numeric, swept, monotonic (not a design's sampled points)."""
    return [a.name for a in ls.axes if not a.categorical and len(a.values) > 1 and not a.sampled]


def plan(ls, args):
    """What reduce_grid draws: the metric, the x and y axes, the fixed dims (their indices), the
    facet (a categorical dim drawn one panel per value, or None), the dims reduced, notes for the title."""
    names = [a.name for a in ls.axes]
    metric = args.metric or ("convergence" if ls.kind == "ik" else ls.objective)
    if metric != "convergence" and metric not in ls.metrics:
        raise SystemExit(f"--metric {metric}: not in landscape {ls.block}; metrics: "
                         f"{', '.join(list(ls.metrics) + (['convergence'] if ls.kind == 'ik' else []))}")
    fixed = {}
    for f in args.fix:
        if "=" not in f:
            raise SystemExit(f"--fix {f}: expected AXIS=VALUE")
        k, v = f.split("=", 1)
        if k not in names:
            raise SystemExit(f"--fix {k}: no such axis; axes: {', '.join(names)}")
        fixed[k] = v
    free = [n for n in numeric_axes(ls) if n not in fixed]
    x = args.x or (free[0] if free else None)
    y = args.y or next((n for n in free if n != x), None)
    for n, opt in ((x, "--x"), (y, "--y")):
        if n is None:
            raise SystemExit(f"{opt}: the landscape has no second swept axis to plot; axes: {', '.join(names)}")
        if n not in names:
            raise SystemExit(f"{opt} {n}: no such axis; axes: {', '.join(names)}")
    if x == y or x in fixed or y in fixed:
        raise SystemExit("--x and --y must be two different axes, neither of them fixed")
    index = [slice(None)] * len(names)
    notes = []
    for k, v in fixed.items():
        a = ls.axis(k)
        index[names.index(k)] = pick_index(a, v)
        notes.append(f"{k} = {v}" + (f" {a.unit}" if a.unit and not a.categorical else ""))
    rest = [n for n in names if n not in (x, y) and n not in fixed]
    multi = [n for n in rest if len(ls.axis(n).values) > 1]
    facet = None
    if metric != "convergence" and multi and args.reduce is None:
        a = ls.axis(multi[0])
        if len(multi) == 1 and a.categorical and len(a.labels) <= MAX_PANELS:
            facet = multi[0]
        else:
            dims = ", ".join(f"{n} ({len(ls.axis(n).values)} values)" for n in multi)
            usage_exit(f"landscape {ls.block}: the dims {dims} are neither plotted nor fixed; choose for each: "
                       f"--fix AXIS=VALUE (e.g. --fix {multi[0]}={_first_value(ls.axis(multi[0]))}), or "
                       f"--reduce min|mean over them" + ("" if len(multi) == 1 else
                                                          ", or --fix all but one categorical dim (one panel per value)"))
    rest = [n for n in rest if n != facet]

    reduce = "mean" if metric == "convergence" and multi else (
        args.reduce if [n for n in rest if len(ls.axis(n).values) > 1] else None)
    if reduce:
        notes.append(f"{reduce} over {', '.join(n for n in rest if len(ls.axis(n).values) > 1)}")
    return {"metric": metric, "x": x, "y": y, "index": index, "fixed": fixed, "facet": facet, "rest": rest,
            "notes": notes, "reduce": reduce}


def reduce_grid(ls, args, pixels, keep_full=False):
    """The metric over (y, x) per panel as drawn in a picture `pixels` across (kinesweep.plotting's
    smaller side): dict with the sorted x/y axes, z (panels x drawn rows x drawn columns), cat (the
    same shape: -1 value, -2 no run, else the status index of the cell's failed runs), block (sy, sx:
    the cells per drawn cell), the drawn cells' edges and centres, per panel the minimum (value, i,
    j) of the full grid, its mean (convergence), the counts of its failed categories and whether a
    cell has no run, the range of the values (vmin, vmax, the smallest positive), facet, notes;
    with keep_full the full grids too (full_z, full_cat: panels x ny x nx)."""
    p = plan(ls, args)
    names = [a.name for a in ls.axes]
    metric, x, y, facet, rest, fixed = p["metric"], p["x"], p["y"], p["facet"], p["rest"], p["fixed"]
    xa, ya = ls.axis(x), ls.axis(y)
    order = {}  # axes in increasing order (random axes are stored in draw order)
    for a, key in ((xa, "x"), (ya, "y")):
        if not a.categorical and np.any(np.diff(a.values) < 0):
            order[key] = np.argsort(a.values, kind="stable")
    xa, ya = (ksread.Axis(a.name, a.unit, a.values[order[k]]) if k in order else a for a, k in ((xa, "x"), (ya, "y")))
    nx, ny = len(xa.values), len(ya.values)
    s = draw_stride(nx, ny, pixels)
    sx, sy = (1 if xa.categorical else s), (1 if ya.categorical else s)
    n_panels = len(ls.axis(facet).values) if facet else 1
    kept = [n for n in names if n not in fixed and n != facet]  # the dims of a panel's piece, stored order
    # Bands along x or y, whichever is stored first (a contiguous read), not one that needs sorting
    band = min((d for d in (x, y) if ("x" if d == x else "y") not in order), key=names.index, default=None)
    other = (ny if band == x else nx) * max(1, int(np.prod([len(ls.axis(n).values) for n in rest])))
    if band is None or nx * ny * other // (ny if band == x else nx) <= BAND_CELLS:
        band, step = (band or x), (nx if (band or x) == x else ny)
    else:
        sb = sx if band == x else sy
        step = max(sb, (BAND_CELLS // max(1, other)) // sb * sb)
    n_band = nx if band == x else ny
    perm = [kept.index(band), kept.index(y if band == x else x)] + [kept.index(n) for n in rest]
    mean = metric == "convergence" or args.reduce == "mean"
    sources = {"value": grid_source(ls, ls.statuses[0] if metric == "convergence" else metric)}
    if metric != "convergence":
        sources["status"] = grid_source(ls, "status_code")
    by, bx = -(-ny // sy), -(-nx // sx)
    out = {"z": np.full((n_panels, by, bx), np.nan), "cat": np.full((n_panels, by, bx), -1, dtype=np.int8),
           "best": [None] * n_panels, "sum": [0.0] * n_panels, "count": [0] * n_panels,
           "counts": [np.zeros(0, dtype=np.int64) for _ in range(n_panels)], "no_run": [False] * n_panels,
           "finite": False, "vmin": None, "vmax": None, "pos": None}
    if keep_full:
        out["full_z"] = np.full((n_panels, ny, nx), np.nan)
        out["full_cat"] = np.full((n_panels, ny, nx), -1, dtype=np.int8)
    for pnl in range(n_panels):
        for b0 in range(0, n_band, step):
            b1 = min(b0 + step, n_band)
            pieces = {}
            for k, src in sources.items():
                key = list(p["index"])
                if facet:
                    key[names.index(facet)] = pnl
                key[names.index(band)] = slice(b0, b1)
                g = src[tuple(key)]
                g = _codes(g) if k == "status" else as_grid(g, src.dtype)
                g = np.transpose(g, perm)  # the band's axis, the other one, the cells reduced (a view)
                g = g.reshape(g.shape[:2] + (-1,))
                for key_, axis in (("x", 0), ("y", 1)) if band == x else (("y", 0), ("x", 1)):
                    if key_ in order:
                        g = np.take(g, order[key_], axis=axis)
                pieces[k] = g
            pieces["fresh"] = not isinstance(sources["value"], np.ndarray) and "x" not in order and "y" not in order
            y0, x0 = (0, b0) if band == x else (b0, 0)
            _band(out, pnl, pieces, y0, x0, (sy, sx), mean, metric == "convergence", keep_full, band == x)
    edges, centres = [], []
    for a, n, sa in ((xa, nx, sx), (ya, ny, sy)):
        v = np.arange(n) if a.categorical else a.values
        log = not a.categorical and ksplot.is_log_spaced(a.values)
        e = ksplot.cell_edges(v, log)
        be = e[::sa] if n % sa == 0 else np.append(e[::sa], e[-1])
        c = v if sa == 1 else (np.sqrt(be[:-1] * be[1:]) if log else (be[:-1] + be[1:]) / 2)
        edges.append(be)
        centres.append(c)
    notes = list(p["notes"])
    if s > 1:
        notes.append(f"each drawn cell the {'mean' if mean else 'min'} of {sy} × {sx} of the {ny} × {nx} cells")
    fa = ls.axis(facet) if facet else None
    return {**out, "metric": metric, "x": xa, "y": ya, "notes": notes, "reduce": p["reduce"], "fixed": fixed,
            "facet": facet, "panel_labels": list(fa.labels) if fa else [None], "block": (sy, sx),
            "edges": edges, "centres": centres, "stride": s}


def _band(out, pnl, pieces, y0, x0, block, mean, convergence, keep_full, swap=False):
    """Reduce a band of a panel (pieces: rows y from y0, columns x from x0, the cells reduced last;
    swap: rows x, columns y): its full-grid values and categories, what they add to the panel's
    minimum, mean, counts and the range, and its drawn cells."""
    vals = pieces["value"]
    st = pieces.get("status")
    if not convergence:  # the failed runs' values are not drawn (0: ok / converged)
        if pieces.get("fresh"):  # a piece read from the file: masked in place
            np.copyto(vals, np.nan, where=st != 0)
        else:
            vals = np.where(st != 0, np.nan, vals)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        if vals.shape[2] == 1:  # nothing to reduce: the grid itself (no copy)
            z = vals[..., 0]
        else:
            z = np.nanmean(vals, axis=2) if mean else np.nanmin(vals, axis=2)
    if convergence:
        cat = np.full(z.shape, -1, dtype=np.int8)
    else:
        cat = failed_category(st, np.isnan(z) if vals.shape[2] == 1 else np.all(np.isnan(vals), axis=2), 0)
    if convergence:  # its mean, not its minimum, is marked; the colour scale is 0 .. 1
        keep = ~np.isnan(z)
        n = int(np.count_nonzero(keep))
        if n:
            out["finite"] = True
            out["sum"][pnl] += np.sum(z, where=keep)
            out["count"][pnl] += n
            out["best"][pnl] = (0.0, 0, 0)  # (the panel has values)
            pos = np.min(z, where=z > 0, initial=np.inf)  # (--log's lower end)
            if np.isfinite(pos):
                out["pos"] = pos if out["pos"] is None else min(out["pos"], pos)
        lo = hi = np.nan
    else:
        with np.errstate(all="ignore"):
            lo, hi = np.fmin.reduce(z, axis=None), np.fmax.reduce(z, axis=None)  # np.nanmin, np.nanmax
    if not convergence and (np.isfinite(lo) or np.isfinite(hi) or np.isfinite(z).any()):
        out["finite"] = True
        out["vmin"] = lo if out["vmin"] is None else min(out["vmin"], lo)
        out["vmax"] = hi if out["vmax"] is None else max(out["vmax"], hi)
        pos = lo if lo > 0 else np.min(z, where=z > 0, initial=np.inf)
        if np.isfinite(pos):
            out["pos"] = pos if out["pos"] is None else min(out["pos"], pos)
        zy = z.T if swap else z  # rows y
        i, j = np.unravel_index(int(np.argmax(zy == lo)), zy.shape)  # np.nanargmin's first cell
        b = (float(lo), int(i) + y0, int(j) + x0)
        out["best"][pnl] = b if out["best"][pnl] is None else min(out["best"][pnl], b)
    c = cat[cat >= 0].astype(np.int64)
    n = np.bincount(c, minlength=len(out["counts"][pnl]))
    n[:len(out["counts"][pnl])] += out["counts"][pnl]
    out["counts"][pnl] = n
    out["no_run"][pnl] |= bool((cat == -2).any())
    if swap:
        z, cat = z.T, cat.T
    if keep_full:
        out["full_z"][pnl, y0:y0 + z.shape[0], x0:x0 + z.shape[1]] = z
        out["full_cat"][pnl, y0:y0 + z.shape[0], x0:x0 + z.shape[1]] = cat
    sy, sx = block
    r0, c0 = y0 // sy, x0 // sx
    if sy == sx == 1:
        dz, dcat = z, cat
    else:
        dz, dcat = _blocks(vals, None if convergence else st, *((sx, sy) if swap else (sy, sx)), mean)
        if swap:
            dz, dcat = dz.T, dcat.T
    out["z"][pnl, r0:r0 + dz.shape[0], c0:c0 + dz.shape[1]] = dz
    out["cat"][pnl, r0:r0 + dz.shape[0], c0:c0 + dz.shape[1]] = dcat


def _codes(v):
    """A piece of a status_code grid as integer codes, -1 where no run (a float grid's NaN)."""
    v = np.asarray(v)
    if v.dtype.kind in "iu":
        return v
    return np.where(np.isnan(v), -1, v).astype(np.int16)


def _blocks(vals, st, sy, sx, mean):
    """The drawn cells of a band: its values (rows x columns x cells reduced) in blocks of sy x sx
    (the last ones padded with no run), each block's min or mean (np.fmin over it, or its sum over
    its count of values), and where a block has no value the most common failed status of its runs
    (failed_category). Returns (values, categories) per block."""
    ny, nx, r = vals.shape
    by, bx = -(-ny // sy), -(-nx // sx)

    def cut(a):  # block rows x sy x block columns x sx x cells reduced (a view when nothing is padded)
        if (by * sy, bx * sx) != (ny, nx):  # padded with no run (NaN, or the code -1)
            a = np.pad(a, ((0, by * sy - ny), (0, bx * sx - nx), (0, 0)),
                       constant_values=np.nan if a.dtype.kind == "f" else -1)
        return a.reshape(by, sy, bx, sx, r)

    v = cut(vals)
    with np.errstate(all="ignore"):
        if mean:
            have = ~np.isnan(v)
            n = np.count_nonzero(have, axis=(1, 3, 4))
            z = np.sum(np.where(have, v, 0.0), axis=(1, 3, 4)) / n
            none = n == 0
        else:
            z = np.fmin.reduce(v, axis=(1, 3, 4))
            none = np.isnan(z)
    cat = np.full(z.shape, -1, dtype=np.int8)
    if st is not None and none.any():  # failed_category of the blocks: each code's runs counted per block
        s = cut(st)
        codes = small_codes(st[st > 0])  # (no run, -1, is not > 0; 0 is the good status)
        if codes.size:
            counts = np.stack([np.count_nonzero(s == c, axis=(1, 3, 4)) for c in codes], axis=-1)
            top = codes[np.argmax(counts, axis=-1)]
            cat[none] = np.where(counts.max(axis=-1) > 0, top, -2)[none]
        else:
            cat[none] = -2
    return z, cat


def nan_mean(z):
    """np.nanmean(z) without its copy of z (the mean of the values that are not NaN)."""
    keep = ~np.isnan(z)
    return float(np.sum(z, where=keep) / np.count_nonzero(keep))


def small_codes(v):
    """np.unique(v).astype(int) of status codes (small integers): counted, not sorted."""
    iv = v.astype(np.int64)
    if iv.size and (iv.min() < 0 or iv.max() > 1 << 16 or np.any(iv != v)):  # not codes: sorted after all
        return np.unique(v).astype(int)
    return np.flatnonzero(np.bincount(iv))


def failed_category(status, none, good):
    """Per cell (panels x ny x nx) of `status` (same x cells reduced; codes as floats, NaN no run, or
    integers, -1 no run): -1 where `none` is false (the cell has a value), else the most common failed
    status of its runs (the smallest code on a tie), -2 when it has no run at all."""
    cat = np.full(none.shape, -1, dtype=np.int8)  # status codes are small
    if not none.any():
        return cat
    if status.shape[-1] == 1:  # one run per cell: its own status when that is a failed one, else no run
        s = status[..., 0]
        cat[none] = -2
        np.copyto(cat, s, casting="unsafe", where=none & _held(s) & (s != good))
        return cat
    st = status[none]  # cells without a value x their runs
    fail = _held(st) & (st != good)
    if not fail.any():
        cat[none] = -2
        return cat
    v = st[fail]
    iv = v.astype(np.int64)
    if iv.min() >= 0 and iv.max() < 128 and np.all(iv == v):  # codes: counted per cell in one bincount
        k = int(iv.max()) + 1
        counts = np.bincount(np.nonzero(fail)[0] * k + iv, minlength=len(st) * k).reshape(len(st), k)
        cat[none] = np.where(counts.max(axis=1) > 0, np.argmax(counts, axis=1), -2)
        return cat
    codes = small_codes(v)
    counts = np.stack([np.sum(st == c, axis=1) for c in codes], axis=1)
    cat[none] = np.where(counts.max(axis=1) > 0, codes[np.argmax(counts, axis=1)], -2)
    return cat


def _held(s):
    """Which status codes are of a run: finite (float grids), not the no-run code -1 (integer codes)."""
    return s >= 0 if s.dtype.kind in "iu" else np.isfinite(s)


def draw_stride(nx, ny, pixels):
    """Every s-th cell of each axis drawn so that neither axis draws more cells than the picture has
    pixels across (more would not show; the minimum is marked from the full grid)."""
    return max(1, -(-max(nx, ny) // max(1, pixels)))


def _first_value(a):
    return a.labels[0] if a.categorical else ksplot.fmt_num(a.values[0])


