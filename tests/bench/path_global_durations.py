"""Local against path-global redundancy resolution as the seed's square is run faster or slower: for
each total duration T (four equal sides), a local landscape (both local methods over alpha1A x k) and
global_spline runs (self-motion chart, 20 knots, from case 4's alpha(t) and from four start angles,
end at rest and free), each with the physical inertia. With --robot 4R or 5R, the arm of
studies/path_global_4r.toml or path_global_5r.toml instead (its [robot] table), its global runs from
the local run at each start angle. Prints a markdown table: the local runs' statuses, the best local
run that stays within 1 mm of its path, and the best global run.

usage: /usr/bin/python3 path_global_durations.py KINESWEEP_BINARY [--durations 1,1.5,2,3,4] [--threads N]
       [--robot 3R|4R|5R]
"""
import argparse
import os
import re

import numpy as np

from study_runs import run_study

STUDY = """
[study]
name = "durations"
histories = "none"

[task]
durations = [{d}, {d}, {d}, {d}]   # s

[[block]]
name = "local"
kind = "trajectory"
tracking_bound = 0.05

[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = {{ from = -25, to = 35, step = 1 }}
k = {{ from = 0, to = 1, step = 0.1 }}

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
knots = 20
global_start = "vertex"
vertex_alpha = [13.30, 17.28, -12.44, -16.12]

[block.axes]
alpha1A = [-23.75, -20, -10, 0, 10]
end_state = ["rest", "free"]
"""


def chain_study(robot):
    """STUDY on the arm of studies/path_global_<robot>.toml: its [robot] table, global runs from local starts."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "studies",
                        "path_global_%s.toml" % robot.lower())
    table = re.search(r"^\[robot\]\n(?:(?:[^\[\n].*)?\n)*", open(path).read(), flags=re.M).group(0)
    study = STUDY.replace("[task]", table.replace("{", "{{").replace("}", "}}") + "\n[task]")
    return study.replace('global_start = "vertex"\nvertex_alpha = [13.30, 17.28, -12.44, -16.12]\n', "")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("kinesweep")
    ap.add_argument("--durations", default="1,1.5,2,3,4")
    ap.add_argument("--threads", default="2")
    ap.add_argument("--robot", default="3R", choices=["3R", "4R", "5R"])
    a = ap.parse_args()
    study = STUDY if a.robot == "3R" else chain_study(a.robot)
    rows = []
    for T in [float(x) for x in a.durations.split(",")]:
        runs = run_study(a.kinesweep, study.format(d=T / 4), a.threads, degrees=True)
        block = np.asarray(runs["block"])
        status = np.asarray(runs["status"])
        E = np.asarray(runs["E"], dtype=float)
        track = np.asarray(runs["max_tracking_error"], dtype=float)
        loc = block == "local"
        n = int(loc.sum())
        counts = {s: int(((status == s) & loc).sum()) for s in np.unique(status[loc])}
        on_path = loc & (status == "ok") & (track <= 1e-3)
        best_local = float(np.nanmin(E[on_path])) if on_path.any() else float("nan")
        best_any = float(np.nanmin(np.where(loc & (status == "ok"), E, np.nan)))
        glo = (block == "global") & (status == "ok")
        end = np.asarray(runs["end_state"])
        best_rest, best_free = (float(np.nanmin(np.where(glo & (end == e), E, np.nan))) if (glo & (end == e)).any()
                                else float("nan") for e in ("rest", "free"))
        g_status = {s: int(((status == s) & (block == "global")).sum()) for s in np.unique(status[block == "global"])}
        rows.append((T, n, counts, int(on_path.sum()), best_local, best_any, best_rest, best_free, g_status))
    print("| T [s] | local runs: statuses | within 1 mm | best local E (≤ 1 mm / any ok) | global_spline E (end at rest / free) | global statuses |")
    print("|---|---|---|---|---|---|")
    for T, n, counts, k, bl, ba, gr, gf, gs in rows:
        st = ", ".join(f"{s} {c}" for s, c in sorted(counts.items(), key=lambda x: -x[1]))
        gst = ", ".join(f"{s} {c}" for s, c in sorted(gs.items()))
        print(f"| {T:g} | {n}: {st} | {k} | {bl:.2f} / {ba:.2f} | {gr:.2f} / {gf:.2f} | {gst} |")


if __name__ == "__main__":
    main()
