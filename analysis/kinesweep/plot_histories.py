#!/usr/bin/python3
"""Joint torques (and q, q̇, q̈ on request) against time for chosen runs, as seed 000's Figures 12-32.

One row of panels per quantity, one column per joint, one line per run.

    python3 -m kinesweep.plot_histories results/thesis_table4.h5 --preset 1a,1c,1e
    python3 -m kinesweep.plot_histories results/thesis_table4.h5 --runs 0,2 --what tau,q,qd
"""
import argparse
import os
import sys

import numpy as np

from kinesweep import plotting as ksplot  # noqa: E402
from kinesweep import read as ksread  # noqa: E402

NAMES = {"tau": "τ", "q": "q", "qd": "q̇", "qdd": "q̈"}
MAX_COLS = 4  # panels per row of one array's components


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.plot_histories", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p)
    p.add_argument("--runs", help="run ids, comma-separated")
    p.add_argument("--preset", help="Table 4 cases (the preset column), comma-separated, e.g. 1a,1c,1e")
    p.add_argument("--what", default="tau", help="quantities, comma-separated: tau, q, qd, qdd (default %(default)s)")
    p.add_argument("--radians", action="store_true", help="plot angles in radians (default degrees)")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    res = ksread.open_results(args.file)
    runs = res.runs(degrees=True)
    ids = []
    if args.runs:
        ids += [int(x) for x in args.runs.split(",") if x.strip()]
    if args.preset:
        if "preset" not in runs:
            raise SystemExit(f"{args.file}: no preset column")
        for c in args.preset.split(","):
            m = np.nonzero(runs["preset"] == c.strip())[0]
            if not m.size:
                raise SystemExit(f"--preset {c}: no done run with that preset; presets: "
                                 f"{', '.join(sorted(set(runs['preset']) - {''}))}")
            ids.append(int(runs["run_id"][m[0]]))
    if not ids:
        # the first three trajectory runs with a history (an IK run's history has no time array)
        done = {int(r) for r in runs["run_id"]}
        ids = []
        for r in res.history_ids():
            if int(r) in done and "t" in res.history_arrays(int(r)):
                ids.append(int(r))
                if len(ids) == 3:
                    break
        if not ids:
            raise SystemExit(f"{args.file}: no trajectory run with a history (run the study with histories)")
    whats = [w.strip() for w in args.what.split(",") if w.strip()]
    hist = {}
    for r in ids:
        if not res.has_history(r):
            raise SystemExit(f"run {r} has no history in {args.file}")
        hist[r] = res.history(r, degrees=not args.radians)
        for w in whats:
            if w not in hist[r]:
                raise SystemExit(f"--what {w}: run {r} has no array {w!r}; arrays: {', '.join(hist[r])}")
        if "t" not in hist[r]:
            raise SystemExit(f"run {r} is not a trajectory run (no time array)")
    label = {}
    rid = list(runs["run_id"])
    rows = [rid.index(r) for r in ids if r in rid]
    # The parameters that tell the plotted runs apart (angles in degrees, as read).
    differ = [c for c in res.parameters("trajectory") if c in runs and c != "preset"
              and len({str(runs[c][i]) for i in rows}) > 1]
    for r in ids:
        i = rid.index(r) if r in rid else None
        pre = runs["preset"][i] if (i is not None and "preset" in runs and runs["preset"][i]) else ""
        what = [f"case {pre}"] if pre else [runs["block"][i]] if i is not None else []
        if i is not None and not pre:
            what += [f"{c} = {ksplot.fmt_num(runs[c][i]) if isinstance(runs[c][i], float) else runs[c][i]}"
                     f"{'°' if runs.units.get(c) == 'deg' else ''}" for c in differ]
        label[r] = f"run {r}" + (f" ({', '.join(what)})" if what else "")

    plt, size = ksplot.figure(args)
    # Each array's components in rows of at most MAX_COLS panels (a 7-joint arm: 4 + 3); the legend
    # in an empty panel slot when there is one.
    comps = [max(hist[r][w].shape[1] for r in ids) for w in whats]
    ncols = min(MAX_COLS, max(comps))
    first_row = np.cumsum([0] + [-(-c // ncols) for c in comps])
    fig, grid = plt.subplots(int(first_row[-1]), ncols, figsize=size, squeeze=False, sharex=True, constrained_layout=True)
    axes = [[grid[first_row[wi] + j // ncols][j % ncols] for j in range(c)] for wi, c in enumerate(comps)]
    used = {id(ax) for row in axes for ax in row}
    for row in grid:
        for ax in row:
            if id(ax) not in used:
                ax.set_visible(False)
    data = {}
    for r in ids:
        h = hist[r]
        t = h["t"][:, 0]
        data[r] = {"label": label[r], "t": t}
        for wi, w in enumerate(whats):
            units = [u.strip() for u in h.units[w].split(",")]
            for j in range(h[w].shape[1]):
                ax = axes[wi][j]
                ax.plot(t, h[w][:, j], lw=1.1, label=label[r])
                ax.set_title(f"{NAMES.get(w, w)}{j + 1}", fontsize=9)
                u = units[j] if len(units) == h[w].shape[1] else units[0]
                if j % ncols == 0:
                    ax.set_ylabel(f"{NAMES.get(w, w)} [{u}]")
                ax.grid(alpha=0.3)
            data[r][w] = h[w]
    for c in range(ncols):  # the lowest panel of each column shows the time axis
        column = [grid[r][c] for r in range(grid.shape[0]) if id(grid[r][c]) in used]
        if column:
            column[-1].set_xlabel("t [s]")
            column[-1].xaxis.set_tick_params(labelbottom=True)
    handles, labels = axes[0][0].get_legend_handles_labels()
    spare = [ax for row in grid for ax in row if id(ax) not in used]
    if spare:  # an empty panel slot holds the legend, clear of the data
        spare[-1].set_visible(True)
        spare[-1].axis("off")
        spare[-1].legend(handles, labels, loc="center", fontsize=7)
    else:
        axes[0][0].legend(fontsize=7, loc="best")
    title = args.title or (f"{', '.join(NAMES.get(w, w) for w in whats)} against time, "
                           f"{'runs ' + ', '.join(map(str, ids)) if differ else '; '.join(label[r] for r in ids)}"
                           f"\n{os.path.basename(args.file)}")
    fig.suptitle(title, fontsize=10)
    return ksplot.finish(fig, args, "histories", {"file": args.file, "runs": data, "panels": {
        "rows": int(first_row[-1]), "cols": ncols, "legend_apart": bool(spare)}})


if __name__ == "__main__":
    sys.exit(main())
