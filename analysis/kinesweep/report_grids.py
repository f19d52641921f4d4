"""Gridded figures of kinesweep.report: which landscape axes go on x and y, which of the other dims
become facets or a dropdown (and which are held at the best cell, said in the caption), subsampling
of big grids, and the landscape heatmaps (metric colour, failed cells in their status colours, hover
with the cell's parameters and metrics). Plain plotly dicts. Run with /usr/bin/python3."""
import math

import numpy as np

from kinesweep.grid_blocks import blocks, first_min, flat_start, frame_parts, grid_source, read_block, take_drawn
from kinesweep.kinds import STATUS_COLOURS  # noqa: F401 (used below)
from kinesweep.report_page import Rounded, esc, fmt

MAX_FRAMES = 24      # facets / dropdown entries per figure; further dims are held at the best cell
MAX_FACETS = 4       # up to this many frames side by side, more in a dropdown


def axis_title(a):
    return f"{a.name} [{a.unit}]" if a.unit else a.name


def axis_values(a, idx):
    return [a.labels[int(i)] for i in idx] if a.categorical else [float(a.values[i]) for i in idx]


def value_text(a, i):
    v = a.labels[int(i)] if a.categorical else fmt(a.values[i], 5)
    return f"{a.name} = {v}" + (f" {a.unit}" if a.unit and not a.categorical else "")


class Selection:
    """x, y (None for a 1-D landscape), the frames over the other dims and the dims held fixed.
    frames: list of (label, {dim: index}); fixed: {dim: index} (same in every frame)."""

    def __init__(self, ls, best_index):
        n = len(ls.axes)
        longer = [i for i, a in enumerate(ls.axes) if len(a.values) > 1]
        numeric = [i for i in longer if not ls.axes[i].categorical]
        if ls.kind == "ik":  # IK grids: the initial guesses on x and y when two of them are swept
            guesses = [i for i in numeric if ls.axes[i].name.startswith("q0_")]
            numeric = (guesses + [i for i in numeric if i not in guesses]) if len(guesses) >= 2 else numeric
        order = numeric + [i for i in longer if i not in numeric] + [i for i in range(n) if i not in longer]
        self.x = order[0]
        self.y = order[1] if len(order) > 1 and len(ls.axes[order[1]].values) > 1 else None
        rest = [i for i in range(n) if i not in (self.x, self.y)]
        self.fixed, self.held = {}, []
        framed, count = [], 1
        for d in rest:
            size = len(ls.axes[d].values)
            if size == 1:
                self.fixed[d] = 0
            elif count * size <= MAX_FRAMES:
                framed.append(d)
                count *= size
            else:
                self.fixed[d] = int(best_index[d]) if best_index is not None else 0
                self.held.append(d)
        self.frames = []
        for combo in np.ndindex(*[len(ls.axes[d].values) for d in framed]) if framed else [()]:
            idx = dict(zip(framed, combo))
            label = ", ".join(value_text(ls.axes[d], i) for d, i in idx.items())
            self.frames.append((label, idx))
        self.framed = framed
        self.ls = ls

    def slice(self, grid, frame_index):
        """The frame's 2-D slice, rows = y, columns = x (1-D: a 1 x nx array)."""
        idx = [0] * grid.ndim
        for d, i in {**self.fixed, **frame_index}.items():
            idx[d] = i
        idx[self.x] = slice(None)
        if self.y is not None:
            idx[self.y] = slice(None)
        g = grid[tuple(idx)]
        if self.y is None:
            return g[None, :]
        return g.T if self.x < self.y else g

    def caption(self):
        ls, parts = self.ls, []
        if self.framed:
            parts.append(f"one {'panel' if len(self.frames) <= MAX_FACETS else 'dropdown entry'} per value of "
                         + " × ".join(ls.axes[d].name for d in self.framed))
        if self.held:
            parts.append("held at the best cell (not reduced): "
                         + ", ".join(value_text(ls.axes[d], self.fixed[d]) for d in self.held))
        return "; ".join(parts)

    def stride(self, cap):
        """Every s-th value of x and y so that the figure holds at most `cap` cells over its frames."""
        nx = len(self.ls.axes[self.x].values)
        ny = len(self.ls.axes[self.y].values) if self.y is not None else 1
        total = nx * ny * len(self.frames)
        if total <= cap:
            return 1
        return int(math.ceil(math.sqrt(total / cap))) if self.y is not None else int(math.ceil(total / cap))


