#!/usr/bin/python3
"""A block's runs read straight from /runs, for a study of any shape (grids, random and Latin-hypercube
axes, a study still running or interrupted: done rows only).

Views (--view):
  scatter    a metric against one parameter (--x), or two parameters (--x, --y) coloured by the metric
  slice      one panel per parameter, the metric against it (as Optuna's slice plot), points coloured by
             run order or by a column (--colour)
  parcoords  parallel coordinates over the parameters and the metric, one line per run coloured by the
             metric; text columns (method, ...) on evenly spaced ticks
Failed runs (status other than ok / converged) are grey markers (grey lines in parcoords) with a legend,
never part of the colour scale; runs with no value of the metric sit on the bottom edge. Parameters
spread evenly over decades (e.g. lambda = 1e-3 .. 100) get log axes. Angles are shown in degrees.

    python3 -m kinesweep.plot_runs results/study.h5 --view slice
    python3 -m kinesweep.plot_runs results/study.h5 --x alpha1A --y k --where "E<60 | status=diverged"
    python3 -m kinesweep.plot_runs results/ik.h5 --view parcoords --params method,lambda,q0_1
"""
import argparse
import os
import sys

import numpy as np

from kinesweep import plotting as ksplot  # noqa: E402
from kinesweep import read as ksread  # noqa: E402
from kinesweep import where as kswhere  # noqa: E402

VIEWS = ("scatter", "slice", "parcoords")
GOOD = tuple(ksread.GOOD_STATUSES)  # the legend's wording; a block's own come from the file (kind_meaning)
FAIL_MARKERS = ["x", "+", "v", "^", "s", "D", "1", "*", "P"]
FACET_MAX = 12  # a numeric column with at most this many distinct values can be a facet
OK_COLOUR = "#1f77b4"


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.plot_runs", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p, default_size="900x600")
    p.add_argument("--view", default="scatter", choices=VIEWS, help="default %(default)s")
    p.add_argument("--block", help="block to plot (default: the first block of the file)")
    p.add_argument("--metric", help="metric column (default: E for trajectory blocks, iterations for IK blocks)")
    p.add_argument("--x", help="scatter: parameter on x (default: the block's first swept parameter)")
    p.add_argument("--y", help="scatter: a second parameter on y; the metric is then the colour")
    p.add_argument("--params", help="slice, parcoords: columns, comma-separated (default: the block's swept "
                   "parameters, i.e. those that take more than one value among its runs)")
    p.add_argument("--colour", "--color", dest="colour",
                   help="slice: colour points by this column (default: run order, i.e. run id)")
    p.add_argument("--facet", help="scatter, slice: one panel (row of panels) per value of this column "
                   "(text, e.g. method or block, or a number with few values); --facet block without "
                   "--block shows every block of the first block's run kind")
    p.add_argument("--where", "-w", action="append", default=[], metavar="EXPR",
                   help="keep the rows where EXPR holds (repeatable: all must hold); the syntax of "
                   "`kinesweep query --where`: COL OP VALUE, COL=A,B, COL=LO..HI, LO<COL<=HI, angles "
                   "in degrees; alternatives separated by ' | ' (any holds)")
    p.add_argument("--log", action="store_true", help="the metric on a log scale (axis or colour)")
    return p.parse_args(kswhere.where_argv(sys.argv[1:] if argv is None else argv))


def fail(msg, code=2):
    print(f"kinesweep.plot_runs: {msg}", file=sys.stderr)
    raise SystemExit(code)


class Col:
    """A column of the plotted rows: values in display units (text for text columns), positions to draw
    at (category index for text), scale "linear" | "log" | "category"."""

    def __init__(self, name, unit, values, scale, categories=None):
        self.name, self.unit, self.values, self.scale, self.categories = name, unit, values, scale, categories
        if categories is not None:
            self.pos = np.array([categories.index(v) for v in values], dtype=float)
        else:
            self.pos = np.asarray(values, dtype=float)

    def describe(self):
        return {"name": self.name, "unit": self.unit, "scale": self.scale, "categories": self.categories}

    def label(self):
        return ksplot.axis_label(self.name, self.unit)


