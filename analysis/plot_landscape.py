#!/usr/bin/python3
"""Heatmap of a landscape metric over two swept axes of a kinesweep results file.

Contour lines, the minimum marked and labelled, cells whose runs failed (unreachable start, singular,
diverged; IK failures) masked in their own colours with a legend, optional log colour scale, and the
thesis' optimum points overlaid (--thesis), an [[optimize]] block's evaluations, local paths and best
point overlaid (--optimization NAME, when its variables are the plotted axes). Dims other than --x/--y
are fixed (--fix AXIS=VALUE) or reduced (--reduce min|mean over them; the title says which).

    /usr/bin/python3 analysis/plot_landscape.py results/landscape_alpha_k.h5 --fix method=local_weighted --log --thesis
    /usr/bin/python3 analysis/plot_landscape.py results/ik_basins.h5 --metric convergence --x q0_1 --y q0_2
    /usr/bin/python3 analysis/plot_landscape.py results/optimize_polish.h5 --block alpha_k_1h --optimization 1h_polish --log
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ksplot  # noqa: E402
import ksread  # noqa: E402

METRIC_LABELS = {"E": "E (mean ‖τ‖)", "E_M": "E_M (mean ‖τ‖ in M⁻¹ norm)", "tau_inf": "‖τ‖∞",
                 "tau1_inf": "‖τ1‖∞", "tau2_inf": "‖τ2‖∞", "tau3_inf": "‖τ3‖∞",
                 "iterations": "iterations", "convergence": "convergence fraction", "error": "final ‖F‖",
                 "min_manipulability": "min manipulability", "max_tracking_error": "max tracking error"}
STATUS_COLOURS = {"unreachable_start": "#b0b0b0", "singular": "#7b3294", "diverged": "#202020",
                  "stalled": "#e08214", "max_iter": "#d7191c", "cycle": "#f4a582",
                  "unsupported": "#6a6a6a", "no_solution": "#b0b0b0", "out_of_limits": "#fdae61"}


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p)
    p.add_argument("--block", help="landscape (block) name (default: the first in the file)")
    p.add_argument("--metric", help="E, E_M, tau_inf, tau1_inf..tau3_inf, min_manipulability, max_tracking_error "
                   "(trajectory; default E), iterations, error, convergence (IK; default convergence = mean of "
                   "'converged' over the other dims)")
    p.add_argument("--x", help="axis on x (default: the first numeric swept axis)")
    p.add_argument("--y", help="axis on y (default: the next numeric swept axis)")
    p.add_argument("--fix", action="append", default=[], metavar="AXIS=VALUE",
                   help="hold another axis at VALUE (degrees for angles, a label for names); repeatable")
    p.add_argument("--reduce", choices=["min", "mean"], default="min",
                   help="how the remaining dims are reduced (default %(default)s; convergence always uses mean)")
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


def reduce_grid(ls, args):
    """Returns dict with x/y axes, z (ny x nx), status (ny x nx: -1 value, else status index), notes."""
    names = [a.name for a in ls.axes]
    metric = args.metric or ("convergence" if ls.kind == "ik" else "E")
    if metric != "convergence" and metric not in ls.metrics:
        raise SystemExit(f"--metric {metric}: not in landscape {ls.block}; metrics: "
                         f"{', '.join(list(ls.metrics) + (['convergence'] if ls.kind == 'ik' else []))}")
    numeric = [a.name for a in ls.axes if not a.categorical and len(a.values) > 1]
    fixed = {}
    for f in args.fix:
        if "=" not in f:
            raise SystemExit(f"--fix {f}: expected AXIS=VALUE")
        k, v = f.split("=", 1)
        if k not in names:
            raise SystemExit(f"--fix {k}: no such axis; axes: {', '.join(names)}")
        fixed[k] = v
    free = [n for n in numeric if n not in fixed]
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

    def arrange(g):
        g = g[tuple(index)]
        kept = [n for n in names if n not in fixed]
        order = [kept.index(y), kept.index(x)] + [kept.index(n) for n in rest]
        g = np.transpose(g, order)
        return g.reshape(g.shape[0], g.shape[1], -1)

    status = arrange(ls.metrics["status_code"])
    good = 0  # ok / converged
    if metric == "convergence":
        z = np.nanmean(arrange(ls.metrics["converged"]), axis=2)
        cat = np.full(z.shape, -1)
        if rest:
            notes.append(f"mean over {', '.join(rest)}")
        reduce = "mean"
    else:
        vals = np.where(status == good, arrange(ls.metrics[metric]), np.nan)
        with np.errstate(all="ignore"):
            import warnings
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                z = np.nanmin(vals, axis=2) if args.reduce == "min" else np.nanmean(vals, axis=2)
        cat = np.full(z.shape, -1)
        none = np.all(np.isnan(vals), axis=2)
        for i, j in zip(*np.nonzero(none)):
            s = status[i, j][np.isfinite(status[i, j])].astype(int)
            s = s[s != good]
            cat[i, j] = np.bincount(s).argmax() if s.size else -2  # -2: no run at all
        if rest:
            notes.append(f"{args.reduce} over {', '.join(rest)}")
        reduce = args.reduce
    return {"metric": metric, "x": ls.axis(x), "y": ls.axis(y), "z": z, "cat": cat, "notes": notes,
            "reduce": reduce if rest else None, "fixed": fixed}


def block_method(res, ls, fixed):
    if "method" in fixed:
        return fixed["method"]
    runs = res.runs(columns=["block", "method"])
    m = set(runs["method"][runs["block"] == ls.block])
    return m.pop() if len(m) == 1 else None


def edges(v):
    v = np.asarray(v, dtype=float)
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def main(argv=None):
    args = parse_args(argv)
    res = ksread.open_results(args.file)
    try:
        ls = res.landscape(args.block, degrees=True)
    except KeyError as e:
        raise SystemExit(f"plot_landscape: {e.args[0]}")
    d = reduce_grid(ls, args)
    xa, ya, z, cat, metric = d["x"], d["y"], d["z"], d["cat"], d["metric"]
    unit = "" if metric == "convergence" else ls.units.get(metric, "")
    label = METRIC_LABELS.get(metric, metric) + (f" [{unit}]" if unit else "")

    plt, size = ksplot.figure(args)
    from matplotlib.colors import ListedColormap, LogNorm, Normalize
    from matplotlib import patheffects
    from matplotlib.patches import Patch
    fig, ax = plt.subplots(figsize=size, constrained_layout=True)
    xv = np.arange(len(xa.values)) if xa.categorical else xa.values
    yv = np.arange(len(ya.values)) if ya.categorical else ya.values
    X, Y = np.meshgrid(edges(xv), edges(yv))
    finite = z[np.isfinite(z)]
    vmin = args.vmin if args.vmin is not None else (finite.min() if finite.size else 0.0)
    vmax = args.vmax if args.vmax is not None else (finite.max() if finite.size else 1.0)
    if metric == "convergence":
        vmin, vmax = (0.0 if args.vmin is None else vmin), (1.0 if args.vmax is None else vmax)
    if args.log:
        pos = finite[finite > 0]
        vmin = max(vmin, pos.min() if pos.size else 1e-12)
        norm = LogNorm(vmin=vmin, vmax=max(vmax, vmin * 1.0001))
    else:
        norm = Normalize(vmin=vmin, vmax=vmax if vmax > vmin else vmin + 1)
    cmap = plt.get_cmap("viridis").copy()
    cmap.set_bad((0, 0, 0, 0))
    mesh = ax.pcolormesh(X, Y, np.ma.masked_invalid(z), cmap=cmap, norm=norm, shading="flat")
    cb = fig.colorbar(mesh, ax=ax, extend="max" if args.vmax is not None else "neither")
    cb.set_label(label)
    # Failed cells in their own colours.
    handles = []
    statuses = ls.statuses
    present = sorted(set(cat[cat >= 0].ravel().tolist()))
    if present or (cat == -2).any():
        colours = ["#ffffff"] * (len(statuses) + 1)
        for s in present:
            colours[s] = STATUS_COLOURS.get(statuses[s], "#999999")
            n = int((cat == s).sum())
            handles.append(Patch(facecolor=colours[s], edgecolor="0.3", label=f"{statuses[s]} ({n} cells)"))
        if (cat == -2).any():
            colours[-1] = "#ffffff"
            handles.append(Patch(facecolor="#ffffff", edgecolor="0.3", label="no run"))
        c = np.where(cat == -2, len(statuses), cat).astype(float)
        ax.pcolormesh(X, Y, np.ma.masked_less(c, 0), cmap=ListedColormap(colours),
                      vmin=-0.5, vmax=len(statuses) + 0.5, shading="flat")
    # Contours.
    if args.levels > 0 and finite.size and len(xv) > 2 and len(yv) > 2 and metric != "convergence":
        if args.log:
            levels = np.geomspace(norm.vmin, norm.vmax, args.levels + 2)[1:-1]
        else:
            levels = np.linspace(norm.vmin, norm.vmax, args.levels + 2)[1:-1]
        cs = ax.contour(xv, yv, np.ma.masked_invalid(z), levels=levels, colors="white", linewidths=0.7, alpha=0.8)
        ax.clabel(cs, fmt=lambda v: f"{v:.0f}" if abs(v) >= 100 else f"{v:.3g}", fontsize=7, inline=True)
    # Minimum (maximum for the convergence fraction).
    best = None
    if metric == "convergence" and finite.size:
        ax.plot([], [], ls="none", label=f"mean convergence fraction {np.nanmean(z):.0%}")
    elif finite.size:
        i, j = np.unravel_index(np.nanargmin(z), z.shape)
        bx, by = xv[j], yv[i]
        best = {"value": z[i, j], "x": xa.values[j], "y": ya.values[i], "i": int(i), "j": int(j)}
        word = "min"
        xs = xa.labels[j] if xa.categorical else f"{ksplot.fmt_num(xa.values[j])}{'°' if xa.unit == 'deg' else ''}"
        ys = ya.labels[i] if ya.categorical else f"{ksplot.fmt_num(ya.values[i])}{'°' if ya.unit == 'deg' else ''}"
        ax.plot([bx], [by], marker="*", ms=16, color="#ff3030", mec="white", mew=1.2, zorder=5, ls="none",
                label=f"{word} {ksplot.fmt_num(z[i, j])}{(' ' + unit) if unit else ''} at {xa.name} = {xs}, {ya.name} = {ys}")
    # Thesis optimum.
    thesis = []
    if args.thesis and {xa.name, ya.name} == {"alpha1A", "k"}:
        m = block_method(res, ls, d["fixed"])
        opt = ksread.THESIS_OPTIMA.get(m)
        if opt is None:
            print(f"plot_landscape: --thesis: no thesis optimum for method {m!r} (fix method=local_weighted "
                  "or local_unweighted)", file=sys.stderr)
        else:
            for case in [opt["global"]] + opt["partial"]:
                _, kk, alpha, e, taus = ksread.THESIS_TABLE4[case]
                tv = {"E": e, "tau_inf": max(taus), "tau1_inf": taus[0], "tau2_inf": taus[1],
                      "tau3_inf": taus[2]}.get(metric)
                tl = (f"{METRIC_LABELS.get(metric, metric)} = {tv} Nm" if tv is not None else f"E = {e} Nm")
                px, py = (alpha, kk) if xa.name == "alpha1A" else (kk, alpha)
                glob = case == opt["global"]
                ax.plot([px], [py], ls="none", marker="P" if glob else "D", ms=11 if glob else 7,
                        mfc="#ff66ff" if glob else "none", mec="#ff66ff", mew=1.8, zorder=6,
                        label=(f"thesis optimum {case}: {tl}" if glob else None))
                ax.annotate(f"thesis {case}", (px, py), xytext=(6, 6 if glob else -12), textcoords="offset points",
                            color="#ff66ff", fontsize=8, fontweight="bold",
                            path_effects=[patheffects.withStroke(linewidth=2.5, foreground="black")])
                thesis.append({"case": case, "x": px, "y": py, "E": e, "value": tv})
            ax.plot([], [], ls="none", marker="D", mfc="none", mec="#ff66ff", label="thesis partial optima")
    # Optimisation overlay (kept inside the landscape's extent: the bounds may be wider than the grid).
    opt = None
    if args.optimization:
        opt = optimization_overlay(res, args.optimization, xa, ya)
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
    for a, setlim, setticks, setlab in ((xa, ax.set_xlim, ax.set_xticks, ax.set_xlabel),
                                        (ya, ax.set_ylim, ax.set_yticks, ax.set_ylabel)):
        setlab(ksplot.axis_label(a.name, a.unit))
        if a.categorical:
            setticks(np.arange(len(a.labels)), a.labels)
    lines = ax.get_legend_handles_labels()
    ax.legend(handles=lines[0] + handles, labels=lines[1] + [h.get_label() for h in handles], loc="upper right",
              fontsize=8, framealpha=0.85)
    what = "convergence fraction" if metric == "convergence" else METRIC_LABELS.get(metric, metric)
    sub = "; ".join(d["notes"])
    title = args.title or (f"{what} over {xa.name} × {ya.name} — block {ls.block}{(' (' + sub + ')') if sub else ''}"
                           f"\n{os.path.basename(args.file)}{' (log colour scale)' if args.log else ''}")
    ax.set_title(title, fontsize=10)
    return ksplot.finish(fig, args, f"landscape_{ls.block}_{metric}",
        {"file": args.file, "block": ls.block, "metric": metric, "unit": unit,
         "reduce": d["reduce"], "fixed": d["fixed"],
         "x": {"name": xa.name, "unit": xa.unit, "values": xa.values, "labels": xa.labels},
         "y": {"name": ya.name, "unit": ya.unit, "values": ya.values, "labels": ya.labels},
         "z": z, "masked_status": [[(ls.statuses[c] if c >= 0 else None) for c in row] for row in cat],
         "best": best, "thesis": thesis, "optimization": opt})


if __name__ == "__main__":
    sys.exit(main())
