"""E of global_spline against its knot count on the chain robots of the shipped path-global studies:
the 4R and 5R arms of path_global_4r/5r.toml (planar chart, from the local run at their first start
angle) and the 7-DOF arm of path_global_arm7.toml (joint coordinates, from its best local run, its
limits as constraints), each with the arm at rest at the end. Reads the robot, task and start of the
study files themselves. Prints a markdown table: E, evaluations and time per knot count, and the
change between the two finest counts.

usage: /usr/bin/python3 path_global_chain_knots.py KINESWEEP_BINARY STUDIES_DIR [--knots 5,10,20,40] [--threads N]
       [--arms 4R,5R,7-DOF]
"""
import argparse
import os
import re

import numpy as np

from study_runs import run_study

ARMS = (("4R", "path_global_4r.toml"), ("5R", "path_global_5r.toml"), ("7-DOF", "path_global_arm7.toml"))


def global_study(path, knots):
    """The study file's global block alone, each of its other axes at its first value, over the knot sweep."""
    text = open(path).read()
    text = re.sub(r'urdf = "([^"]+)"',
                  lambda m: 'urdf = "%s"' % os.path.abspath(os.path.join(os.path.dirname(path), m.group(1))), text)
    head, glob = text.split('name = "global"\n')
    glob = glob.split("[[block]]")[0]
    fixed, axes = (glob.split("[block.axes]") + [""])[:2]
    fixed = re.sub(r"^(zip|knots) = .*$", "", fixed, flags=re.M)
    firsts = "".join("%s = %s\n" % (m.group(1), m.group(2).strip())
                     for m in re.finditer(r"^(\w+) = \[([^,\]]+)", axes, flags=re.M) if m.group(1) != "knots")
    study = head.split("[[block]]")[0]
    return study + '[[block]]\nname = "global"\n' + fixed + firsts + "[block.axes]\nknots = [%s]\n" % knots


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("kinesweep")
    ap.add_argument("studies")
    ap.add_argument("--knots", default="5,10,20,40")
    ap.add_argument("--threads", default="2")
    ap.add_argument("--arms", default="4R,5R,7-DOF")
    a = ap.parse_args()
    knots = [int(k) for k in a.knots.split(",")]
    print("| arm | " + " | ".join(f"{k} knots: E, evaluations, time" for k in knots) + " | change between the two finest |")
    print("|---|" + "---|" * len(knots) + "---|")
    for arm, name in ARMS:
        if arm not in a.arms.split(","):
            continue
        runs = run_study(a.kinesweep, global_study(os.path.join(a.studies, name), a.knots), a.threads)
        row = {}
        for k, e, s, n, t in zip(np.asarray(runs["knots"]), np.asarray(runs["E"], float), np.asarray(runs["status"]),
                                 np.asarray(runs["opt_evaluations"], float), np.asarray(runs["wall_time"], float)):
            row[int(k)] = (e, s, n, t)
        cells = []
        for k in knots:
            e, s, n, t = row[k]
            cells.append(f"{e:.2f}, {n:.0f}, {t:.1f} s" + ("" if s == "ok" else f" ({s})"))
        change = abs(row[knots[-1]][0] / row[knots[-2]][0] - 1) * 100
        print(f"| {arm} | " + " | ".join(cells) + f" | {change:.2f} % |")


if __name__ == "__main__":
    main()