def ordinal(n):
    return f"{n}{'th' if 10 <= n % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(n % 10, 'th')}"


def capped_note(sel, s, star=True):
    if s == 1:
        return ""
    ls = sel.ls
    nx = len(ls.axes[sel.x].values)
    ny = len(ls.axes[sel.y].values) if sel.y is not None else 1
    shown = len(range(0, nx, s)) * (len(range(0, ny, s)) if sel.y is not None else 1)
    return (f' <span class="capped">Capped: every {ordinal(s)} value of each plotted axis is drawn ({shown} of '
            f"{nx * ny} cells per panel){'; the marked best cell is the full grid' + chr(39) + 's' if star else ''}."
            "</span>")


def arrange(frames, sel, xa, ya, height=480):
    """Lay out the frames' traces: side by side (facets) or one at a time with a dropdown.
    frames: list of (label, [trace dicts]). Returns (data, layout)."""
    data, layout = [], {"height": height, "margin": {"l": 70, "r": 30, "t": 60, "b": 60},
                        "legend": {"orientation": "h", "y": -0.18, "x": 0}, "plot_bgcolor": "#ffffff"}
    ytitle = axis_title(ya) if ya is not None else ""
    n = len(frames)
    if n <= MAX_FACETS:
        gap = 0.05 if n > 1 else 0.0
        notes = []
        for i, (label, traces) in enumerate(frames):
            s = "" if i == 0 else str(i + 1)
            for t in traces:
                t["xaxis"], t["yaxis"] = "x" + s, "y" + s
                data.append(t)
            dom = [i / n + (gap / 2 if i else 0), (i + 1) / n - (gap / 2 if i < n - 1 else 0)]
            layout["xaxis" + s] = {"domain": dom, "title": {"text": axis_title(xa)}, "anchor": "y" + s}
            layout["yaxis" + s] = {"anchor": "x" + s, "title": {"text": ytitle if i == 0 else ""}}
            if i:
                layout["yaxis" + s]["matches"] = "y"
                layout["yaxis" + s]["showticklabels"] = False
            if label:
                notes.append({"text": esc(label), "x": (dom[0] + dom[1]) / 2, "y": 1.0, "xref": "paper",
                              "yref": "paper", "xanchor": "center", "yanchor": "bottom", "showarrow": False, "font": {"size": 13}})
        layout["annotations"] = notes
        return data, layout
    counts = [len(t) for _, t in frames]
    buttons = []
    for i, (label, traces) in enumerate(frames):
        for t in traces:
            t["visible"] = i == 0
            data.append(t)
        vis = [j == i for j, c in enumerate(counts) for _ in range(c)]
        buttons.append({"label": label, "method": "restyle", "args": [{"visible": vis}, list(range(len(vis)))]})
    layout["updatemenus"] = [{"buttons": buttons, "x": 0, "y": 1.02, "xanchor": "left", "yanchor": "bottom",
                              "direction": "down", "showactive": True, "active": 0}]
    layout["margin"]["t"] = 80
    layout["xaxis"] = {"title": {"text": axis_title(xa)}}
    layout["yaxis"] = {"title": {"text": ytitle}}
    return data, layout


def legend_square(name, colour, group=None):
    """A legend entry with no data (heatmap cells have none of their own)."""
    return {"type": "scatter", "x": [None], "y": [None], "mode": "markers", "name": name, "showlegend": True,
            "marker": {"symbol": "square", "size": 12, "color": colour, "line": {"color": "#555", "width": 1}},
            "hoverinfo": "skip", "legendgroup": group or name}


