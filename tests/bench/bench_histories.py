"""History write speed against the disk: bench_sweep's study (2 methods x 81 alpha1A x 21 k = 3402
trajectory runs of 2001 samples) run by `kinesweep run` with histories none, every=10 and full, at
1 and 2 threads, round after round (the order of the cases rotates), and in the same rounds `dd`
writing as many bytes as the full-history file holds (the compressed histories and the rest) to a
file in the same directory, without fsync like the writer. Prints each case's min and median wall
time and the ratios the results store is held to: full / dd, every=10 / none, and full at 1 thread
/ full at 2 threads. Ratios of things run in the same rounds are what a shared, noisy machine can
measure.

usage: /usr/bin/python3 tests/bench/bench_histories.py BUILD/kinesweep [--rounds 5] [--compression 1]
"""
import argparse
import os
import statistics
import subprocess
import tempfile
import time

STUDY = """
[study]
name = "bench"
[[block]]
name = "landscape"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { from = -20, to = 30, count = 81 }
k = { from = 0, to = 1, count = 21 }
"""


def timed(cmd):
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main():
    p = argparse.ArgumentParser()
    p.add_argument("kinesweep")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--compression", type=int, default=1)
    args = p.parse_args()
    cases = [(h, t) for h in ("none", "every=10", "full") for t in (1, 2)]
    times = {c: [] for c in cases}
    times["dd"] = []
    size = {}
    with tempfile.TemporaryDirectory() as tmp:
        study = os.path.join(tmp, "bench.toml")
        with open(study, "w") as f:
            f.write(STUDY)
        order = cases + ["dd"]
        for r in range(args.rounds):
            k = r % len(order)
            for c in order[k:] + order[:k]:
                if c == "dd":
                    if "full" not in size:
                        continue
                    mib = max(1, size["full"] // (1 << 20))
                    out = os.path.join(tmp, "dd.bin")
                    times["dd"].append(timed(["dd", "if=/dev/zero", "of=" + out, "bs=1M", "count=%d" % mib]))
                    os.remove(out)
                    continue
                hist, threads = c
                out = os.path.join(tmp, "out.h5")
                times[c].append(timed([args.kinesweep, "run", study, "-o", out, "--overwrite", "-q", "--threads",
                                       str(threads), "--histories", hist, "--compression", str(args.compression)]))
                size[hist] = os.path.getsize(out)
                os.remove(out)
    print("case                 min [s]  median [s]  file [MB]")
    for c in cases:
        print("%-8s %d thread%s  %8.3f  %9.3f  %9.1f" % (c[0], c[1], "s" if c[1] > 1 else " ", min(times[c]),
                                                     statistics.median(times[c]), size[c[0]] / 1e6))
    print("dd (full's bytes)   %8.3f  %9.3f" % (min(times["dd"]), statistics.median(times["dd"])))

    def ratio(a, b):
        return "%.2f (min) / %.2f (median)" % (min(times[a]) / min(times[b]),
                                               statistics.median(times[a]) / statistics.median(times[b]))
    for t in (1, 2):
        print("threads %d: full / dd = %s; every=10 / none = %s" % (t, ratio(("full", t), "dd"),
                                                                    ratio(("every=10", t), ("none", t))))
    print("full, 1 thread / 2 threads = %s" % ratio(("full", 1), ("full", 2)))


if __name__ == "__main__":
    main()
