#!/usr/bin/python3
"""Heatmap of a landscape metric over two swept axes of a kinesweep results file.

Contour lines, the minimum marked and labelled, cells whose runs failed (unreachable start, singular,
diverged; IK failures) masked in their own colours with a legend, optional log colour scale, and the
thesis' optimum points overlaid (--thesis), an [[optimize]] block's evaluations, local paths and best
point overlaid (--optimization NAME, when its variables are the plotted axes). Dims other than --x/--y
are fixed (--fix AXIS=VALUE), reduced (--reduce min|mean over them; the title says which), or, when one
categorical dim remains (method), drawn as small multiples: one panel per value, one colour scale.
A log-spaced numeric axis (lambda from 1e-3 to 100) is drawn on a log scale; --log is the colour scale.
A grid with more cells along an axis than the picture has pixels across (its smaller side) is drawn in
blocks of s x s cells: each drawn cell is the min of its block's values (the mean with --reduce mean
and for the convergence fraction), or where none has a value its runs' most common failed status; the
title says so. The marked minimum, the colour scale's range, the mean convergence fraction and the
failed-cell counts in the legend come from the full grid; --print-data prints the full grid (z,
masked_status) and the drawn one (drawn: block, aggregate, x, y, z).

    python3 -m kinesweep.plot_landscape results/landscape_alpha_k.h5 --fix method=local_weighted --log --thesis
    python3 -m kinesweep.plot_landscape results/ik_basins.h5 --metric convergence --x q0_1 --y q0_2
    python3 -m kinesweep.plot_landscape results/optimize_polish.h5 --block alpha_k_1h --optimization 1h_polish --log
"""
import argparse
import os
import sys

import numpy as np

from kinesweep import plotting as ksplot  # noqa: E402
from kinesweep import read as ksread  # noqa: E402
from kinesweep.landscape_grid import MAX_PANELS, numeric_axes, pick_index, reduce_grid  # noqa: E402,F401

STATUS_COLOURS = ksread.STATUS_COLOURS


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.plot_landscape", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p)
    p.add_argument("--block", help="landscape (block) name (default: the first in file order with two swept "
                   "numeric axes)")
    p.add_argument("--metric", help="E, E_M, tau_inf, tau1_inf..tau3_inf, min_manipulability, max_tracking_error "
                   "(trajectory; default E), iterations, error, convergence (IK; default convergence = mean of "
                   "'converged' over the other dims)")
    p.add_argument("--x", help="axis on x (default: the first numeric swept axis)")
    p.add_argument("--y", help="axis on y (default: the next numeric swept axis)")
    p.add_argument("--fix", action="append", default=[], metavar="AXIS=VALUE",
                   help="hold another axis at VALUE (degrees for angles, a label for names); repeatable")
    p.add_argument("--reduce", choices=["min", "mean"],
                   help="reduce the dims neither plotted nor fixed by their min or mean (the title says so). "
                   "Without it they are faceted: one panel per value of one remaining categorical dim (up to "
                   f"{MAX_PANELS}, one colour scale); else exit 2 naming them. convergence is always the mean")
    p.add_argument("--log", action="store_true", help="logarithmic colour scale")
    p.add_argument("--vmin", type=float, help="lower end of the colour scale")
    p.add_argument("--vmax", type=float, help="upper end of the colour scale (larger values saturate)")
    p.add_argument("--levels", type=int, default=8, help="number of contour lines (0: none; default %(default)s)")
    p.add_argument("--thesis", action="store_true",
                   help="overlay seed 000's optimum points (Table 4 rows 1d-1h / 2d-2h) on an (alpha1A, k) plane")
    p.add_argument("--optimization", metavar="NAME",
                   help="overlay /optimizations/NAME: its evaluations (dots coloured by stage), the local stage's "
                   "paths (arrows start -> best) and the final best point; its variables must be the --x/--y axes")
    return p.parse_args(argv)


STAGE_COLOURS = {"sweep": "#ffffff", "global": "#ff9f1c", "local": "#2ec4f6"}


