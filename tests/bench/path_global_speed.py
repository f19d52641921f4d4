"""One path-global run's own time, before against after: the seed's 3R arm on its square (global_spline,
20 knots, self-motion chart from the local start, objective E; and the tip-angle chart with its reach
constraints) and, with --arm7, the 7-DOF arm's square (joint coordinates, 10 knots, the URDF's limits as
constraints). The two binaries run alternately, --rounds times each, one thread; the time is the
run's own (/runs wall_time, without the process start and the writer), of the runs of block
"global" (the seed's study runs a warm-up run first, as a sweep's later runs find their memory). Prints each run's min and median
time and evaluations per binary, the ratio before / after of the medians and of the minima, and the
relative difference of the optima (E, the objective at the optimum).

usage: /usr/bin/python3 tests/bench/path_global_speed.py BEFORE_BINARY AFTER_BINARY [--rounds 7] [--arm7 STUDIES_DIR]
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
from kinesweep import read as ksread  # noqa: E402
from study_runs import ARM7_SQUARE  # noqa: E402

SEED = """
[study]
name = "path_global_speed"
histories = "none"

# run first, not reported: the process's first run pays for its memory's first touch (page faults
# of the dense check's 32001-sample arrays, about 30 ms on this machine); the runs after it are the
# steady state of a sweep
[[block]]
name = "warm_up"
kind = "trajectory"
method = "global_spline"
knots = 20
alpha1A = -20.5

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
knots = 20
zip = [["extension", "global_start"]]
[block.axes]
extension = ["self_motion", "alpha"]
global_start = ["local", "local"]
"""

ARM7 = """
[study]
name = "path_global_speed_arm7"
histories = "none"
""" + ARM7_SQUARE.replace("{d}", "2") + """

[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
start_method = "local_weighted"
extension = "joints"
knots = 10
K_N = 20
K_L = 8
q0_3 = 60    # deg: the start within the URDF's limits (studies/path_global_arm7.toml's global block, as here)
q0_4 = -90
"""


def run_once(binary, study, tmp):
    out = os.path.join(tmp, "out.h5")
    if os.path.exists(out):
        os.remove(out)
    subprocess.run([binary, "run", study, "-o", out, "-q", "--threads", "1", "--no-verify-best"], check=True,
                   capture_output=True)  # (the run alone: not its grid verification)
    with ksread.open_results(out) as r:
        t = r.runs()
        keep = [i for i, b in enumerate(t["block"]) if b == "global"]
        cols = {c: [t[c][i] for i in keep]
                for c in ("wall_time", "E", "opt_objective", "opt_evaluations", "status", "extension") if c in t}
    return cols


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--arm7", metavar="STUDIES_DIR", help="also the 7-DOF arm (its URDF under STUDIES_DIR/robots)")
    a = ap.parse_args()
    studies = [("seed 3R, 20 knots", SEED)]
    if a.arm7:
        urdf = os.path.abspath(os.path.join(a.arm7, "robots", "arm7.urdf"))
        studies.append(("7-DOF, 10 knots", ARM7.format(urdf=urdf)))
    with tempfile.TemporaryDirectory() as tmp:
        for title, text in studies:
            study = os.path.join(tmp, "study.toml")
            with open(study, "w") as f:
                f.write(text)
            results = {"before": [], "after": []}
            for k in range(a.rounds):
                order = ("before", "after") if k % 2 == 0 else ("after", "before")
                for side in order:
                    results[side].append(run_once(a.before if side == "before" else a.after, study, tmp))
            runs = len(results["before"][0]["wall_time"])
            print(f"## {title}")
            print("| run | side | status | min [ms] | median [ms] | evaluations | E | opt_objective |")
            print("|---|---|---|---|---|---|---|---|")
            for i in range(runs):
                med = {}
                mins = {}
                for side in ("before", "after"):
                    times = [r["wall_time"][i] * 1e3 for r in results[side]]
                    first = results[side][0]
                    med[side], mins[side] = statistics.median(times), min(times)
                    label = first.get("extension", [""] * runs)[i]
                    print(f"| {i} {label} | {side} | {first['status'][i]} | {mins[side]:.2f} | {med[side]:.2f} | "
                          f"{first['opt_evaluations'][i]:.0f} | {first['E'][i]:.10g} | {first['opt_objective'][i]:.10g} |")
                b, f = results["before"][0], results["after"][0]
                dE = abs(f["E"][i] / b["E"][i] - 1.0)
                dO = abs(f["opt_objective"][i] / b["opt_objective"][i] - 1.0)
                print(f"| {i} | before / after | | **{mins['before'] / mins['after']:.2f}×** | "
                      f"**{med['before'] / med['after']:.2f}×** | | Δ {dE:.1e} | Δ {dO:.1e} |")


if __name__ == "__main__":
    main()
