"""Before vs after: one study run alternately by two kinesweep binaries, N times each (histories
none), then each binary's min and median wall time and the ratios B / A. On a shared, noisy machine
only such same-script ratios mean anything.

usage: /usr/bin/python3 tests/bench/compare_builds.py BIN_A BIN_B STUDY.toml [--runs 5] [--threads 1]
"""
import argparse
import os
import statistics
import subprocess
import tempfile
import time


def main():
    p = argparse.ArgumentParser()
    p.add_argument("a")
    p.add_argument("b")
    p.add_argument("study")
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--threads", type=int, default=1)
    args = p.parse_args()
    times = {"a": [], "b": []}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.runs):
            for which in ("a", "b"):
                out = os.path.join(tmp, which + ".h5")
                cmd = [getattr(args, which), "run", args.study, "-o", out, "--overwrite", "-q",
                       "--threads", str(args.threads), "--histories", "none"]
                t0 = time.perf_counter()
                subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
                times[which].append(time.perf_counter() - t0)
    for which in ("a", "b"):
        t = times[which]
        print(f"{which}: {getattr(args, which)}: min {min(t):.3f} s, median {statistics.median(t):.3f} s ({len(t)} runs)")
    print(f"{os.path.basename(args.study)}: median b/a = {statistics.median(times['b']) / statistics.median(times['a']):.3f}, "
          f"min b/a = {min(times['b']) / min(times['a']):.3f}")


if __name__ == "__main__":
    main()
