#!/usr/bin/python3
"""‖F_k‖ against iteration (log scale) per IK method and λ, from the runs' iteration histories.

By default one line per (method, lambda) present among the IK runs with a history: the first such
run (lowest id); --start Q1,Q2 picks the runs whose initial guess (degrees) is nearest instead, and
--runs lists run ids explicitly. Each line's label names its run, method, λ and start; runs that share
a method and λ get a colour each.

    /usr/bin/python3 analysis/plot_convergence.py results/ik_scara.h5 --start 60,45
"""
import argparse
import os
import sys

import numpy as np

from kinesweep import plotting as ksplot  # noqa: E402
from kinesweep import read as ksread  # noqa: E402

LAMBDA_METHODS = {"lm", "lm_adaptive"}


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p)
    p.add_argument("--runs", help="run ids, comma-separated")
    p.add_argument("--start", help="initial guess q0_1,q0_2 in degrees: per (method, lambda) the nearest run")
    p.add_argument("--methods", help="only these methods, comma-separated")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    res = ksread.open_results(args.file)
    need = ["run_id", "block", "method", "lambda", "q0_1", "q0_2", "status", "iterations"]
    missing = [c for c in need if c not in res.columns()]
    if missing:
        raise SystemExit(f"{args.file}: not an IK study (no column {', '.join(missing)})")
    runs = res.runs(columns=need, degrees=True)
    ik = res.row_kinds() == "ik"  # from the columns' kinds attributes
    if args.methods:
        ik &= np.isin(runs["method"], [m.strip() for m in args.methods.split(",")])
    if args.runs:
        ids = [int(x) for x in args.runs.split(",")]
    else:
        groups = {}
        for i in np.nonzero(ik)[0]:
            m = runs["method"][i]
            key = (m, float(runs["lambda"][i]) if m in LAMBDA_METHODS else None)
            groups.setdefault(key, []).append(i)
        ids = []
        have = set(res.history_ids().tolist())
        for key, rows in groups.items():
            rows = [i for i in rows if int(runs["run_id"][i]) in have]
            if not rows:
                continue
            if args.start:
                q1, q2 = (float(v) for v in args.start.split(","))
                d = [(runs["q0_1"][i] - q1) ** 2 + (runs["q0_2"][i] - q2) ** 2 for i in rows]
                rows = [rows[int(np.argmin(d))]]
            ids.append(int(runs["run_id"][rows[0]]))
    if not ids:
        raise SystemExit(f"{args.file}: no IK run with an iteration history (run the study with histories)")
    rid = {int(r): i for i, r in enumerate(runs["run_id"])}
    plt, size = ksplot.figure(args)
    fig, ax = plt.subplots(figsize=size, constrained_layout=True)
    import matplotlib
    cmap = matplotlib.colormaps["plasma"]
    lams = sorted({float(runs["lambda"][rid[r]]) for r in ids if runs["method"][rid[r]] in LAMBDA_METHODS})
    styles = {"lm": "-", "lm_adaptive": "--"}
    other = iter(["#000000", "#1b9e77", "#7570b3", "#e7298a", "#66a61e"])
    other_colour = {}
    data, starts = {}, set()
    floor = None
    missing = [r for r in ids if r not in rid]
    if missing:
        raise SystemExit(f"--runs: no done run {', '.join(map(str, missing))} in {args.file}")
    # One line per (method, lambda) gets that pair's colour and style; when two plotted runs share the
    # pair (runs from other starts), each run gets its own colour instead.
    keys = [(runs["method"][rid[r]], float(runs["lambda"][rid[r]]) if runs["method"][rid[r]] in LAMBDA_METHODS
             else None) for r in ids]
    per_run = len(set(keys)) < len(keys)
    run_colours = matplotlib.colormaps["tab10"]
    for n, r in enumerate(ids):
        i = rid[r]
        if not res.has_history(r):
            raise SystemExit(f"run {r} has no history in {args.file} (run the study with histories)")
        h = res.history(r)
        if "norm_F" not in h:
            raise SystemExit(f"run {r} is not an IK run (no norm_F history)")
        k, nf = h["k"][:, 0], h["norm_F"][:, 0]
        m = runs["method"][i]
        if m in LAMBDA_METHODS:
            lam = float(runs["lambda"][i])
            c = cmap(0.05 + 0.85 * (lams.index(lam) / max(1, len(lams) - 1)))
            ls = styles[m]
        else:
            c = other_colour.setdefault(m, next(other, "#444444"))
            ls = "-"
        if per_run:
            c, ls = run_colours(n % 10), "-"
        start = f"({runs['q0_1'][i]:.4g}°, {runs['q0_2'][i]:.4g}°)"
        starts.add(start)
        lab = (f"run {r}: {m}" + (f", λ = {float(runs['lambda'][i]):g}" if m in LAMBDA_METHODS else "")
               + f", q0 = {start}" + f" ({runs['status'][i]}, {int(runs['iterations'][i])} it.)")
        pos = nf > 0
        ax.semilogy(k[pos], nf[pos], ls, color=c, lw=1.4, marker="o" if len(k) < 40 else None, ms=3, label=lab)
        floor = nf[pos].min() if floor is None or not pos.any() else min(floor, nf[pos].min())
        data[r] = {"label": lab, "colour": matplotlib.colors.to_hex(c), "style": ls, "k": k, "norm_F": nf, "method": m,
                   "lambda": float(runs["lambda"][i]) if m in LAMBDA_METHODS else None}
    ax.set_xlabel("iteration k")
    ax.set_ylabel("‖F_k‖ [problem units: mm for the SCARA]")
    ax.grid(which="both", alpha=0.25)
    if max(len(d["k"]) for d in data.values()) > 200:
        ax.set_xscale("symlog", linthresh=10)
        ax.set_xlabel("iteration k (linear to 10, then log)")
    handles, labels = ax.get_legend_handles_labels()
    if len(starts) == 1:  # one start for all: said once, in the title
        labels = [lab.replace(f", q0 = {next(iter(starts))}", "") for lab in labels]
    ax.legend(handles, labels, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    q = f" from q0 = {next(iter(starts))}" if len(starts) == 1 else ""
    what = f"runs {', '.join(map(str, ids))}" if args.runs else f"per method and λ{q}"
    ax.set_title(args.title or f"Convergence ‖F_k‖, {what}\n{os.path.basename(args.file)}", fontsize=10)
    return ksplot.finish(fig, args, "convergence", {"file": args.file, "runs": data})


if __name__ == "__main__":
    sys.exit(main())
