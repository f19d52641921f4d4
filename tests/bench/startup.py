#!/usr/bin/env python3
"""Start-up time of the kinesweep executable against a static hello-world, measured alternately.

    tests/bench/startup.py build/kinesweep [--rounds 15] [--reps 20]

Each round runs every command --reps times back to back (wall clock per run), in turn: a static C
hello-world (compiled here with cc -static), `kinesweep --version`, `kinesweep schema` and
`kinesweep query` of a small results file (the seed's Table 4 study, written here). Prints the
min and median milliseconds per run over the rounds and each command's ratio to the hello-world.
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


def per_run_ms(argv, reps):
    start = time.perf_counter()
    for _ in range(reps):
        subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return (time.perf_counter() - start) * 1000.0 / reps


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("kinesweep")
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--reps", type=int, default=20)
    args = ap.parse_args()
    ks = os.path.abspath(args.kinesweep)
    with tempfile.TemporaryDirectory() as tmp:
        hello = os.path.join(tmp, "hello")
        src = hello + ".c"
        with open(src, "w") as f:
            f.write('#include <stdio.h>\nint main(void) { puts("hello"); return 0; }\n')
        subprocess.run(["cc", "-O2", "-static", src, "-o", hello], check=True)
        small = os.path.join(tmp, "small.h5")
        subprocess.run([ks, "run", os.path.join(ROOT, "studies", "thesis_table4.toml"), "-o", small],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        commands = {
            "static hello-world": [hello],
            "kinesweep --version": [ks, "--version"],
            "kinesweep schema": [ks, "schema"],
            "kinesweep query (Table 4 file)": [ks, "query", small],
        }
        times = {name: [] for name in commands}
        for _ in range(args.rounds):
            for name, argv in commands.items():
                times[name].append(per_run_ms(argv, args.reps))
        nlibs = subprocess.run(["ldd", ks], capture_output=True, text=True).stdout.count("\n")
        print(f"{args.rounds} rounds x {args.reps} runs, alternating; {ks} maps {nlibs} shared objects")
        base = statistics.median(times["static hello-world"])
        print(f"{'command':32} {'min ms':>8} {'median ms':>10} {'x hello':>8}")
        for name, t in times.items():
            med = statistics.median(t)
            print(f"{name:32} {min(t):8.2f} {med:10.2f} {med / base:8.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
