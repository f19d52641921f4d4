"""Local against path-global redundancy resolution on the 7-DOF arm as its square is run faster or
slower: for each duration per side d (four equal sides), arm7_square.toml's local runs (both local
methods over k with and without the limit spring, and local_weighted over the start's elbow posture)
and global_spline runs (joint coordinates, 10 knots, the URDF's limits as constraints) from the local
run of its best posture, all sampled every 4 ms. Prints a markdown table: the local runs' statuses,
the best local run that keeps within the limits (status ok), and the global runs.

usage: /usr/bin/python3 path_global_arm7_durations.py KINESWEEP_BINARY STUDIES_DIR [--sides 1,1.5,2,3] [--threads N]
"""
import argparse
import os

import numpy as np

from study_runs import ARM7_SQUARE, run_study

STUDY = """
[study]
name = "arm7_durations"
histories = "none"
""" + ARM7_SQUARE + """

[[block]]
name = "k_sweep"
kind = "trajectory"
K_N = 20
[block.axes]
method = ["local_weighted", "local_unweighted"]
k = {{ from = 0, to = 1, step = 0.25 }}
K_L = [0, 8]

[[block]]
name = "posture"
kind = "trajectory"
method = "local_weighted"
K_N = 20
K_L = 8
[block.axes]
q0_3 = {{ from = -90, to = 90, step = 30 }}
q0_4 = [-90, -60, -30]

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
start_method = "local_weighted"
K_N = 20
K_L = 8
q0_3 = 60
q0_4 = -90
knots = 10
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("kinesweep")
    ap.add_argument("studies")
    ap.add_argument("--sides", default="1,1.5,2,3")
    ap.add_argument("--threads", default="2")
    a = ap.parse_args()
    urdf = os.path.abspath(os.path.join(a.studies, "robots", "arm7.urdf"))
    print("| side [s] | local runs: statuses | best local E within the limits | global_spline: status, E, limit ratios q q̇ τ, evaluations |")
    print("|---|---|---|---|")
    for d in [float(x) for x in a.sides.split(",")]:
        runs = run_study(a.kinesweep, STUDY.format(urdf=urdf, d=d), a.threads)
        block, status = np.asarray(runs["block"]), np.asarray(runs["status"])
        E = np.asarray(runs["E"], dtype=float)
        loc = block != "global"
        counts = {s: int(((status == s) & loc).sum()) for s in np.unique(status[loc])}
        ok = loc & (status == "ok")
        best = f"{np.nanmin(E[ok]):.2f}" if ok.any() else "none"
        g = np.flatnonzero(block == "global")[0]
        ratios = " ".join(f"{float(runs[c][g]):.3f}" for c in ("max_q_limit_ratio", "max_qd_limit_ratio",
                                                                "max_tau_limit_ratio"))
        st = ", ".join(f"{s} {c}" for s, c in sorted(counts.items(), key=lambda x: -x[1]))
        print(f"| {d:g} | {st} | {best} | {status[g]}, {E[g]:.2f}, {ratios}, {float(runs['opt_evaluations'][g]):.0f} |")


if __name__ == "__main__":
    main()