def make_col(runs, name, rows, scale=None):
    v = runs[name][rows]
    if v.dtype == object:
        return Col(name, "", v, "category", list(dict.fromkeys(v)))
    v = v.astype(float)
    return Col(name, runs.units[name], v, scale or ("log" if ksplot.is_log_spaced(v) else "linear"))


def check_column(name, columns, what):
    if name not in columns:
        fail(kswhere.unknown_column_message(name, columns, f" in {what}"))
    return name


def set_axis(ax, col, which):
    """Scale, limits and ticks of one axis of `ax` for column `col` ("x" or "y")."""
    if col.scale == "category":
        n = len(col.categories)
        labels = [c.replace("_", "_\n") if len(c) > 10 else c for c in col.categories] \
            if which == "x" and sum(len(c) for c in col.categories) > 16 else col.categories
        (ax.set_xticks if which == "x" else ax.set_yticks)(range(n), labels)
        (ax.set_xlim if which == "x" else ax.set_ylim)(-0.5, n - 0.5)
    elif col.scale == "log":
        (ax.set_xscale if which == "x" else ax.set_yscale)("log")
    (ax.set_xlabel if which == "x" else ax.set_ylabel)(col.label())


def jitter(col, seed):
    """Draw positions: text categories spread ±0.15 around their tick (deterministic), numbers as they are."""
    if col.scale != "category":
        return col.pos
    return col.pos + np.random.default_rng(seed).uniform(-0.15, 0.15, len(col.pos))


def draw_failed(ax, x, y, status, fail_order, y_is_metric):
    """Grey markers per failure status; with y the metric, runs without a value sit on the bottom edge."""
    import matplotlib.transforms as mtrans
    for i, s in enumerate(fail_order):
        m = status == s
        if not m.any():
            continue
        kw = dict(marker=FAIL_MARKERS[i % len(FAIL_MARKERS)], color="0.35", s=28, lw=1.0, zorder=3)
        if kw["marker"] in ("v", "^", "s", "D", "P", "*"):
            kw.update(facecolors="none", edgecolors="0.35")
            del kw["color"]
        has = m & np.isfinite(y)
        ax.scatter(x[has], y[has], **kw)
        none = m & ~np.isfinite(y) if y_is_metric else np.zeros_like(m)
        if none.any():
            tr = mtrans.blended_transform_factory(ax.transData, ax.transAxes)
            ax.scatter(x[none], np.full(int(none.sum()), 0.025), transform=tr, **kw)
            # the x limits must take these points in too (autoscaling skips a blended transform)
            ax.update_datalim(np.column_stack([x[none], np.ones(int(none.sum()))]), updatey=False)
            ax.autoscale_view()


def failure_handles(ctx, y_is_metric=True):
    """Legend entries of the failure statuses: runs of each (those without a value of the metric)."""
    from matplotlib.lines import Line2D
    out = []
    for i, s in enumerate(ctx["fail_order"]):
        m = ctx["status"] == s
        n = int(m.sum())
        none = int(np.sum(m & ~np.isfinite(ctx["metric"].pos))) if y_is_metric else 0
        mk = FAIL_MARKERS[i % len(FAIL_MARKERS)]
        label = f"{s} ({n})" + (f", {none} without a value: on the bottom edge" if none else "")
        out.append(Line2D([], [], ls="", marker=mk, color="0.35", mfc="none", label=label))
    return out


def layout(fig, handles, colourbar):
    """Fit the panels (tight layout) between the title, a legend row at the bottom and the colour bar's
    axes on the right; returns those axes (or None)."""
    h = fig.get_figheight() * fig.dpi
    rows = (len(handles) + 2) // 3 if handles else 0
    low = (8 + 16 * rows) / h
    top = 1 - 48 / h
    fig.tight_layout(rect=(0, low, 0.87 if colourbar else 1.0, top), h_pad=1.0, w_pad=0.6)
    if handles:
        fig.legend(handles=handles, loc="lower center", ncol=min(3, len(handles)), fontsize=8, frameon=False)
    sp = fig.subplotpars
    return fig.add_axes([0.89, sp.bottom, 0.018, sp.top - sp.bottom]) if colourbar else None