def colour_scale(values):
    """Linear or (for a positive range over more than two decades) log10 colour scale: returns
    (transform, zmin, zmax, colorbar ticks or None)."""
    finite = values[np.isfinite(values)]
    return colour_scale_range(float(finite.min()), float(finite.max())) if finite.size else colour_scale_range()


def colour_scale_range(lo=None, hi=None):
    """colour_scale of values whose finite ones range from lo to hi (None: no finite value)."""
    if lo is None:
        return (lambda v: v), 0.0, 1.0, None
    if lo > 0 and hi / lo > 100:
        vals = [m * 10.0 ** e for e in range(int(math.floor(math.log10(lo))), int(math.ceil(math.log10(hi))) + 1)
                for m in (1, 2, 5) if lo <= m * 10.0 ** e <= hi]
        ticks = {"tickvals": [math.log10(v) for v in vals], "ticktext": [f"{v:g}" for v in vals]}
        return np.log10, math.log10(lo), math.log10(hi), ticks
    return (lambda v: v), lo, hi if hi > lo else lo + 1.0, None


def best_cell(ls, metric):
    """np.nanargmin's cell (an index per dim) of `metric` over the cells of good status, None when
    none has a value: read a block at a time."""
    status, values = grid_source(ls, "status_code"), grid_source(ls, metric)
    best = None
    for lo, hi in blocks(status.shape):
        st = read_block(status, lo, hi)
        v = np.where(st == 0, read_block(values, lo, hi), np.nan).ravel()
        finite = np.isfinite(v)
        if finite.any():
            m = v[finite].min()
            if best is None or m < best[0]:
                best = (m, flat_start(lo, status.shape) + int(np.argmax(v == m)))
    return np.unravel_index(best[1], status.shape) if best is not None else None


def scan_landscape(ls, metric, sel, s, xi, yi):
    """One pass over the landscape's grids, a block of cells at a time (kinesweep.grid_blocks): per
    frame the drawn cells (every s-th of x and y) of the status, of `metric` where the status is good
    and of every other metric, the counts of each status code and the smallest value (np.nanargmin's
    cell); the range of the values over the frames; the metrics with a value in a good and in a failed
    cell; whether a cell has no run. Memory: a few blocks and the drawn cells."""
    others = [m for m in ls.metrics if m not in ls.status_grids()]
    status = grid_source(ls, "status_code")
    sources = {m: grid_source(ls, m) for m in others}
    nf, shape = len(sel.frames), (len(yi), len(xi))
    out = {"status": [np.full(shape, np.nan) for _ in range(nf)], "value": [np.full(shape, np.nan) for _ in range(nf)],
           "sampled": {m: [np.full(shape, np.nan) for _ in range(nf)] for m in others},
           "counts": [np.zeros(len(ls.statuses) + 1, dtype=np.int64) for _ in range(nf)], "best": [None] * nf,
           "range": None, "good": set(), "failed": set(), "no_run": False}

    def put(target, k, part, y0, x0):
        cells, r, c = take_drawn(part, y0, x0, s)
        target[k][r, c] = cells

    for lo, hi in blocks(status.shape):
        st = read_block(status, lo, hi)
        good, finite_st = st == 0, np.isfinite(st)
        failed = finite_st & ~good
        out["no_run"] |= not finite_st.all()
        for k, part, y0, x0 in frame_parts(sel, lo, hi, st):
            put(out["status"], k, part, y0, x0)
            codes = part[np.isfinite(part)].astype(np.int64)
            n = np.bincount(codes, minlength=len(out["counts"][k]))
            if len(n) > len(out["counts"][k]):
                n[:len(out["counts"][k])] += out["counts"][k]
                out["counts"][k] = n
            else:
                out["counts"][k] += n
        for m in others:
            g = read_block(sources[m], lo, hi)
            finite = np.isfinite(g)
            if m not in out["good"] and (finite & good).any():
                out["good"].add(m)
            if m not in out["failed"] and (finite & failed).any():  # the failed runs' metrics with values
                out["failed"].add(m)
            for k, part, y0, x0 in frame_parts(sel, lo, hi, g):
                put(out["sampled"][m], k, part, y0, x0)
            if m != metric:
                continue
            val = np.where(good, g, np.nan)
            for k, part, y0, x0 in frame_parts(sel, lo, hi, val):
                put(out["value"], k, part, y0, x0)
                b = first_min(part, y0, x0)
                if b is not None:
                    out["best"][k] = b if out["best"][k] is None else min(out["best"][k], b)
                    fin = part[np.isfinite(part)]
                    lo_v, hi_v = float(fin.min()), float(fin.max())
                    r = out["range"]
                    out["range"] = (min(r[0], lo_v), max(r[1], hi_v)) if r else (lo_v, hi_v)
    return out