def optimization_overlay(res, name, xa, ya):
    """The optimisation's points in plot coordinates (x = xa's variable, y = ya's), or SystemExit when its
    variables are not the plotted axes."""
    names = res.optimizations()
    if name not in names:
        raise SystemExit(f"--optimization {name}: not in {res.path}; optimizations: {', '.join(names) or 'none'}")
    o = res.optimization(name, degrees=True)
    if xa.categorical or ya.categorical or sorted(o.variables) != sorted([xa.name, ya.name]):
        raise SystemExit(f"--optimization {name}: its variables ({', '.join(o.variables)}) are not the plotted axes "
                         f"({xa.name}, {ya.name}); pick them with --x/--y (and --fix/--block)")
    ix, iy = o.variable_index(xa.name), o.variable_index(ya.name)
    ev = o.evaluations
    return {"name": name, "objective": o.objective, "variables": o.variables, "units": o.units,
            "points": {"x": ev["x"][:, ix], "y": ev["x"][:, iy], "stage": list(ev["stage"]),
                       "objective": ev["objective"], "status": list(ev["status"])},
            "paths": [{"from": [f[ix], f[iy]], "to": [t[ix], t[iy]], "objective": v}
                      for f, t, v in zip(o.local["from"], o.local["to"], o.local["objective"])],
            "best": {"x": o.best["x"][ix], "y": o.best["x"][iy], "objective": o.best["objective"],
                     "status": o.best["status"], "stage": o.best["stage"]}}


def choose_block(res, block):
    """The named landscape, or the first in file order with two swept numeric axes to plot."""
    names = res.landscapes()
    if not names:
        raise SystemExit(f"plot_landscape: {res.path} holds no landscapes")
    if block:
        if block not in names:
            raise SystemExit(f"plot_landscape: no landscape {block!r}; landscapes: {', '.join(names)}")
        return block
    for b in names:
        if len(numeric_axes(res.landscape(b))) >= 2:
            return b
    axes = "; ".join(f"{b}: {', '.join(a.name for a in res.landscape(b).axes) or 'no axis'}" for b in names)
    raise SystemExit(f"plot_landscape: {res.path}: no landscape has two swept numeric axes to plot ({axes}); "
                     "a dimension of sampled points (LHS, zipped random draws, Saltelli) is not a grid axis: "
                     "python3 -m kinesweep.plot_runs draws such runs as points")


def block_method(res, ls, fixed):
    if "method" in fixed:
        return fixed["method"]
    runs = res.runs(columns=["block", "method"])
    m = set(runs["method"][runs["block"] == ls.block])
    return m.pop() if len(m) == 1 else None


def is_integer_metric(res, metric):
    """An integer column of /runs (iterations): its contours go on integers. A labelled text column
    (an enum over uint8) is not one."""
    if metric not in res.columns():
        return False
    d = res.f["runs"][metric]
    return d.dtype.kind in "iu" and ksread.enum_labels(d) is None