def panel_grid(plt, size, n, sharey=True, ncols=None):
    ncols = ncols or int(np.ceil(np.sqrt(n)))
    nrows = int(np.ceil(n / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=size, squeeze=False, sharex=True, sharey=sharey)
    flat = list(axes.ravel())
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, axes, flat[:n]


def norm_for(values, log):
    import matplotlib.colors as mcolors
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v) & ((v > 0) if log else True)]
    lo, hi = (float(v.min()), float(v.max())) if v.size else (0.0, 1.0)
    if hi == lo:
        lo, hi = (lo / 2, hi * 2) if log and lo > 0 else (lo - 0.5, hi + 0.5)
    return (mcolors.LogNorm if log else mcolors.Normalize)(vmin=lo, vmax=hi)


def panel_title(ax, facet, value, n):
    if facet:
        ax.set_title(f"{facet} = {value}  ({n} runs)", fontsize=9)


def view_scatter(plt, size, ctx):
    x, y, metric, good, facets = ctx["x"], ctx["y"], ctx["metric"], ctx["good"], ctx["facets"]
    two = y is not None
    yc = y if two else metric
    fig, axes, flat = panel_grid(plt, size, len(facets))
    norm = norm_for(metric.values[good], ctx["log"]) if two else None
    panels, sc = [], None
    for p, (ax, (fv, rows)) in enumerate(zip(flat, facets)):
        g = rows & good
        xp = jitter(x, p)
        yp = jitter(y, p + 100) if two else metric.pos
        if two:
            sc = ax.scatter(xp[g], yp[g], c=metric.values[g], cmap="viridis", norm=norm, s=22, zorder=2,
                            edgecolors="none")
        else:
            ax.scatter(xp[g], yp[g], color=OK_COLOUR, s=18, alpha=0.8, zorder=2, edgecolors="none")
        f = rows & ~good
        draw_failed(ax, xp[f], yp[f], ctx["status"][f], ctx["fail_order"], not two)
        panel_title(ax, ctx["facet"], fv, int(rows.sum()))
        ax.grid(alpha=0.3)
        panels.append({"facet": fv, "run_ids": ctx["run_ids"][rows], "status": ctx["status"][rows],
                       "x": x.values[rows], "y": yc.values[rows], "colour": metric.values[rows] if two else None})
    for ax in flat:
        set_axis(ax, x, "x")
        set_axis(ax, yc, "y")
        if not two and ctx["log"]:
            ax.set_yscale("log")
        ax.label_outer()
    handles = failure_handles(ctx, not two)
    if not two and any(good[r].any() for _, r in facets):
        from matplotlib.lines import Line2D
        handles.insert(0, Line2D([], [], ls="", marker="o", color=OK_COLOUR, label=f"{'/'.join(GOOD)} runs"))
    cax = layout(fig, handles, two)
    if two:
        cb = fig.colorbar(sc if sc is not None else plt.cm.ScalarMappable(norm=norm, cmap="viridis"), cax=cax)
        cb.set_label(metric.label() + " (ok runs)")
    what = f"{metric.name} over ({x.name}, {y.name})" if two else f"{metric.name} against {x.name}"
    data = {"axes": {"x": x.describe(), "y": yc.describe(), "colour": metric.describe() if two else None},
            "colour_range": [norm.vmin, norm.vmax] if two else None, "panels": panels}
    return fig, what, data


