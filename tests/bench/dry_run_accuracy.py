"""How good `kinesweep run --dry-run`'s estimates are: for each study, the estimated time and size
against the measured wall time and file size of the real run (same threads and histories), as ratios
estimate / measured. Each study is run --runs times; min and median of the measured times reported.

usage: /usr/bin/python3 tests/bench/dry_run_accuracy.py KINESWEEP [STUDY.toml ...] [--threads 2] [--runs 2]
       (default studies: every studies/*.toml but the [[optimize]] ones, whose optimisation blocks the
       estimate leaves out)
"""
import argparse
import glob
import os
import re
import statistics
import subprocess
import tempfile
import time

UNITS = {"B": 1, "KiB": 1024, "MiB": 1024 ** 2, "GiB": 1024 ** 3, "TiB": 1024 ** 4}
TIME = {"s": 1, "min": 60, "h": 3600}


def estimate(ks, study, out, threads):
    r = subprocess.run([ks, "run", study, "-o", out, "--dry-run", "--threads", str(threads)], capture_output=True,
                       text=True, check=True)
    size = re.search(r"estimated size: ([\d.]+) (\w+)", r.stdout)
    secs = re.search(r"estimated time: ([\d.]+) (s|min|h)", r.stdout)
    return float(size.group(1)) * UNITS[size.group(2)], float(secs.group(1)) * TIME[secs.group(2)]


def main():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    p = argparse.ArgumentParser()
    p.add_argument("kinesweep")
    p.add_argument("studies", nargs="*")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--runs", type=int, default=2)
    args = p.parse_args()
    studies = args.studies or [s for s in sorted(glob.glob(os.path.join(root, "studies", "*.toml")))
                               if "[[optimize]]" not in open(s).read()]
    worst = 1.0
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "r.h5")
        for s in studies:
            est_b, est_s = estimate(args.kinesweep, s, out, args.threads)
            times = []
            for _ in range(args.runs):
                t0 = time.perf_counter()
                subprocess.run([args.kinesweep, "run", s, "-o", out, "--overwrite", "-q", "--threads",
                                str(args.threads)], check=True, stdout=subprocess.DEVNULL)
                times.append(time.perf_counter() - t0)
            size = os.path.getsize(out)
            rs, rt = est_b / size, est_s / statistics.median(times)
            worst = max(worst, rs, 1 / rs, rt, 1 / rt)
            print(f"{os.path.basename(s):28s} size est/real {rs:5.2f} ({est_b / 2**20:8.1f} / {size / 2**20:8.1f} MiB)  "
                  f"time est/real {rt:5.2f} ({est_s:7.2f} s / median {statistics.median(times):7.2f} s, "
                  f"min {min(times):7.2f} s)")
    print(f"worst factor: {worst:.2f}")


if __name__ == "__main__":
    main()
