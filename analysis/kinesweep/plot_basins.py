#!/usr/bin/python3
"""Basins of attraction of the IK methods over a grid of initial guesses.

One panel per method (or per value of the block's other dim; a second one, e.g. lambda, gives rows of
panels): each cell is coloured by the solution its run converged to, shaded by its iteration count
(full colour = few iterations, pale = many), and failed runs (singular, max_iter, cycle, diverged,
stalled) are drawn in their own colours. Solutions are named by their joints in the file's units
(angles in degrees, prismatic joints in mm or m). A log-spaced axis is drawn on a log scale.

    python3 -m kinesweep.plot_basins results/ik_basins.h5 -o basins.png
"""
import argparse
import os
import sys

import numpy as np

from kinesweep import plotting as ksplot  # noqa: E402
from kinesweep import read as ksread  # noqa: E402

DEFAULT_SIZE = "1200x500"  # one row of panels; more rows get more height
MAX_ROWS = 6  # rows of panels: one per value of a second remaining dim
SOLUTION_COLOURS = ["#1f77b4", "#2ca02c", "#ff7f0e", "#17becf", "#bcbd22", "#8c564b"]
# The failed statuses in the colours of every plot and the report (kinesweep.kinds.STATUS_COLOURS).
FAIL_COLOURS = dict(ksread.STATUS_COLOURS, **{"converged, other solution": ksread.OTHER_SOLUTION_COLOUR})


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.plot_basins", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p, default_size=DEFAULT_SIZE)
    p.add_argument("--block", help="IK landscape (block) name (default: the first in file order with two swept initial-guess axes)")
    p.add_argument("--x", help="initial-guess axis on x (default: the block's first swept q0_ axis, e.g. q0_1)")
    p.add_argument("--y", help="initial-guess axis on y (default: its next swept q0_ axis, e.g. q0_2)")
    p.add_argument("--panels", help="axis giving one column of panels per value (default: the first remaining axis, "
                   f"e.g. method); a second remaining axis (up to {MAX_ROWS} values, e.g. lambda) gives the rows")
    p.add_argument("--fix", action="append", default=[], metavar="AXIS=VALUE",
                   help="hold any further axis at VALUE (degrees for angles, a label for names)")
    return p.parse_args(argv)


def wrap_deg(a):
    return (np.asarray(a) + 180.0) % 360.0 - 180.0


# max-norm distance [rad or m] under which two converged final iterates are the same solution
CLUSTER_TOLERANCE = 1e-3


def joint_text(runs, qcols, units, mask):
    """The median final iterate of the runs in `mask`, joint by joint in its own unit (angles in degrees,
    lengths in the file's mm or m)."""
    parts = []
    for c, u in zip(qcols, units):
        v = np.median(runs[c][mask])
        sym = ksplot.joint_symbol(c, u)
        if u == "rad":
            parts.append(f"{sym} = {wrap_deg(v * ksread.RAD2DEG):.1f}°")
        elif u in ("mm", "m"):
            parts.append(f"{sym} = {v:.4g} {u}")
        else:
            parts.append(f"{sym} = {v:.3g}" + (f" {u}" if u else ""))
    return ", ".join(parts)


def joint_units(res, runs, qcols, sel):
    """Each final-iterate column's unit for the selected rows: the /runs unit attribute, where one reading
    "rad or mm" (joint 3: the SCARA's prismatic d in mm, an angle for the other problems) is resolved by
    the rows' problem and the unit of the matching initial-guess column."""
    problems = set(runs["problem"][sel]) if "problem" in runs else set()
    units = []
    for c in qcols:
        u = runs.units[c]
        if " or " in u:
            options = [x.strip() for x in u.split(" or ")]
            length = next((x for x in options if x in ("mm", "m")), "mm")
            u = length if problems == {"scara"} else next((x for x in options if x in ("rad", "deg")), "rad")
        units.append(u)
    return units


def xy_axes(ls, args):
    """--x and --y, else the landscape's first two swept initial-guess axes (q0_1, q0_2)."""
    starts = [a.name for a in ls.axes if a.name.startswith("q0_") and not a.categorical and len(a.values) > 1]
    x = args.x or next((n for n in starts if n != args.y), None)
    y = args.y or next((n for n in starts if n != x), None)
    return x, y


def plottable(ls, args):
    """Why the landscape can't be drawn as basins ("" when it can)."""
    names = [a.name for a in ls.axes]
    if ls.kind != "ik":
        return f"landscape {ls.block} is not an IK block"
    x, y = xy_axes(ls, args)
    if x is None or y is None:
        return f"landscape {ls.block} has not two swept initial-guess axes (axes: {', '.join(names) or 'none'})"
    missing = [n for n in (x, y) if n not in names]
    if missing:
        return f"landscape {ls.block} has no axis {', '.join(missing)} (axes: {', '.join(names) or 'none'})"
    return ""


