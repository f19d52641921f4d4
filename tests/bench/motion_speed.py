"""Shipped motion studies, before against after: each study is run by the two binaries alternately,
--rounds times each, one thread; the time is the sum of the runs' own times (/runs wall_time, without
the process start and the writer). Prints, per study, each binary's min and median and the ratios
before / after, and whether every stored objective and dense-check metric is equal bit for bit.

usage: /usr/bin/python3 tests/bench/motion_speed.py BEFORE_BINARY AFTER_BINARY [--rounds 5]
       [--studies motion_elbow,motion_moving_2r]
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "analysis"))
from kinesweep import read as ksread  # noqa: E402

COMPARED = ("objective", "torque_sq_integral", "power_sq_integral", "check_min_clearance", "check_torque_sq_change",
            "check_power_sq_change")


def run_once(binary, study, tmp):
    out = os.path.join(tmp, "out.h5")
    if os.path.exists(out):
        os.remove(out)
    subprocess.run([binary, "run", study, "-o", out, "-q", "--threads", "1", "--histories", "none"], check=True,
                   capture_output=True)
    with ksread.open_results(out) as r:
        t = r.runs()
        return sum(float(x) for x in t["wall_time"]), {c: [float(x) for x in t[c]] for c in COMPARED if c in t}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--studies", default="motion_elbow,motion_moving_2r")
    a = ap.parse_args()
    print("| study | before min / median [s] | after min / median [s] | before / after (min, median) | metrics equal |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in a.studies.split(","):
            study = os.path.join(ROOT, "studies", name + ".toml")
            times = {"before": [], "after": []}
            values = {}
            for k in range(a.rounds):
                for side in (("before", "after") if k % 2 == 0 else ("after", "before")):
                    t, v = run_once(a.before if side == "before" else a.after, study, tmp)
                    times[side].append(t)
                    values[side] = v
            b, f = times["before"], times["after"]
            same = values["before"] == values["after"]
            print(f"| {name} | {min(b):.3f} / {statistics.median(b):.3f} | {min(f):.3f} / {statistics.median(f):.3f} | "
                  f"**{min(b) / min(f):.2f}×**, {statistics.median(b) / statistics.median(f):.2f}× | {same} |")


if __name__ == "__main__":
    main()
