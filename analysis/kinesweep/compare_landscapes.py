#!/usr/bin/python3
"""One landscape metric from several results files side by side, on one colour scale: e.g. E over
(alpha1A, k) for the planar 3R, 4R and 5R arms (studies/redundancy_*.toml). Each panel marks its
minimum; cells without a value (a failed run) are left blank. Dims other than --x/--y must be fixed
(--fix AXIS=VALUE), never reduced silently.

    python3 -m kinesweep.compare_landscapes results/redundancy_3r.h5 results/redundancy_4r.h5 \\
        results/redundancy_5r.h5 --fix method=local_weighted -o redundancy.png
"""
import argparse
import os
import sys

import numpy as np

from kinesweep import plotting as ksplot  # noqa: E402
from kinesweep import read as ksread  # noqa: E402


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.compare_landscapes", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="+", help="results files (.h5) written by `kinesweep run`")
    p.add_argument("-o", "--output", default="compare_landscapes.png", help="output picture (.png or .svg)")
    p.add_argument("--svg", action="store_true", help="write SVG instead of PNG")
    p.add_argument("--size", default=None, help="picture size in pixels WxH (default: 420 per panel x 420)")
    p.add_argument("--dpi", type=float, default=100.0, help="dots per inch (default %(default)s)")
    p.add_argument("--title", help="replace the figure title")
    p.add_argument("--print-data", action="store_true", help="also print the minima as JSON on stdout")
    p.add_argument("--block", help="landscape (block) name (default: each file's first in file order with "
                   "the --x and --y axes)")
    p.add_argument("--metric", help="landscape metric (default: the metric the first file's runs are ranked by, E)")
    p.add_argument("--x", default="alpha1A", help="axis on x (default %(default)s)")
    p.add_argument("--y", default="k", help="axis on y (default %(default)s)")
    p.add_argument("--fix", action="append", default=[], metavar="AXIS=VALUE",
                   help="fix another axis (a label, or the nearest number); required for every other axis")
    p.add_argument("--labels", help="panel titles, comma-separated (default: each file's study description)")
    return p.parse_args(argv)


def panel(land, args, fixed):
    """The metric over (x, y) of one landscape, the other dims fixed: (x values, y values, 2-D array)."""
    args.metric = args.metric or land.objective
    if args.metric not in land.metrics:
        raise SystemExit(f"{land.block}: no metric {args.metric!r}; metrics: {', '.join(land.metrics)}")
    data = land.metrics[args.metric]
    index = []
    for i, a in enumerate(land.axes):
        if a.name in (args.x, args.y):
            index.append(slice(None))
            continue
        if a.name not in fixed:
            if len(a.values) == 1:
                index.append(0)
                continue
            raise SystemExit(f"{land.block}: axis {a.name!r} is neither plotted nor fixed; "
                             f"expected --fix {a.name}=VALUE")
        v = fixed[a.name]
        if a.categorical:
            if v not in a.labels:
                raise SystemExit(f"--fix {a.name}={v}: expected one of {', '.join(a.labels)}")
            index.append(a.labels.index(v))
        else:
            index.append(int(np.argmin(np.abs(a.values - float(v)))))
    sub = data[tuple(index)]
    ax_names = [a.name for a in land.axes if a.name in (args.x, args.y)]
    if ax_names != [args.x, args.y]:
        sub = sub.T
    return land.axis(args.x).values, land.axis(args.y).values, sub


def main(argv=None):
    args = parse_args(argv)
    fixed = dict(f.split("=", 1) for f in args.fix)
    panels = []
    for path in args.files:
        with ksread.open_results(path) as res:
            block = args.block or next((b for b in res.landscapes() if {args.x, args.y} <=
                                        {a.name for a in res.landscape(b).axes}), None)
            if block is None:
                raise SystemExit(f"{path}: no landscape over ({args.x}, {args.y}); landscapes: "
                                 f"{', '.join(res.landscapes()) or 'none'}")
            land = res.landscape(block, degrees=True)
            x, y, z = panel(land, args, fixed)
            label = res.f.attrs.get("study_name", os.path.basename(path))
            label = label.decode() if isinstance(label, bytes) else str(label)
            panels.append((label, x, y, z, land.axis(args.x).unit, land.axis(args.y).unit, land.units[args.metric]))
    if args.labels:
        names = args.labels.split(",")
        if len(names) != len(panels):
            raise SystemExit(f"--labels has {len(names)} names for {len(panels)} files")
        panels = [(n,) + p[1:] for n, p in zip(names, panels)]
    if args.size is None:
        args.size = f"{420 * len(panels) + 80}x440"
    plt, figsize = ksplot.figure(args)
    fig, axes = plt.subplots(1, len(panels), figsize=figsize, squeeze=False, sharey=True, constrained_layout=True)
    finite = np.concatenate([p[3][np.isfinite(p[3])].ravel() for p in panels])
    if finite.size == 0:
        raise SystemExit(f"no finite {args.metric} in any file")
    lo, hi = np.percentile(finite, 1), np.percentile(finite, 95)  # a few whiplash runs would flatten the rest
    minima = []
    for ax, (label, x, y, z, xu, yu, mu) in zip(axes[0], panels):
        img = ax.pcolormesh(x, y, z.T, shading="nearest", cmap="viridis", vmin=lo, vmax=hi)
        if np.isfinite(z).any():
            i, j = np.unravel_index(np.nanargmin(z), z.shape)
            ax.plot(x[i], y[j], marker="*", color="red", markersize=12, markeredgecolor="white")
            ax.annotate(f"{args.metric} = {z[i, j]:.4g} {mu}\n{args.x} = {x[i]:.3g}, {args.y} = {y[j]:.3g}",
                        (x[i], y[j]), textcoords="offset points", xytext=(6, 8), fontsize=8, color="white",
                        bbox=dict(boxstyle="round", fc="black", alpha=0.5))
            minima.append({"file": label, args.metric: z[i, j], args.x: x[i], args.y: y[j]})
        ax.set_title(label, fontsize=10)
        ax.set_xlabel(ksplot.axis_label(args.x, xu))
    axes[0][0].set_ylabel(ksplot.axis_label(args.y, panels[0][5]))
    fig.colorbar(img, ax=axes[0].tolist(), label=f"{args.metric} [{panels[0][6]}] (colour clipped at the 95th percentile)")
    fixed_text = ", ".join(f"{k} = {v}" for k, v in fixed.items())
    fig.suptitle(args.title or f"{args.metric} over ({args.x}, {args.y})" + (f", {fixed_text}" if fixed_text else ""))
    out = args.output
    if args.svg and not out.lower().endswith(".svg"):
        out = os.path.splitext(out)[0] + ".svg"
    if os.path.dirname(out):
        os.makedirs(os.path.dirname(out), exist_ok=True)
    fig.savefig(out, dpi=args.dpi, format="svg" if out.lower().endswith(".svg") else "png")
    if args.print_data:
        ksplot.print_json({"minima": minima, "output": out})
    else:
        print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