def choose_block(res, args):
    """--block, else the first IK landscape in file order that has the --x and --y axes."""
    names = res.landscapes()
    if args.block:
        if args.block not in names:
            raise SystemExit(f"plot_basins: no landscape {args.block!r}; landscapes: {', '.join(names) or 'none'}")
        why = plottable(res.landscape(args.block), args)
        if why:
            raise SystemExit(f"plot_basins: {why}")
        return args.block
    reasons = []
    for b in names:
        why = plottable(res.landscape(b), args)
        if not why:
            return b
        reasons.append(why)
    raise SystemExit(f"plot_basins: {args.file}: no IK landscape over two initial-guess axes to plot (a study with "
                     f"an ik block and a grid of initial guesses){': ' + '; '.join(reasons) if reasons else ''}")


def main(argv=None):
    args = parse_args(argv)
    res = ksread.open_results(args.file)
    ls = res.landscape(choose_block(res, args), degrees=True)
    args.x, args.y = xy_axes(ls, args)
    names = [a.name for a in ls.axes]
    fixed = {}
    for f in args.fix:
        if "=" not in f or f.split("=", 1)[0] not in names:
            raise SystemExit(f"--fix {f}: expected AXIS=VALUE with AXIS one of {', '.join(names)}")
        k, v = f.split("=", 1)
        fixed[k] = v
    others = [n for n in names if n not in (args.x, args.y) and n not in fixed]
    if args.panels and args.panels not in others:
        raise SystemExit(f"--panels {args.panels}: not a remaining axis; remaining: {', '.join(others) or 'none'}")
    panel_axis = args.panels or (others[0] if others else None)
    row_axis = next((n for n in others if n != panel_axis), None)
    extra = [n for n in others if n not in (panel_axis, row_axis)]
    if extra or (row_axis and len(ls.axis(row_axis).values) > MAX_ROWS):
        raise SystemExit(f"plot_basins: block {ls.block}: more dims than x, y, panels and rows "
                         f"({', '.join(others)}): hold some with --fix AXIS=VALUE")
    from kinesweep.plot_landscape import pick_index
    index = [slice(None)] * len(names)
    for k, v in fixed.items():
        index[names.index(k)] = pick_index(ls.axis(k), v)
    kept = [n for n in names if n not in fixed]
    order = [kept.index(n) for n in (row_axis, panel_axis) if n] + [kept.index(args.y), kept.index(args.x)]

    # x and y in increasing order (a random axis is stored in draw order)
    xa, ya = ls.axis(args.x), ls.axis(args.y)
    xo, yo = np.argsort(xa.values, kind="stable"), np.argsort(ya.values, kind="stable")
    xa, ya = ksread.Axis(xa.name, xa.unit, xa.values[xo]), ksread.Axis(ya.name, ya.unit, ya.values[yo])

    def arrange(g):  # -> rows x panels x ny x nx
        g = np.transpose(g[tuple(index)], order)
        g = g.reshape((g.shape[0] if row_axis else 1, g.shape[1 if row_axis else 0] if panel_axis else 1)
                      + g.shape[-2:])
        return g[:, :, yo][:, :, :, xo]

    status, sol, its = (arrange(ls.metrics[m]) for m in ("status_code", "solution", "iterations"))
    def value_labels(name):
        if not name:
            return [""]
        a = ls.axis(name)
        sym = ksplot.axis_label(name, "").split(" ")[0]
        return list(a.labels) if a.categorical else [f"{sym} = {ksplot.fmt_num(v)}{' ' + a.unit if a.unit else ''}"
                                                      for v in a.values]
    panel_labels, row_labels = value_labels(panel_axis), value_labels(row_axis)
    statuses = ls.statuses

    # The final iterates: as many joints as the robot has (q_final_1 .. q_final_n), with their units.
    qcols = sorted((c for c in res.columns() if c.startswith("q_final_")), key=lambda c: int(c.rsplit("_", 1)[1]))
    runs = res.runs(columns=["run_id", "block", "solution", "status", "problem"] + qcols, done_only=False)
    good = res.kind_meaning(ls.kind)["good_statuses"]  # ik: converged
    is_good = np.isin(runs["status"], good)
    sel = (runs["block"] == ls.block) & runs["done"]
    qunits = joint_units(res, runs, qcols, sel)
    clustered = False
    continuum = {}
    if not np.any((runs["solution"] >= 0) & sel):
        # No closed form (a chain robot): name the distinct solutions by clustering the converged final
        # iterates (ksread.cluster_solutions, tolerance CLUSTER_TOLERANCE), in run order, and grid them:
        # a grid block's runs are its cells in row-major order of the landscape's axes.
        rows = np.flatnonzero(runs["block"] == ls.block)
        conv = runs["done"][rows] & is_good[rows]
        q = np.column_stack([runs[c][rows] for c in qcols])
        q[~conv] = np.nan
        revolute = [u == "rad" for u in qunits]
        labels = ksread.cluster_solutions(q, revolute, CLUSTER_TOLERANCE)
        if labels.max(initial=-1) + 1 > len(SOLUTION_COLOURS):
            # A continuum (a redundant problem): name the solutions by the joints whose final values
            # take a few distinct values over the converged runs (e.g. an S-R-S arm's elbow angle).
            discrete = [j for j in range(q.shape[1])
                        if ksread.cluster_solutions(q[:, [j]], [revolute[j]], CLUSTER_TOLERANCE).max(initial=-1) + 1
                        <= len(SOLUTION_COLOURS)]
            continuum["discrete"] = [qcols[j] for j in discrete]
            continuum["postures"] = int(labels.max(initial=-1) + 1)
            labels = (ksread.cluster_solutions(q[:, discrete], [revolute[j] for j in discrete], CLUSTER_TOLERANCE)
                      if discrete else np.where(np.isfinite(q[:, 0]), 0, -1))
            qcols = [qcols[j] for j in discrete] or qcols[:0]
            qunits = [qunits[j] for j in discrete]
        labels = labels.astype(float)
        labels[labels < 0] = np.nan
        shape = ls.metrics["solution"].shape
        if labels.size == int(np.prod(shape)):
            runs["solution"] = runs["solution"].astype(float)
            runs["solution"][rows] = labels
            sol = arrange(labels.reshape(shape))
            clustered = True
    sol_ids = sorted(int(s) for s in np.unique(sol[np.isfinite(sol)]))
    sol_label = {}
    for s in sol_ids:
        m = sel & (runs["solution"] == s) & is_good
        text = joint_text(runs, qcols, qunits, m) if m.any() and qcols else ""
        sol_label[s] = f"solution {s}" + (": " + text if text else "")
        if continuum:
            sol_label[s] = (f"{text}: {continuum['postures']} distinct postures in all (a continuum)" if text
                            else f"converged: a continuum of {continuum['postures']} distinct postures")
    if len(sol_ids) > len(SOLUTION_COLOURS):  # a continuum (redundant problem): too many to tell apart
        sol_label = {s: sol_label[s] for s in sol_ids[:len(SOLUTION_COLOURS)]}

    import matplotlib.colors as mcolors
    finite_its = its[np.isfinite(its) & (status == 0)]
    it_max = max(2.0, float(finite_its.max()) if finite_its.size else 2.0)
    shade_norm = mcolors.LogNorm(vmin=1, vmax=it_max)

    plt, size = ksplot.figure(args)
    nrows, ncols = len(row_labels), len(panel_labels)
    if nrows > 1 and args.size == DEFAULT_SIZE:  # room for the rows of panels
        args.size = f"{min(1600, 300 * ncols + 200)}x{min(1800, 230 * nrows + 220)}"
        plt, size = ksplot.figure(args)
    fig, axes = plt.subplots(nrows, ncols, figsize=size, squeeze=False, sharex=True, sharey=True)
    h_in = size[1]
    fig.subplots_adjust(left=0.08 if nrows > 1 else 0.06, right=0.85, bottom=min(0.3, 1.2 / h_in),
                        top=1 - min(0.2, 0.8 / h_in), wspace=0.06, hspace=0.25 if nrows > 1 else 0.2)
    xlog = not xa.categorical and ksplot.is_log_spaced(xa.values)
    ylog = not ya.categorical and ksplot.is_log_spaced(ya.values)
    xe, ye = ksplot.cell_edges(xa.values, xlog), ksplot.cell_edges(ya.values, ylog)
    image = not xlog and not ylog and not ksplot.output_path(args, f"basins_{ls.block}").lower().endswith(".svg")
    used = {}
    data_panels = []
    for r in range(nrows):
        for p in range(ncols):
            ax = axes[r][p]
            st, so, it = status[r, p], sol[r, p], its[r, p]
            rgb = np.ones(st.shape + (3,))
            cls = np.empty(st.shape, dtype=object)
            for i in range(st.shape[0]):
                for j in range(st.shape[1]):
                    code = int(st[i, j]) if np.isfinite(st[i, j]) else -1
                    name = statuses[code] if code >= 0 else "no run"
                    if name in good and np.isfinite(so[i, j]):
                        s = int(so[i, j])
                        base = np.array(mcolors.to_rgb(SOLUTION_COLOURS[s % len(SOLUTION_COLOURS)]))
                        n = it[i, j]
                        f = shade_norm(max(n, 1)) if np.isfinite(n) else 0.0
                        rgb[i, j] = base * (1 - 0.75 * f) + 0.75 * f  # pale = many iterations
                        cls[i, j] = s
                        used[("sol", s)] = used.get(("sol", s), 0) + 1
                    else:
                        key = name + ", other solution" if name in good else name
                        rgb[i, j] = mcolors.to_rgb(FAIL_COLOURS.get(key, "#ffffff"))
                        cls[i, j] = key
                        used[("fail", key)] = used.get(("fail", key), 0) + 1
            # The cells' colours as indices into their palette, drawn as cells of any width (a
            # log-spaced axis): one image in a PNG on linear axes, else a quadrilateral per cell.
            palette, idx = np.unique(rgb.reshape(-1, 3), axis=0, return_inverse=True)
            ksplot.cells(ax, xe, ye, idx.reshape(st.shape), image, cmap=mcolors.ListedColormap(palette),
                         vmin=-0.5, vmax=len(palette) - 0.5)
            if xlog:
                ksplot.log_axis(ax, "x")
            if ylog:
                ksplot.log_axis(ax, "y")
            label = ", ".join(x for x in (panel_labels[p], row_labels[r]) if x)
            ax.set_title(label, fontsize=10 if nrows == 1 else 8)
            if r == nrows - 1:
                ax.set_xlabel(ksplot.axis_label(xa.name, xa.unit))
            if p == 0:
                ax.set_ylabel(ksplot.axis_label(ya.name, ya.unit))
            conv = float(np.mean(st == 0)) if st.size else 0.0
            ax.text(0.02, 0.02, f"converged {conv:.0%}", transform=ax.transAxes, fontsize=8 if nrows == 1 else 7,
                    bbox=dict(facecolor="white", alpha=0.8, lw=0))
            data_panels.append({"label": label, "class": cls.tolist(), "iterations": it,
                                "converged_fraction": conv})
    from matplotlib.patches import Patch
    handles = [Patch(color=SOLUTION_COLOURS[s % len(SOLUTION_COLOURS)], label=sol_label.get(s, f"solution {s}"))
               for (k, s) in sorted(k for k in used if k[0] == "sol")]
    handles += [Patch(color=FAIL_COLOURS.get(s, "#ffffff"), label=f"{s} ({used[(k, s)]} cells)", ec="0.4")
                for (k, s) in sorted(k for k in used if k[0] == "fail")]
    # long entries (a solution's joint values) one a line, so that none runs off the figure; the
    # panels' bottom leaves the legend's lines free
    ncol = 1 if max((len(h.get_label()) for h in handles), default=0) > 40 else min(3, max(1, len(handles)))
    lines = -(-len(handles) // ncol)
    fig.subplots_adjust(bottom=min(0.45, (0.75 + 0.17 * lines) / h_in))
    fig.legend(handles=handles, loc="lower center", ncol=ncol, fontsize=8, frameon=False)
    sm = plt.cm.ScalarMappable(norm=shade_norm, cmap=mcolors.LinearSegmentedColormap.from_list(
        "shade", [(0.25, 0.25, 0.25), (0.8125, 0.8125, 0.8125)]))
    pos0, pos1 = axes[0][-1].get_position(), axes[-1][-1].get_position()
    cb = fig.colorbar(sm, cax=fig.add_axes([0.87, pos1.y0, 0.015, pos0.y1 - pos1.y0]))
    cb.set_label("iterations to converge (shade: pale = many)")
    ksplot.log_colorbar_ticks(cb, shade_norm.vmin, shade_norm.vmax)
    title = args.title or (f"IK basins of attraction over ({xa.name}, {ya.name}) — block {ls.block}"
                           + (f" ({', '.join(f'{k} = {v}' for k, v in fixed.items())})" if fixed else "")
                           + f"\n{os.path.basename(args.file)}")
    fig.suptitle(title, fontsize=11)
    return ksplot.finish(fig, args, f"basins_{ls.block}",
        {"file": args.file, "block": ls.block, "panel_axis": panel_axis,
         "x": {"name": xa.name, "unit": xa.unit, "values": xa.values},
         "y": {"name": ya.name, "unit": ya.unit, "values": ya.values},
         "panels": data_panels, "solutions": sol_label, "units": dict(zip(qcols, qunits)),
         "xscale": axes[0][0].get_xscale(), "yscale": axes[0][0].get_yscale(), "rows": row_axis, "clustered": clustered, "continuum": continuum})


if __name__ == "__main__":
    sys.exit(main())
