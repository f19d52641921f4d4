"""E of global_spline against its knot count on the seed's arm and square: the self-motion chart from
case 4's alpha(t), end at rest, alpha(0) fixed at -23.75 deg or free, physical and thesis inertia.
Prints a markdown table with the change between the two finest counts.

usage: /usr/bin/python3 path_global_knots.py KINESWEEP_BINARY [--knots 5,10,20,40,80,160] [--threads N]
"""
import argparse

import numpy as np

from study_runs import run_study

STUDY = """
[study]
name = "knots"
histories = "none"

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
global_start = "vertex"
alpha1A = -23.75
vertex_alpha = [13.30, 17.28, -12.44, -16.12]

[block.axes]
inertia = ["physical", "thesis_m11"]
start_posture = ["fixed", "free"]
knots = [{knots}]
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("kinesweep")
    ap.add_argument("--knots", default="5,10,20,40,80,160")
    ap.add_argument("--threads", default="2")
    a = ap.parse_args()
    runs = run_study(a.kinesweep, STUDY.format(knots=a.knots), a.threads)
    knots = [int(k) for k in a.knots.split(",")]
    print("| α(0) | inertia | " + " | ".join(f"{k} knots" for k in knots) + " | change between the two finest |")
    print("|---|---|" + "---|" * len(knots) + "---|")
    for posture in ("fixed", "free"):
        for inertia in ("physical", "thesis_m11"):
            sel = (np.asarray(runs["start_posture"]) == posture) & (np.asarray(runs["inertia"]) == inertia)
            E = {int(k): float(e) for k, e, s in zip(np.asarray(runs["knots"])[sel], np.asarray(runs["E"])[sel],
                                                     np.asarray(runs["status"])[sel]) if s == "ok"}
            cells = [f"{E[k]:.4f}" if k in E else "–" for k in knots]
            change = abs(E[knots[-1]] / E[knots[-2]] - 1) * 100 if knots[-1] in E and knots[-2] in E else float("nan")
            print(f"| {posture} | {inertia} | " + " | ".join(cells) + f" | {change:.3f} % |")


if __name__ == "__main__":
    main()
