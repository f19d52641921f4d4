"""Peak resident memory of `kinesweep run` against the run count: one IK study (max_iter = 1,
histories none, one block swept over q0_1 x q0_2, so it has a landscape) at each run count asked
for, each run in a fresh temporary directory; prints peak RSS (ru_maxrss of the process), wall time
and the ratio of each peak to the smallest run count's.

usage: /usr/bin/python3 tests/bench/memory_scaling.py build/kinesweep [--runs 100000 10000000] [--threads 2]
"""
import argparse
import os
import subprocess
import tempfile
import time

STUDY = """[study]
histories = "none"
max_runs = {n}
[[block]]
name = "b"
kind = "ik"
max_iter = 1
[block.axes]
q0_1 = {{ from = 0, to = 1, count = {rows} }}
q0_2 = {{ from = 0, to = 1, count = 1000 }}
"""


def peak(ks, n, threads):
    with tempfile.TemporaryDirectory(dir=os.environ.get("TMPDIR")) as d:
        study = os.path.join(d, "m.toml")
        with open(study, "w") as f:
            f.write(STUDY.format(n=n, rows=n // 1000))
        t0 = time.perf_counter()
        p = subprocess.Popen([ks, "run", study, "-o", os.path.join(d, "m.h5"), "-q", "--threads", str(threads),
                              "--max-runs", str(n)], stdout=subprocess.DEVNULL)
        _, status, usage = os.wait4(p.pid, 0)
        if os.waitstatus_to_exitcode(status) != 0:
            raise SystemExit(f"kinesweep run of {n} runs failed")
        return usage.ru_maxrss * 1024, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("kinesweep")
    ap.add_argument("--runs", type=int, nargs="+", default=[100_000, 10_000_000])
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    base = None
    for n in a.runs:
        rss, wall = peak(a.kinesweep, n, a.threads)
        base = base or rss
        print(f"{n:>10} runs: peak RSS {rss / 2**20:8.1f} MiB, {wall:7.1f} s, {rss / base:.2f}x the first")


if __name__ == "__main__":
    main()
