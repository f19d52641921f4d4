#!/usr/bin/python3
"""Basins of attraction of the IK methods over a grid of initial guesses.

One panel per method (or per value of the block's other dim): each cell is coloured by the solution
its run converged to, shaded by its iteration count (full colour = few iterations, pale = many), and
failed runs (singular, max_iter, cycle, diverged, stalled) are drawn in their own colours.

    /usr/bin/python3 analysis/plot_basins.py results/ik_basins.h5 -o basins.png
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ksplot  # noqa: E402
import ksread  # noqa: E402

SOLUTION_COLOURS = ["#1f77b4", "#2ca02c", "#ff7f0e", "#17becf", "#bcbd22", "#8c564b"]
FAIL_COLOURS = {"stalled": "#8c510a", "singular": "#7b3294", "max_iter": "#d7191c", "cycle": "#f781bf",
                "diverged": "#111111", "unsupported": "#555555", "no_solution": "#999999", "out_of_limits": "#fdae61",
                "converged, other solution": "#bbbbbb"}


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p, default_size="1200x500")
    p.add_argument("--block", help="IK landscape (block) name (default: the first IK landscape)")
    p.add_argument("--x", default="q0_1", help="initial-guess axis on x (default %(default)s)")
    p.add_argument("--y", default="q0_2", help="initial-guess axis on y (default %(default)s)")
    p.add_argument("--panels", help="axis giving one panel per value (default: the remaining axis, e.g. method)")
    p.add_argument("--fix", action="append", default=[], metavar="AXIS=VALUE",
                   help="hold any further axis at VALUE (degrees for angles, a label for names)")
    return p.parse_args(argv)


def wrap_deg(a):
    return (np.asarray(a) + 180.0) % 360.0 - 180.0


# max-norm distance [rad or m] under which two converged final iterates are the same solution
CLUSTER_TOLERANCE = 1e-3


def joint_text(runs, qcols, units, mask):
    """The median final iterate of the runs in `mask`, joint by joint with its unit."""
    parts = []
    for c, u in zip(qcols, units):
        v = np.median(runs[c][mask])
        j = c.rsplit("_", 1)[1]
        if u == "rad":
            parts.append(f"θ{j} = {wrap_deg(v * ksread.RAD2DEG):.1f}°")
        elif u == "mm":  # the SCARA's prismatic joint
            parts.append(f"d = {v:.1f} mm")
        else:
            parts.append(f"q{j} = {v:.3g} {u}")
    return ", ".join(parts)


def main(argv=None):
    args = parse_args(argv)
    res = ksread.open_results(args.file)
    blocks = args.block and [args.block] or [b for b in res.landscapes() if res.landscape(b).kind == "ik"]
    if not blocks:
        raise SystemExit(f"{args.file}: no IK landscape (a study with an ik block and a grid of q0_1, q0_2)")
    ls = res.landscape(blocks[0], degrees=True)
    if ls.kind != "ik":
        raise SystemExit(f"landscape {ls.block} is not an IK block")
    names = [a.name for a in ls.axes]
    for n in (args.x, args.y):
        if n not in names:
            raise SystemExit(f"axis {n}: not in landscape {ls.block}; axes: {', '.join(names)}")
    fixed = dict(f.split("=", 1) for f in args.fix)
    others = [n for n in names if n not in (args.x, args.y) and n not in fixed]
    panel_axis = args.panels or (others[0] if others else None)
    if len([n for n in others if n != panel_axis]) > 0:
        raise SystemExit(f"more dims than x, y and panels: fix them with --fix ({', '.join(others)})")
    from plot_landscape import pick_index
    index = [slice(None)] * len(names)
    for k, v in fixed.items():
        index[names.index(k)] = pick_index(ls.axis(k), v)
    kept = [n for n in names if n not in fixed]
    order = ([kept.index(panel_axis)] if panel_axis else []) + [kept.index(args.y), kept.index(args.x)]

    def arrange(g):
        g = np.transpose(g[tuple(index)], order)
        return g if panel_axis else g[None]

    status, sol, its = (arrange(ls.metrics[m]) for m in ("status_code", "solution", "iterations"))
    pa = ls.axis(panel_axis) if panel_axis else None
    panel_labels = (pa.labels if pa.categorical else [f"{panel_axis} = {ksplot.fmt_num(v)}" for v in pa.values]) \
        if pa else [""]
    xa, ya = ls.axis(args.x), ls.axis(args.y)
    statuses = ls.statuses

    # The final iterates: as many joints as the robot has (q_final_1 .. q_final_n), with their units.
    qcols = sorted((c for c in res.columns() if c.startswith("q_final_")), key=lambda c: int(c.rsplit("_", 1)[1]))
    runs = res.runs(columns=["run_id", "block", "solution", "status", "problem"] + qcols, done_only=False)
    sel = (runs["block"] == ls.block) & runs["done"]
    scara = bool(np.any(runs["problem"][sel] == "scara"))
    # "rad or mm": the third joint is the SCARA's d in mm, else an angle
    qunits = [("mm" if scara else "rad") if runs.units[c].startswith("rad or") else runs.units[c] for c in qcols]
    clustered = False
    continuum = {}
    if not np.any((runs["solution"] >= 0) & sel):
        # No closed form (a chain robot): name the distinct solutions by clustering the converged final
        # iterates (ksread.cluster_solutions, tolerance CLUSTER_TOLERANCE), in run order, and grid them:
        # a grid block's runs are its cells in row-major order of the landscape's axes.
        rows = np.flatnonzero(runs["block"] == ls.block)
        conv = runs["done"][rows] & (runs["status"][rows] == "converged")
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
        m = sel & (runs["solution"] == s) & (runs["status"] == "converged")
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
    fig, axes = plt.subplots(1, len(panel_labels), figsize=size, squeeze=False, sharey=True)
    fig.subplots_adjust(left=0.06, right=0.9, bottom=0.24, top=0.85, wspace=0.06)
    axes = axes[0]
    used = {}
    data_panels = []
    ex = lambda v: [v[0] - (v[1] - v[0]) / 2, v[-1] + (v[-1] - v[-2]) / 2] if len(v) > 1 else [v[0] - .5, v[0] + .5]
    extent = ex(xa.values) + ex(ya.values)
    for p, ax in enumerate(axes):
        st, so, it = status[p], sol[p], its[p]
        rgb = np.ones(st.shape + (3,))
        cls = np.empty(st.shape, dtype=object)
        for i in range(st.shape[0]):
            for j in range(st.shape[1]):
                code = int(st[i, j]) if np.isfinite(st[i, j]) else -1
                name = statuses[code] if code >= 0 else "no run"
                if name == "converged" and np.isfinite(so[i, j]):
                    s = int(so[i, j])
                    base = np.array(mcolors.to_rgb(SOLUTION_COLOURS[s % len(SOLUTION_COLOURS)]))
                    n = it[i, j]
                    f = shade_norm(max(n, 1)) if np.isfinite(n) else 0.0
                    rgb[i, j] = base * (1 - 0.75 * f) + 0.75 * f  # pale = many iterations
                    cls[i, j] = s
                    used[("sol", s)] = used.get(("sol", s), 0) + 1
                else:
                    key = "converged, other solution" if name == "converged" else name
                    rgb[i, j] = mcolors.to_rgb(FAIL_COLOURS.get(key, "#ffffff"))
                    cls[i, j] = key
                    used[("fail", key)] = used.get(("fail", key), 0) + 1
        ax.imshow(rgb, origin="lower", extent=extent, aspect="auto", interpolation="nearest")
        ax.set_title(panel_labels[p], fontsize=10)
        ax.set_xlabel(ksplot.axis_label(xa.name, xa.unit))
        if p == 0:
            ax.set_ylabel(ksplot.axis_label(ya.name, ya.unit))
        conv = float(np.mean(st == 0)) if st.size else 0.0
        ax.text(0.02, 0.02, f"converged {conv:.0%}", transform=ax.transAxes, fontsize=8,
                bbox=dict(facecolor="white", alpha=0.8, lw=0))
        data_panels.append({"label": panel_labels[p], "class": cls.tolist(), "iterations": it,
                            "converged_fraction": conv})
    from matplotlib.patches import Patch
    handles = [Patch(color=SOLUTION_COLOURS[s % len(SOLUTION_COLOURS)], label=sol_label.get(s, f"solution {s}"))
               for (k, s) in sorted(k for k in used if k[0] == "sol")]
    handles += [Patch(color=FAIL_COLOURS.get(s, "#ffffff"), label=f"{s} ({used[(k, s)]} cells)", ec="0.4")
                for (k, s) in sorted(k for k in used if k[0] == "fail")]
    fig.legend(handles=handles, loc="lower center", ncol=min(3, len(handles)), fontsize=8, frameon=False)
    sm = plt.cm.ScalarMappable(norm=shade_norm, cmap=mcolors.LinearSegmentedColormap.from_list(
        "shade", [(0.25, 0.25, 0.25), (0.8125, 0.8125, 0.8125)]))
    cb = fig.colorbar(sm, cax=fig.add_axes([0.915, 0.24, 0.015, 0.61]))
    cb.set_label("iterations to converge (shade: pale = many)")
    title = args.title or (f"IK basins of attraction over ({xa.name}, {ya.name}) — block {ls.block}"
                           + (f" ({', '.join(f'{k} = {v}' for k, v in fixed.items())})" if fixed else "")
                           + f"\n{os.path.basename(args.file)}")
    fig.suptitle(title, fontsize=11)
    return ksplot.finish(fig, args, f"basins_{ls.block}",
        {"file": args.file, "block": ls.block, "panel_axis": panel_axis,
         "x": {"name": xa.name, "unit": xa.unit, "values": xa.values},
         "y": {"name": ya.name, "unit": ya.unit, "values": ya.values},
         "panels": data_panels, "solutions": sol_label, "clustered": clustered, "continuum": continuum})


if __name__ == "__main__":
    sys.exit(main())