def view_slice(plt, size, ctx):
    params, metric, good, facets, colour = ctx["params"], ctx["metric"], ctx["good"], ctx["facets"], ctx["colour"]
    fig, axes = plt.subplots(len(facets), len(params), figsize=size, squeeze=False, sharey=True)
    text_colour = colour.scale == "category"
    if text_colour:
        import matplotlib.colors as mcolors
        palette = [mcolors.to_hex(plt.cm.tab10(i % 10)) for i in range(len(colour.categories))]
    else:
        norm = norm_for(colour.values[good], colour.scale == "log")
    panels, sc = [], None
    for i, (fv, rows) in enumerate(facets):
        g = rows & good
        for j, par in enumerate(params):
            ax = axes[i, j]
            xp = jitter(par, j)
            if text_colour:
                for k, cat in enumerate(colour.categories):
                    m = g & (colour.values == cat)
                    ax.scatter(xp[m], metric.pos[m], color=palette[k], s=16, zorder=2, edgecolors="none")
            else:
                sc = ax.scatter(xp[g], metric.pos[g], c=colour.pos[g], cmap="viridis", norm=norm, s=16,
                                zorder=2, edgecolors="none")
            f = rows & ~good
            draw_failed(ax, xp[f], metric.pos[f], ctx["status"][f], ctx["fail_order"], True)
            set_axis(ax, par, "x")
            if ctx["log"]:
                ax.set_yscale("log")
            ax.grid(alpha=0.3)
            if j == 0:
                ax.set_ylabel(metric.label() + (f"\n{ctx['facet']} = {fv}" if ctx["facet"] else ""))
            panels.append({"facet": fv, "param": par.name, "run_ids": ctx["run_ids"][rows],
                           "status": ctx["status"][rows], "x": par.values[rows], "y": metric.values[rows],
                           "colour": colour.values[rows]})
    if ctx["facet"]:
        for j in range(len(params)):
            for i in range(len(facets) - 1):
                axes[i, j].set_xlabel("")
    handles = failure_handles(ctx)
    if text_colour:
        from matplotlib.lines import Line2D
        handles = [Line2D([], [], ls="", marker="o", color=palette[k], label=f"{colour.name} = {c}")
                   for k, c in enumerate(colour.categories)] + handles
    cax = layout(fig, handles, not text_colour)
    if not text_colour:
        cb = fig.colorbar(sc if sc is not None else plt.cm.ScalarMappable(norm=norm, cmap="viridis"), cax=cax)
        cb.set_label("run id (run order)" if colour.name == "run_id" else colour.label() + " (ok runs)")
    data = {"params": [p.describe() for p in params], "colour": colour.describe(), "panels": panels}
    return fig, f"{metric.name} against each parameter", data


def axis_positions(col):
    """Positions 0..1 along a parallel axis and its ticks [(position, label)]."""
    import matplotlib.ticker as mticker
    if col.scale == "category":
        n = len(col.categories)
        pos = col.pos / (n - 1) if n > 1 else np.full(len(col.pos), 0.5)
        return pos, [(k / (n - 1) if n > 1 else 0.5, c) for k, c in enumerate(col.categories)]
    v = np.asarray(col.values, dtype=float)
    log = col.scale == "log"
    with np.errstate(all="ignore"):
        t = np.log10(v) if log else v
    fin = t[np.isfinite(t)]
    lo, hi = (float(fin.min()), float(fin.max())) if fin.size else (0.0, 1.0)
    span = hi - lo
    pos = (t - lo) / span if span > 0 else np.where(np.isfinite(t), 0.5, np.nan)
    if log:
        ticks = [10.0 ** e for e in range(int(np.ceil(lo - 1e-9)), int(np.floor(hi + 1e-9)) + 1)]
        tpos = [(np.log10(tv) - lo) / span if span > 0 else 0.5 for tv in ticks]
        return pos, [(p, f"{tv:g}") for p, tv in zip(tpos, ticks)]
    ticks = mticker.MaxNLocator(5).tick_values(lo, hi) if span > 0 else [lo]
    ticks = [tv for tv in ticks if lo - 1e-9 * abs(span) <= tv <= hi + 1e-9 * abs(span)]
    return pos, [((tv - lo) / span if span > 0 else 0.5, f"{tv:g}") for tv in ticks]


