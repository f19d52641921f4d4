#!/usr/bin/env python3
"""Start-up time of the kinesweep executable against a static hello-world, measured alternately.

    tests/bench/startup.py build/kinesweep [OTHER/kinesweep ...] [--rounds 15] [--reps 20]

Each round runs every command --reps times back to back (wall clock per run), in turn: a static C
hello-world (compiled here with cc -static -O2), then for each kinesweep binary given (e.g. the one of
an older commit, to compare before and after in one run) `kinesweep --version`, `kinesweep schema`
and `kinesweep query` of a small results file (the seed's Table 4 study, 21 runs, written here by
that binary). Prints, per command, the min and median milliseconds per run over the rounds, their
ratios to the hello-world's min and median, and how many shared objects each binary maps (ldd).
Nothing here asserts a time.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
HELLO_C = '#include <stdio.h>\nint main(void) { puts("hello"); return 0; }\n'


def per_run_ms(argv, reps):
    start = time.perf_counter()
    for _ in range(reps):
        subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return (time.perf_counter() - start) * 1000.0 / reps


def shared_objects(binary):
    out = subprocess.run(["ldd", binary], capture_output=True, text=True).stdout
    return sum(1 for line in out.splitlines() if line.strip())


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("kinesweep", nargs="+", help="kinesweep binaries (measured alternately)")
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--reps", type=int, default=20)
    args = ap.parse_args()
    binaries = [os.path.abspath(k) for k in args.kinesweep]
    study = os.path.join(ROOT, "studies", "thesis_table4.toml")
    with tempfile.TemporaryDirectory() as tmp:
        hello = os.path.join(tmp, "hello")
        with open(hello + ".c", "w") as f:
            f.write(HELLO_C)
        subprocess.run(["cc", "-O2", "-static", hello + ".c", "-o", hello], check=True)
        commands = {"static hello-world": [hello]}
        for i, ks in enumerate(binaries):
            tag = f"[{i}] " if len(binaries) > 1 else ""
            small = os.path.join(tmp, f"small{i}.h5")
            subprocess.run([ks, "run", study, "-o", small, "-q"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
            commands[f"{tag}kinesweep --version"] = [ks, "--version"]
            commands[f"{tag}kinesweep schema"] = [ks, "schema"]
            commands[f"{tag}kinesweep query (Table 4 file)"] = [ks, "query", small]
        times = {name: [] for name in commands}
        for _ in range(args.rounds):
            for name, argv in commands.items():
                times[name].append(per_run_ms(argv, args.reps))
        print(f"{args.rounds} rounds x {args.reps} runs, alternating")
        for i, ks in enumerate(binaries):
            tag = f"[{i}] " if len(binaries) > 1 else ""
            print(f"{tag}{ks}: maps {shared_objects(ks)} shared objects (ldd)")
        hello_t = times["static hello-world"]
        base_min, base_med = min(hello_t), statistics.median(hello_t)
        print(f"{'command':36} {'min ms':>8} {'median ms':>10} {'min/min':>8} {'med/med':>8}")
        for name, t in times.items():
            med = statistics.median(t)
            print(f"{name:36} {min(t):8.2f} {med:10.2f} {min(t) / base_min:8.1f} {med / base_med:8.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