def main(argv=None):
    args = parse_args(argv)
    res = ksread.open_results(args.file)
    ls = res.landscape(choose_block(res, args.block), degrees=True)
    size = ksplot.figure_size(args)
    # A grid with more cells than the picture has pixels is drawn in blocks (landscape_grid); the
    # minimum, the colour scale's range and the counts come from the full grid.
    d = reduce_grid(ls, args, min(int(round(size[0] * args.dpi)), int(round(size[1] * args.dpi))),
                    keep_full=args.print_data)
    xa, ya, Z, CAT, metric = d["x"], d["y"], d["z"], d["cat"], d["metric"]
    unit = "" if metric == "convergence" else ls.units.get(metric, "")
    label = ls.label(metric) + (f" [{unit}]" if unit else "")
    xlog = not xa.categorical and ksplot.is_log_spaced(xa.values)
    ylog = not ya.categorical and ksplot.is_log_spaced(ya.values)

    from matplotlib import colormaps
    from matplotlib.colors import ListedColormap, LogNorm, Normalize
    from matplotlib import patheffects
    from matplotlib.patches import Patch
    n = Z.shape[0]
    ncols = min(n, 3)
    nrows = -(-n // ncols)
    fig = ksplot.agg_figure(size, constrained_layout=True)
    axs = fig.subplots(nrows, ncols, squeeze=False, sharex=True, sharey=True)
    for k in range(n, nrows * ncols):
        axs.flat[k].set_visible(False)
    xv = np.arange(len(xa.values)) if xa.categorical else xa.values
    yv = np.arange(len(ya.values)) if ya.categorical else ya.values
    dx, dy = d["centres"]
    # the cells as an image in a PNG on linear axes (drawn at the picture's pixels), else one
    # quadrilateral each (vector cells in SVG; log axes)
    image = not xlog and not ylog and not ksplot.output_path(args, "landscape").lower().endswith(".svg")
    any_finite = d["finite"]  # one colour scale for every panel
    vmin = args.vmin if args.vmin is not None else (d["vmin"] if any_finite else 0.0)
    vmax = args.vmax if args.vmax is not None else (d["vmax"] if any_finite else 1.0)
    if metric == "convergence":
        vmin, vmax = (0.0 if args.vmin is None else vmin), (1.0 if args.vmax is None else vmax)
    if args.log:
        vmin = max(vmin, d["pos"] if d["pos"] is not None else 1e-12)
        norm = LogNorm(vmin=vmin, vmax=max(vmax, vmin * 1.0001))
    else:
        norm = Normalize(vmin=vmin, vmax=vmax if vmax > vmin else vmin + 1)
    cmap = colormaps["viridis"].copy()
    cmap.set_bad((0, 0, 0, 0))
    levels = []
    if args.levels > 0 and any_finite and len(xv) > 2 and len(yv) > 2 and metric != "convergence":
        levels = ksplot.round_levels(norm.vmin, norm.vmax, args.levels, log=args.log,
                                     integer=is_integer_metric(res, metric))
    statuses = ls.statuses
    panels, thesis, opt = [], [], None
    if args.optimization:
        opt = optimization_overlay(res, args.optimization, xa, ya)
    for p in range(n):
        ax, z, cat = axs.flat[p], Z[p], CAT[p]
        has_values = d["best"][p] is not None
        mesh = ksplot.cells(ax, *d["edges"], np.ma.masked_invalid(z), image, cmap=cmap, norm=norm)
        # Failed cells in their own colours (counted over the full grid).
        handles = []
        counts = d["counts"][p]
        present = np.flatnonzero(counts).tolist()
        if present or d["no_run"][p]:
            colours = ["#ffffff"] * (len(statuses) + 1)
            for s in present:
                colours[s] = STATUS_COLOURS.get(statuses[s], "#999999")
                handles.append(Patch(facecolor=colours[s], edgecolor="0.3",
                                     label=f"{statuses[s]} ({int(counts[s])} cells)"))
            if d["no_run"][p]:
                handles.append(Patch(facecolor="#ffffff", edgecolor="0.3", label="no run"))
            c = np.where(cat == -2, len(statuses), cat).astype(float)
            ksplot.cells(ax, *d["edges"], np.ma.masked_less(c, 0), image, cmap=ListedColormap(colours),
                         vmin=-0.5, vmax=len(statuses) + 0.5)
        if len(levels) and has_values:
            cs = ax.contour(dx, dy, np.ma.masked_invalid(z), levels=levels, colors="white", linewidths=0.7, alpha=0.8)
            ax.clabel(cs, fmt=lambda v: f"{v:g}", fontsize=7, inline=True)
        # Minimum (the mean for the convergence fraction).
        best = None
        if metric == "convergence" and has_values:
            ax.plot([], [], ls="none", label=f"mean convergence fraction {float(d['sum'][p] / d['count'][p]):.0%}")
        elif has_values:
            v, i, j = d["best"][p]  # nanargmin's first minimum of the full grid
            best = {"value": v, "x": xa.values[j], "y": ya.values[i], "i": i, "j": j}
            xs = xa.labels[j] if xa.categorical else f"{ksplot.fmt_num(xa.values[j])}{'°' if xa.unit == 'deg' else ''}"
            ys = ya.labels[i] if ya.categorical else f"{ksplot.fmt_num(ya.values[i])}{'°' if ya.unit == 'deg' else ''}"
            ax.plot([xv[j]], [yv[i]], marker="*", ms=16, color="#ff3030", mec="white", mew=1.2, zorder=5, ls="none",
                    label=f"min {ksplot.fmt_num(v)}{(' ' + unit) if unit else ''} at {xa.name} = {xs}, "
                          f"{ya.name} = {ys}")
        # Thesis optimum (of the panel's method).
        if args.thesis and {xa.name, ya.name} == {"alpha1A", "k"}:
            m = d["panel_labels"][p] if d["facet"] == "method" else block_method(res, ls, d["fixed"])
            thesis += thesis_overlay(ax, m, metric, ls.label(metric), xa, patheffects)
        if opt is not None:
            optimization_draw(ax, opt, xa, ya, patheffects)
        for a, setticks, setlab, log, which in ((xa, ax.set_xticks, ax.set_xlabel, xlog, "x"),
                                                (ya, ax.set_yticks, ax.set_ylabel, ylog, "y")):
            if which == "x" and p + ncols < n:
                pass  # the panel below carries the x label
            elif which == "y" and p % ncols:
                pass
            else:
                setlab(ksplot.axis_label(a.name, a.unit))
            if a.categorical:
                setticks(np.arange(len(a.labels)), a.labels)
            elif log:
                ksplot.log_axis(ax, which)
        lines = ax.get_legend_handles_labels()
        ax.legend(handles=lines[0] + handles, labels=lines[1] + [h.get_label() for h in handles], loc="upper right",
                  fontsize=8 if n == 1 else 7, framealpha=0.85)
        if d["facet"]:
            ax.set_title(f"{d['facet']} = {d['panel_labels'][p]}", fontsize=9)
        panels.append({"label": d["panel_labels"][p], "z": d["full_z"][p] if args.print_data else None, "best": best,
                       "cat": d["full_cat"][p] if args.print_data else None})
    cb = fig.colorbar(mesh, ax=list(axs.flat[:n]), extend="max" if args.vmax is not None else "neither")
    cb.set_label(label)
    if args.log:
        ksplot.log_colorbar_ticks(cb, norm.vmin, norm.vmax)
    what = ls.label(metric)
    sub = "; ".join(d["notes"] + ([f"one panel per {d['facet']}"] if d["facet"] else []))
    title = args.title or (f"{what} over {xa.name} × {ya.name} — block {ls.block}{(' (' + sub + ')') if sub else ''}"
                           f"\n{os.path.basename(args.file)}{' (log colour scale)' if args.log else ''}")
    (fig.suptitle if n > 1 else axs.flat[0].set_title)(ksplot.fit_title(title, fig, 10), fontsize=10)
    for pan in panels:  # the failed cells' statuses by name: printed data only (a list per cell)
        cat = pan.pop("cat")
        if args.print_data:
            pan["masked_status"] = [[(statuses[c] if c >= 0 else None) for c in row] for row in cat]
    first = panels[0]
    # Saved first: the colour bar's ticks are read as the saving drew them (no draw of its own).
    out = ksplot.save(fig, args, f"landscape_{ls.block}_{metric}", layout_once=True)
    if not args.print_data:
        print(out)
        return 0
    cticks = [t for t in cb.ax.yaxis.get_majorticklocs() if norm.vmin <= t <= norm.vmax]
    clabels = [t.get_text() for t in cb.ax.yaxis.get_majorticklabels() if t.get_text()]
    ksplot.print_json(
        {"file": args.file, "block": ls.block, "metric": metric, "unit": unit,
         "reduce": d["reduce"], "fixed": d["fixed"], "facet": d["facet"], "levels": levels,
         "x": {"name": xa.name, "unit": xa.unit, "values": xa.values, "labels": xa.labels, "log": xlog},
         "y": {"name": ya.name, "unit": ya.unit, "values": ya.values, "labels": ya.labels, "log": ylog},
         "z": first["z"], "masked_status": first.get("masked_status"), "best": first["best"], "panels": panels,
         "draw_stride": d["stride"],
         "drawn": {"block": d["block"], "aggregate": "mean" if metric == "convergence" or args.reduce == "mean" else "min",
                   "x": dx, "y": dy, "z": Z[0]},
         "thesis": thesis, "optimization": opt, "xscale": axs.flat[0].get_xscale(),
         "yscale": axs.flat[0].get_yscale(), "colorbar": {"ticks": cticks, "labels": clabels}, "output": out})
    return 0


def thesis_overlay(ax, method, metric, label, xa, patheffects):
    """Seed 000's optimum points of `method` on an (alpha1A, k) panel (`label`: how the plot names
    `metric`); returns what it drew."""
    opt = ksread.THESIS_OPTIMA.get(method)
    if opt is None:
        print(f"plot_landscape: --thesis: no thesis optimum for method {method!r} (fix method=local_weighted "
              "or local_unweighted)", file=sys.stderr)
        return []
    out = []
    for case in [opt["global"]] + opt["partial"]:
        _, kk, alpha, e, taus = ksread.THESIS_TABLE4[case]
        tv = {"E": e, "tau_inf": max(taus), "tau1_inf": taus[0], "tau2_inf": taus[1], "tau3_inf": taus[2]}.get(metric)
        tl = (f"{label} = {tv} Nm" if tv is not None else f"E = {e} Nm")
        px, py = (alpha, kk) if xa.name == "alpha1A" else (kk, alpha)
        glob = case == opt["global"]
        ax.plot([px], [py], ls="none", marker="P" if glob else "D", ms=11 if glob else 7,
                mfc="#ff66ff" if glob else "none", mec="#ff66ff", mew=1.8, zorder=6,
                label=(f"thesis optimum {case}: {tl}" if glob else None))
        ax.annotate(f"thesis {case}", (px, py), xytext=(6, 6 if glob else -12), textcoords="offset points",
                    color="#ff66ff", fontsize=8, fontweight="bold",
                    path_effects=[patheffects.withStroke(linewidth=2.5, foreground="black")])
        out.append({"case": case, "x": px, "y": py, "E": e, "value": tv})
    ax.plot([], [], ls="none", marker="D", mfc="none", mec="#ff66ff", label="thesis partial optima")
    return out


def optimization_draw(ax, opt, xa, ya, patheffects):
    """An optimisation's evaluations, local paths and best point, kept inside the landscape's extent
    (the bounds may be wider than the grid)."""
    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    pt = opt["points"]
    stages = np.array(pt["stage"], dtype=object)
    for st in dict.fromkeys(pt["stage"]):
        m = stages == st
        ax.scatter(np.asarray(pt["x"])[m], np.asarray(pt["y"])[m], s=9, c=STAGE_COLOURS.get(st, "#cccccc"),
                   edgecolors="black", linewidths=0.3, zorder=7, alpha=0.85,
                   label=f"{opt['name']}: {st} evaluations ({int(m.sum())})")
    for path in opt["paths"]:
        ax.annotate("", xy=path["to"], xytext=path["from"], zorder=8,
                    arrowprops=dict(arrowstyle="-|>", color="#2ec4f6", lw=1.4, mutation_scale=10,
                                    path_effects=[patheffects.withStroke(linewidth=2.6, foreground="black")]))
    if opt["paths"]:
        ax.plot([], [], color="#2ec4f6", lw=1.4, label=f"{opt['name']}: local paths (start → best)")
    b = opt["best"]
    bu = ["°" if u == "deg" else "" for u in (opt["units"][opt["variables"].index(xa.name)],
                                             opt["units"][opt["variables"].index(ya.name)])]
    ax.plot([b["x"]], [b["y"]], marker="o", ms=10, mfc="none", mec="#ff3030", mew=2.2, zorder=9, ls="none",
            label=f"{opt['name']} best: {opt['objective']} = {ksplot.fmt_num(b['objective'])} at "
                  f"{xa.name} = {ksplot.fmt_num(b['x'])}{bu[0]}, {ya.name} = {ksplot.fmt_num(b['y'])}{bu[1]}")
    ax.annotate(f"{opt['name']} best {ksplot.fmt_num(b['objective'])}", (b["x"], b["y"]), xytext=(8, -14),
                textcoords="offset points", color="#ff3030", fontsize=8, fontweight="bold", zorder=9,
                path_effects=[patheffects.withStroke(linewidth=2.5, foreground="white")])
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)


if __name__ == "__main__":
    sys.exit(main())
