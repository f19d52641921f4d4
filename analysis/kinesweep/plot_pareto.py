#!/usr/bin/python3
"""The Pareto front of 2 or 3 metrics over a results file's runs (kinesweep.pareto; the front of
`kinesweep query FILE --pareto M1,M2[:max][,M3]`).

2 metrics: the good runs off the front faded, the front's runs as points joined by the step line that
bounds the region they dominate. 3 metrics: a 3-D scatter, the front highlighted. Each metric is
minimised unless written METRIC:max; runs of a failed status and runs without a value are left out
(the title counts them). Angles are shown in degrees.

    python3 -m kinesweep.plot_pareto results/study.h5 --metrics torque_sq_integral,min_manipulability:max
    python3 -m kinesweep.plot_pareto results/study.h5 --metrics E,tau_inf,min_manipulability:max -w "k<0.5"
"""
import argparse
import os
import sys

import numpy as np

from kinesweep import pareto as kspareto
from kinesweep import plotting as ksplot
from kinesweep import read as ksread
from kinesweep import where as kswhere

FRONT_COLOUR = "#d62728"
FADED = "#b8b8b8"


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.plot_pareto", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p, default_size="800x600")
    p.add_argument("--metrics", "--pareto", dest="metrics", required=True,
                   help="2 or 3 metrics, comma-separated, each COL, COL:min (default) or COL:max")
    p.add_argument("--where", "-w", action="append", default=[], metavar="EXPR",
                   help="keep the rows where EXPR holds (repeatable; `kinesweep query --where` syntax)")
    p.add_argument("--log", action="store_true", help="log scales on the metric axes")
    return p.parse_args(kswhere.where_argv(sys.argv[1:] if argv is None else argv))


def fail(msg, code=2):
    print(f"kinesweep.plot_pareto: {msg}", file=sys.stderr)
    raise SystemExit(code)


def step_line(front, senses):
    """The boundary of the region the 2-D front dominates: its points from the best first metric to
    the worst, each held until the next one's first metric (a post step)."""
    order = np.argsort(front[:, 0] if senses[0] == "min" else -front[:, 0], kind="stable")
    return front[order]


def label(runs, name):
    return ksplot.axis_label(runs.display_names.get(name, name), runs.units.get(name, ""))


def main(argv=None):
    args = parse_args(argv)
    try:
        res = ksread.open_results(args.file)
    except (OSError, ValueError) as e:
        fail(f"{args.file}: {e}")
    try:
        runs, rows, good, on, parsed = kspareto.front_of_runs(res, args.metrics, args.where)
    except (kspareto.ParetoError, kswhere.WhereError) as e:
        fail(str(e))
    names, senses = [n for n, _ in parsed], [s for _, s in parsed]
    values = kspareto.metric_values(runs, names)
    usable = rows & good & ~np.isnan(values).any(axis=1)
    if not on.any():
        fail("nothing to draw: no good run with a value of every metric"
             + (f" matches --where {' and '.join(args.where)}" if args.where else ""), 1)
    off = usable & ~on
    plt, size = ksplot.figure(args)
    fig = plt.figure(figsize=size)
    front = values[on]
    if len(names) == 2:
        ax = fig.add_subplot(1, 1, 1)
        ax.scatter(values[off, 0], values[off, 1], s=14, color=FADED, alpha=0.5, label=f"dominated ({int(off.sum())})")
        line = step_line(front, senses)
        ax.plot(line[:, 0], line[:, 1], drawstyle="steps-post", color=FRONT_COLOUR, lw=1.5)
        ax.scatter(front[:, 0], front[:, 1], s=30, color=FRONT_COLOUR, zorder=3, label=f"front ({int(on.sum())})")
        ax.set_xlabel(f"{label(runs, names[0])} ({senses[0]})")
        ax.set_ylabel(f"{label(runs, names[1])} ({senses[1]})")
        if args.log:
            ax.set_xscale("log"), ax.set_yscale("log")
        ax.grid(alpha=0.3)
    else:
        ax = fig.add_subplot(1, 1, 1, projection="3d")
        ax.scatter(values[off, 0], values[off, 1], values[off, 2], s=8, color=FADED, alpha=0.35,
                   label=f"dominated ({int(off.sum())})")
        ax.scatter(front[:, 0], front[:, 1], front[:, 2], s=30, color=FRONT_COLOUR, depthshade=False,
                   label=f"front ({int(on.sum())})")
        ax.set_xlabel(f"{label(runs, names[0])} ({senses[0]})", fontsize=8)
        ax.set_ylabel(f"{label(runs, names[1])} ({senses[1]})", fontsize=8)
        ax.set_zlabel(f"{label(runs, names[2])} ({senses[2]})", fontsize=8)
    ax.legend(loc="best", fontsize=8)
    failed = int((rows & ~good).sum())
    no_value = int((rows & good & np.isnan(values).any(axis=1)).sum())
    title = args.title or (f"Pareto front of {', '.join(f'{n} ({s})' for n, s in parsed)}\n{int(on.sum())} of "
                           f"{int(usable.sum())} good runs on it" + (f"; {failed} of a failed status" if failed else "")
                           + (f"; {no_value} without a value" if no_value else "")
                           + (f"; where {' and '.join(args.where)}" if args.where else "")
                           + f"\n{os.path.basename(args.file)}")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    ids = runs["run_id"][on]
    return ksplot.finish(fig, args, "pareto_" + "_".join(names),
                         {"file": args.file, "metrics": names, "senses": senses, "where": args.where,
                          "front_run_ids": ids, "front": front, "n_dominated": int(off.sum()),
                          "n_failed": failed, "n_no_value": no_value})


if __name__ == "__main__":
    sys.exit(main())