def view_parcoords(plt, size, ctx):
    from matplotlib.collections import LineCollection
    rows = ctx["facets"][0][1]
    cols = ctx["params"] + [ctx["metric"]]
    good = ctx["good"] & rows
    pos = np.column_stack([axis_positions(c)[0] for c in cols])
    fig, ax = plt.subplots(figsize=size)
    xs = np.arange(len(cols), dtype=float)
    counts = {}
    f = rows & ~ctx["good"]
    if f.any():
        segs = [np.column_stack([xs, pos[r]]) for r in np.flatnonzero(f)]
        ax.add_collection(LineCollection(segs, colors="0.55", linewidths=0.8, linestyles=(0, (3, 2)), zorder=1))
        counts["failed"] = [int(f.sum()), int(np.sum(~np.isfinite(pos[f, -1])))]
    metric = ctx["metric"]
    norm = norm_for(metric.values[good], ctx["log"])
    order = np.flatnonzero(good)
    order = order[np.argsort(-np.nan_to_num(metric.values[order], nan=np.inf), kind="stable")]  # low on top
    lc = LineCollection([np.column_stack([xs, pos[r]]) for r in order], cmap="viridis", norm=norm,
                        linewidths=1.0, alpha=0.75, zorder=2)
    lc.set_array(metric.values[order])
    ax.add_collection(lc)
    for k, c in enumerate(cols):
        ax.axvline(k, color="0.2", lw=0.8, zorder=3)
        for p, text in axis_positions(c)[1]:
            ax.plot([k - 0.03, k], [p, p], color="0.2", lw=0.8, zorder=3)
            ax.text(k - 0.05, p, text, ha="right", va="center", fontsize=7, zorder=4,
                    bbox=dict(facecolor="white", alpha=0.7, lw=0, pad=0.5))
    ax.set_xlim(-0.35, len(cols) - 0.8)
    ax.set_ylim(-0.04, 1.04)
    ax.set_yticks([])
    ax.set_xticks(xs, [c.label() + (" (log)" if c.scale == "log" else "") for c in cols], fontsize=8)
    for s in ax.spines.values():
        s.set_visible(False)
    handles = []
    if f.any():
        from matplotlib.lines import Line2D
        n, none = counts["failed"]
        statuses = ", ".join(s for s in ctx["fail_order"] if (ctx["status"][f] == s).any())
        handles.append(Line2D([], [], color="0.55", ls=(0, (3, 2)), label=f"failed runs ({n}: {statuses})"
                              + (f"; {none} without a {metric.name} stop before its axis" if none else "")))
    cax = layout(fig, handles, True)
    cb = fig.colorbar(lc, cax=cax)
    cb.set_label(metric.label() + " (ok runs)")
    data = {"axes": [c.describe() for c in cols], "run_ids": ctx["run_ids"][rows], "status": ctx["status"][rows],
            "values": {c.name: c.values[rows] for c in cols}, "colour": metric.values[rows],
            "colour_range": [norm.vmin, norm.vmax]}
    return fig, f"parallel coordinates of {len(cols) - 1} parameters and {metric.name}", data