def landscape_figure(ls, cap):
    """The block's default metric (E; IK: iterations of converged runs) over the selected axes.
    Returns (figure dict, caption html, cells drawn). The grids are read a block of cells at a time
    (scan_landscape): the figure holds the drawn cells, not the grids."""
    if not ls.axes:
        return None
    metric = ls.objective
    if metric not in ls.metrics:
        metric = [m for m in ls.metrics if m not in ls.status_grids()][0]
    sel = Selection(ls, None)
    if sel.held:  # dims held at the best cell: find it first
        sel = Selection(ls, best_cell(ls, metric))
    xa, ya = ls.axes[sel.x], (ls.axes[sel.y] if sel.y is not None else None)
    s = sel.stride(cap)
    xi = np.arange(0, len(xa.values), s)
    yi = np.arange(0, len(ya.values), s) if ya is not None else np.array([0])
    scan = scan_landscape(ls, metric, sel, s, xi, yi)
    hover_metrics = [m for m in ls.metrics if m in scan["good"]]
    fail_metrics = [m for m in ls.metrics if m in scan["failed"]]
    sampled = scan["sampled"]
    transform, zmin, zmax, ticks = colour_scale_range(*(scan["range"] or ()))
    statuses = ls.statuses
    unit = ls.units.get(metric, "")
    label = ls.label(metric) + (f" [{unit}]" if unit else "")
    xs, ys = axis_values(xa, xi), (axis_values(ya, yi) if ya is not None else [""])
    pos = "%{x}" + (f" {xa.unit}" if xa.unit else "")
    head = f"{xa.name} = {pos}" + (f"<br>{ya.name} = %{{y}}" + (f" {ya.unit}" if ya.unit else "") if ya else "")
    frames, failed_seen, cells = [], {}, 0
    dropdown = len(sel.frames) > MAX_FACETS  # then every frame carries its colour bar and legend entry
    for k_frame, (flabel, f) in enumerate(sel.frames):
        ctx = (f"<br>{esc(flabel)}" if flabel else "") + "".join(
            f"<br>{esc(value_text(ls.axes[d], sel.fixed[d]))}" for d in sel.held)
        st = scan["status"][k_frame]
        z = scan["value"][k_frame]
        custom = hover_data([sampled[m][k_frame] for m in hover_metrics], np.isfinite(z))
        tmpl = head + ctx + "".join(f"<br>{m} = %{{customdata[{k}]:.5g}}" + (f" {ls.units[m]}" if ls.units[m] else "")
                                    for k, m in enumerate(hover_metrics)) + f"<br>status {statuses[0]}<extra></extra>"
        with np.errstate(all="ignore"):
            zt = transform(z)
        cb = {"title": {"text": label, "side": "right"}, **(ticks or {})}
        traces = [{"type": "heatmap", "x": xs, "y": ys, "z": zt, "customdata": custom, "hovertemplate": tmpl,
                   "colorscale": "Viridis", "zmin": zmin, "zmax": zmax, "colorbar": cb, "hoverongaps": False,
                   "showscale": dropdown or not frames, "name": metric}]
        fail = np.where(np.isfinite(st) & (st != 0), st, np.nan)
        codes = sorted({int(c) for c in np.unique(fail[np.isfinite(fail)])})
        fm = fail_metrics if codes else []
        fvals = [sampled[m][k_frame] for m in fm]
        for c in codes:  # one trace per failed status: its name in the hover text, not in every cell
            failed_seen[c] = failed_seen.get(c, 0) + int(scan["counts"][k_frame][c])
            cells_c = fail == c
            ftmpl = head + ctx + f"<br>status {esc(statuses[c])}" + "".join(
                f"<br>{m} = %{{customdata[{k}]:.5g}}" + (f" {ls.units[m]}" if ls.units[m] else "")
                for k, m in enumerate(fm)) + "<extra></extra>"
            traces.append({"type": "heatmap", "x": xs, "y": ys, "z": np.where(cells_c, fail, np.nan),
                           "customdata": hover_data(fvals, cells_c) if fm else None,
                           "zmin": 0, "zmax": max(1, len(statuses) - 1), "colorscale": _steps(statuses),
                           "showscale": False, "hoverongaps": False, "name": statuses[c], "hovertemplate": ftmpl})
        best = scan["best"][k_frame]
        if best is not None:
            v, i, j = best
            bx = axis_values(xa, [j])[0]
            by = axis_values(ya, [i])[0] if ya is not None else ""
            traces.append({"type": "scatter", "x": [bx], "y": [by], "mode": "markers", "name": "best cell",
                           "showlegend": dropdown or not frames, "legendgroup": "best",
                           "marker": {"symbol": "star", "size": 16, "color": "#ff3030",
                                      "line": {"color": "white", "width": 1.5}},
                           "hovertemplate": f"best cell: {metric} = {fmt(v, 6)} {unit}<extra></extra>"})
        cells += z.size
        frames.append((flabel, traces))
    if ya is None:  # a 1-D landscape: a one-row strip
        for _, traces in frames:
            for t in traces:
                if t["type"] == "heatmap":
                    t["y"] = [metric]
                elif t["type"] == "scatter":
                    t["y"] = [metric]
    data, layout = arrange(frames, sel, xa, ya, height=300 if ya is None else 500)
    data += [legend_square(f"{statuses[c]}", STATUS_COLOURS.get(statuses[c], "#999999")) for c in sorted(failed_seen)]
    fig = {"data": data, "layout": layout}
    good_name = statuses[0]
    parts = [f"{esc(label[0].upper() + label[1:])} of the {good_name} runs over {esc(xa.name)}"
             + (f" × {esc(ya.name)}" if ya is not None else "")
             + (" (log colour scale)" if ticks else "") + "; the colour scale is shared by all panels."]
    if failed_seen:
        parts.append("Failed cells in their status colours: "
                     + ", ".join(f"{statuses[c]} {n}" for c, n in sorted(failed_seen.items())) + ".")
    if scan["no_run"]:
        parts.append("White cells: no run.")
    more = sel.caption()
    if more:
        parts.append(esc(more[0].upper() + more[1:]) + ".")
    parts.append("The star marks the smallest value of each panel; hover a cell for its parameters and metrics.")
    return fig, " ".join(parts) + capped_note(sel, s), cells


def hover_data(values, cells):
    """Per-cell hover values (a list per row of [v0, v1, ...]) where `cells` is true, null elsewhere
    (cells without hover text), floats to 5 significant digits as the hover shows them (a Rounded
    list: the page keeps them as they are, 7 digits of them being the same numbers)."""
    out = Rounded()
    stacked = np.stack(values, axis=-1) if values else np.zeros(cells.shape + (0,))
    for row, keep in zip(stacked, cells):
        out.append([[float(f"{x:.5g}") if math.isfinite(x) else None for x in cell] if k else None
                    for cell, k in zip(row.tolist(), keep.tolist())])
    return out


def _steps(statuses):
    """A discrete colour scale: status code c (0..n-1, zmin 0, zmax n-1) in its status colour."""
    n = len(statuses)
    out = []
    for c, name in enumerate(statuses):
        col = STATUS_COLOURS.get(name, "#999999")
        lo, hi = max(0.0, (c - 0.5) / (n - 1)), min(1.0, (c + 0.5) / (n - 1))
        out += [[lo, col], [hi, col]]
    return out
