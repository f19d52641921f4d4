#!/usr/bin/python3
"""‖F_k‖ against iteration (log scale) per IK method and λ, from the runs' iteration histories.

By default one line per (method, lambda) present among the IK runs with a history: the first such
run (lowest id); --start Q1,Q2 picks the runs whose initial guess (degrees) is nearest instead, and
--runs lists run ids explicitly. Each line's label names its run, method, λ and start; lines that share
a method and λ get a colour each. Runs whose ‖F_k‖ histories are bitwise identical (lm_adaptive ignores
λ, so its runs from one start are) are drawn as one line labelled with all of them ("runs 3,4,5
(identical)"), with a note on stderr; --print-data lists the drawn lines ("lines": each one's runs,
label and plotted data) and, per run, the line it is drawn as.

    python3 -m kinesweep.plot_convergence results/ik_scara.h5 --start 60,45
"""
import argparse
import os
import sys

import numpy as np

from kinesweep import plotting as ksplot  # noqa: E402
from kinesweep import read as ksread  # noqa: E402

LAMBDA_METHODS = {"lm", "lm_adaptive"}


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.plot_convergence", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
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
    hists = {}
    for r in ids:
        if not res.has_history(r):
            raise SystemExit(f"run {r} has no history in {args.file} (run the study with histories)")
        h = res.history(r)
        if "norm_F" not in h:
            raise SystemExit(f"run {r} is not an IK run (no norm_F history)")
        hists[r] = (h["k"][:, 0], h["norm_F"][:, 0])
    # Runs whose histories are bitwise equal (e.g. lm_adaptive, which ignores lambda, from one start at
    # every lambda) would be drawn on top of each other: one line for them, labelled with all of them.
    groups = {}
    for r in ids:
        k, nf = hists[r]
        groups.setdefault((k.shape, k.tobytes(), nf.tobytes()), []).append(r)
    groups = list(groups.values())
    notes = []
    for g in groups:
        if len(g) > 1:
            notes.append(f"runs {','.join(map(str, g))} have identical ‖F_k‖ histories: drawn as one line")
            print(f"kinesweep.plot_convergence: note: {notes[-1]}", file=sys.stderr)
    # One line per (method, lambda) gets that pair's colour and style; when two drawn lines share the
    # pair (runs from other starts), each line gets its own colour instead.
    def key(r):
        m = runs["method"][rid[r]]
        return m, float(runs["lambda"][rid[r]]) if m in LAMBDA_METHODS else None
    keys = [key(g[0]) for g in groups]
    per_run = len(set(keys)) < len(keys)
    run_colours = matplotlib.colormaps["tab10"]

    def joined(values):
        """One value when all agree, else all of them (first seen first), comma-separated."""
        return ", ".join(dict.fromkeys(values))

    lines = []
    for n, g in enumerate(groups):
        r = g[0]
        i = rid[r]
        k, nf = hists[r]
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
        rows = [rid[x] for x in g]
        start = joined(f"({runs['q0_1'][j]:.4g}°, {runs['q0_2'][j]:.4g}°)" for j in rows)
        starts.add(start)
        methods = joined(str(runs["method"][j]) for j in rows)
        lam_text = joined(f"{float(runs['lambda'][j]):g}" for j in rows if runs["method"][j] in LAMBDA_METHODS)
        outcome = joined(f"{runs['status'][j]}, {int(runs['iterations'][j])} it." for j in rows)
        who = f"run {r}" if len(g) == 1 else f"runs {','.join(map(str, g))} (identical)"
        lab = (f"{who}: {methods}" + (f", λ = {lam_text}" if lam_text else "") + f", q0 = {start}" + f" ({outcome})")
        pos = nf > 0
        line, = ax.semilogy(k[pos], nf[pos], ls, color=c, lw=1.4, marker="o" if len(k) < 40 else None, ms=3,
                            label=lab)
        floor = nf[pos].min() if floor is None or not pos.any() else min(floor, nf[pos].min())
        colour = matplotlib.colors.to_hex(c)
        lines.append({"runs": g, "label": lab, "colour": colour, "style": ls,
                      "x": np.asarray(line.get_xdata(), dtype=float), "y": np.asarray(line.get_ydata(), dtype=float)})
        for x in g:
            j = rid[x]
            mx = runs["method"][j]
            data[x] = {"label": lab, "colour": colour, "style": ls, "k": hists[x][0], "norm_F": hists[x][1],
                       "method": mx, "lambda": float(runs["lambda"][j]) if mx in LAMBDA_METHODS else None,
                       "line": n, "identical_to": [y for y in g if y != x]}
    ax.set_xlabel("iteration k")
    ax.set_ylabel("‖F_k‖ [problem units: mm for the SCARA]")
    ax.grid(which="both", alpha=0.25)
    if max(len(d["k"]) for d in data.values()) > 200:
        ax.set_xscale("symlog", linthresh=10)
        ax.set_xlabel("iteration k (linear to 10, then log)")
    handles, labels = ax.get_legend_handles_labels()
    if len(starts) == 1:  # one start for all: said once, in the title
        labels = [lab.replace(f", q0 = {next(iter(starts))}", "") for lab in labels]
    import textwrap  # a long label (a line of several identical runs) on several legend lines
    labels = [textwrap.fill(lab, 64, subsequent_indent="   ") for lab in labels]
    ax.legend(handles, labels, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    q = f" from q0 = {next(iter(starts))}" if len(starts) == 1 else ""
    what = f"runs {', '.join(map(str, ids))}" if args.runs else f"per method and λ{q}"
    ax.set_title(args.title or f"Convergence ‖F_k‖, {what}\n{os.path.basename(args.file)}", fontsize=10)
    data = {r: data[r] for r in ids}  # in the order the runs were picked
    return ksplot.finish(fig, args, "convergence", {"file": args.file, "runs": data, "lines": lines, "notes": notes})


if __name__ == "__main__":
    sys.exit(main())
