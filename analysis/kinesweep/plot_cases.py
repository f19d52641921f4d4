#!/usr/bin/python3
"""Bar chart of a metric per Table 4 case, the thesis' value beside kinesweep's (seed 000, Figures 9-11).

Reads the rows of a study with a `preset` column (e.g. studies/thesis_table4.toml).

    python3 -m kinesweep.plot_cases results/thesis_table4.h5
    python3 -m kinesweep.plot_cases results/thesis_table4.h5 --metric tau1_inf --cases 1a,1b,1c,1d --log
"""
import argparse
import os
import sys

import numpy as np

from kinesweep import plotting as ksplot  # noqa: E402
from kinesweep import read as ksread  # noqa: E402

THESIS_INDEX = {"E": None, "tau1_inf": 0, "tau2_inf": 1, "tau3_inf": 2}
LABELS = {"E": "E (mean ‖τ‖)", "tau1_inf": "‖τ1‖∞", "tau2_inf": "‖τ2‖∞", "tau3_inf": "‖τ3‖∞"}


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.plot_cases", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p)
    p.add_argument("--metric", default="E", choices=list(THESIS_INDEX), help="default %(default)s")
    p.add_argument("--cases", help="cases to show, comma-separated (default: every preset in the file)")
    p.add_argument("--log", action="store_true", help="logarithmic value axis")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    res = ksread.open_results(args.file)
    if "preset" not in res.columns():
        raise SystemExit(f"{args.file}: no Table 4 preset rows (no preset column); "
                         "studies/thesis_table4.toml runs them all")
    if args.metric not in res.columns():
        raise SystemExit(f"{args.file}: no column {args.metric} (plot_cases reads trajectory runs)")
    runs = res.runs(columns=["run_id", "preset", "status", args.metric])
    if not any(runs["preset"]):
        raise SystemExit(f"{args.file}: no Table 4 preset rows (no done run has a preset); "
                         "studies/thesis_table4.toml runs them all")
    cases = [c.strip() for c in args.cases.split(",")] if args.cases else \
        [c for c in dict.fromkeys(runs["preset"]) if c]
    ours, thesis, ids = [], [], []
    for c in cases:
        m = np.nonzero(runs["preset"] == c)[0]
        if not m.size:
            raise SystemExit(f"--cases {c}: no done run with preset {c}")
        ours.append(float(runs[args.metric][m[0]]))
        ids.append(int(runs["run_id"][m[0]]))
        row = ksread.THESIS_TABLE4.get(c)
        k = THESIS_INDEX[args.metric]
        thesis.append(np.nan if row is None else (row[3] if k is None else row[4][k]))
    unit = runs.units[args.metric]
    plt, size = ksplot.figure(args)
    fig, ax = plt.subplots(figsize=size, constrained_layout=True)
    x = np.arange(len(cases))
    w = 0.4
    ax.bar(x - w / 2, thesis, w, label="thesis (seed 000, Table 4)", color="#9ecae1", edgecolor="#3182bd")
    ax.bar(x + w / 2, ours, w, label="kinesweep", color="#fdae6b", edgecolor="#e6550d")
    for xi, (t, o) in enumerate(zip(thesis, ours)):
        if np.isfinite(t) and t:
            dev = (o - t) / t * 100
            if abs(dev) >= 1.0:
                ax.annotate(f"{dev:+.0f}%", (xi + w / 2, o), xytext=(0, 2), textcoords="offset points",
                            ha="center", fontsize=7, color="#a63603")
    ax.set_xticks(x, cases)
    ax.set_xlabel("Table 4 case")
    ax.set_ylabel(f"{LABELS[args.metric]} [{unit}]")
    if args.log:
        ax.set_yscale("log")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=9, loc="upper left")
    ax.set_title(args.title or f"{LABELS[args.metric]} per case: thesis beside kinesweep (labels: deviation ≥ 1 %)\n"
                 f"{os.path.basename(args.file)}", fontsize=10)
    return ksplot.finish(fig, args, f"cases_{args.metric}",
        {"file": args.file, "metric": args.metric, "unit": unit, "cases": cases,
         "run_ids": ids, "kinesweep": ours, "thesis": thesis})


if __name__ == "__main__":
    sys.exit(main())