def main(argv=None):
    args = parse_args(argv)
    try:
        res = ksread.open_results(args.file)
    except (OSError, ValueError) as e:
        fail(f"{args.file}: {e}")
    runs = res.runs(degrees=True)
    columns = list(runs.keys())
    if not len(runs):
        fail(f"{args.file}: no done runs yet: nothing to draw", 1)
    kinds = res.row_kinds()
    blocks = list(dict.fromkeys(runs["block"]))  # file order: first appearance in /runs
    if args.block is not None and args.block not in blocks:
        close = kswhere.did_you_mean(args.block, blocks)
        fail(f"--block {args.block}: no done runs of such a block" + (f"; did you mean '{close}'?" if close else "")
             + f"\nblocks: {', '.join(blocks)}")
    block = args.block or blocks[0]
    kind = kinds[np.flatnonzero(runs["block"] == block)[0]]
    inblock = (kinds == kind) if (args.facet == "block" and not args.block) else (runs["block"] == block)

    metrics = res.metrics(kind)
    meaning = res.kind_meaning(kind)
    metric_name = args.metric or next(iter(meaning.get("ranking", [])), metrics[0] if metrics else None)
    if metric_name not in metrics:
        close = kswhere.did_you_mean(str(metric_name), metrics)
        fail(f"--metric {metric_name}: not a metric of {kind} runs" + (f"; did you mean '{close}'?" if close else "")
             + f"\nmetrics: {', '.join(metrics)}")
    for name, what in ((args.x, "--x"), (args.y, "--y"), (args.colour, "--colour"), (args.facet, "--facet")):
        if name:
            check_column(name, columns, what)
    params_asked = [s.strip() for s in args.params.split(",") if s.strip()] if args.params else None
    for name in params_asked or []:
        check_column(name, columns, "--params")

    try:
        for note in kswhere.unheld_value_notes(runs, args.where):
            print(f"kinesweep.plot_runs: note: {note}", file=sys.stderr)
        rows = inblock & kswhere.select(runs, args.where, degrees=True)
    except kswhere.WhereError as e:
        fail(str(e))
    where_text = " and ".join(f"({w})" if "|" in w and len(args.where) > 1 else w for w in args.where)
    if not rows.any():
        fail(f"nothing to draw: no done run of block {block}" + (f" matches --where {where_text}" if args.where
                                                                 else ""), 1)

    def varies(c):
        v = runs[c][inblock]
        return len(set(v.tolist())) > 1 if v.dtype == object else len(np.unique(v)) > 1

    swept = [c for c in res.parameters(kind) if c != args.facet and varies(c)]
    params = params_asked or swept
    if args.view != "scatter" and not params:
        fail(f"block {block} sweeps no parameter: give the columns to plot with --params", 1)
    x_name = args.x or (swept[0] if swept else None)
    if args.view == "scatter" and not x_name:
        fail(f"block {block} sweeps no parameter: give the column on x with --x", 1)

    idx = np.flatnonzero(rows)
    status = runs["status"][idx]
    good = np.isin(status, meaning.get("good_statuses", []))
    known = meaning.get("statuses", [])
    failed_seen = [s for s in dict.fromkeys(status[~good])]
    fail_order = [s for s in known if s in failed_seen] + [s for s in failed_seen if s not in known]
    metric = make_col(runs, metric_name, idx, scale="log" if args.log else "linear")
    if metric.scale == "category":
        fail(f"--metric {metric_name}: a text column")
    facets = [(None, np.ones(len(idx), dtype=bool))]
    if args.facet:
        fcol = runs[args.facet][idx]
        values = list(dict.fromkeys(fcol.tolist() if fcol.dtype == object else fcol.tolist()))
        if fcol.dtype != object and len(values) > FACET_MAX:
            fail(f"--facet {args.facet}: {len(values)} distinct values; a facet column is text or has at most "
                 f"{FACET_MAX} values")
        facets = [(v if fcol.dtype == object else float(v), fcol == v) for v in values]
    ctx = {"metric": metric, "good": good, "status": status, "fail_order": fail_order, "facets": facets,
           "facet": args.facet, "run_ids": runs["run_id"][idx], "log": args.log}
    if args.view == "scatter":
        ctx["x"] = make_col(runs, x_name, idx)
        ctx["y"] = make_col(runs, args.y, idx) if args.y else None
    else:
        ctx["params"] = [make_col(runs, c, idx) for c in params]
        ctx["colour"] = make_col(runs, args.colour or "run_id", idx,
                                 scale=None if args.colour else "linear")
    if args.view == "parcoords" and args.facet:
        fail("--facet applies to the scatter and slice views")

    plt, size = ksplot.figure(args)
    draw = {"scatter": view_scatter, "slice": view_slice, "parcoords": view_parcoords}[args.view]
    fig, what, data = draw(plt, size, ctx)
    n_failed = int((~good).sum())
    blocks_text = f"block {block}" if not (args.facet == "block" and not args.block) else "every block"
    title = args.title or (f"{what} — {blocks_text}, {len(idx)} runs"
                           + (f" ({n_failed} failed)" if n_failed else "")
                           + (f", where {where_text}" if args.where else "")
                           + f"\n{os.path.basename(args.file)}")
    fig.suptitle(title, fontsize=10)
    return ksplot.finish(fig, args, f"runs_{args.view}_{metric_name}",
        {"file": args.file, "view": args.view, "block": block, "kind": kind, "metric": metric.describe(),
         "where": args.where, "facet": args.facet, "facets": [f for f, _ in facets], "n_runs": len(idx),
         "n_failed": n_failed, **data})


if __name__ == "__main__":
    sys.exit(main())
