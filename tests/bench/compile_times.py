#!/usr/bin/env python3
"""Compile time per object file, for one or more build directories, interleaved and repeated.

Each build directory must have been configured with -DCMAKE_EXPORT_COMPILE_COMMANDS=ON. The
objects whose source path matches --match (a regular expression) are compiled one at a time with
their recorded command (output to a scratch file), --repeat times, alternating between the build
directories so that load on a shared machine falls on both alike. Prints per object and build its
min and median wall time, and the sum of the medians per build.

  compile_times.py --match 'engine/ik/' before/build after/build
"""
import argparse
import json
import os
import re
import shlex
import statistics
import subprocess
import tempfile
import time


def commands(build, pattern):
    with open(os.path.join(build, "compile_commands.json")) as f:
        entries = json.load(f)
    out = {}
    for e in entries:
        if re.search(pattern, e["file"]):
            args = shlex.split(e["command"])
            i = args.index("-o")
            out[os.path.relpath(e["file"], e["directory"]).split("engine/", 1)[-1]] = (e["directory"], args, i)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("builds", nargs="+")
    ap.add_argument("--match", default=r"engine/ik/")
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    per_build = [commands(b, a.match) for b in a.builds]
    times = [{k: [] for k in c} for c in per_build]
    with tempfile.TemporaryDirectory() as scratch:
        obj = os.path.join(scratch, "o.o")
        for _ in range(a.repeat):
            for cmds, t in zip(per_build, times):
                for name, (directory, args, i) in sorted(cmds.items()):
                    argv = args[: i + 1] + [obj] + args[i + 2:]
                    start = time.perf_counter()
                    subprocess.run(argv, cwd=directory, check=True)
                    t[name].append(time.perf_counter() - start)
    for build, t in zip(a.builds, times):
        print(f"{build}:")
        total = 0.0
        for name, v in sorted(t.items()):
            med = statistics.median(v)
            total += med
            print(f"  {name:45s} min {min(v):7.1f} s  median {med:7.1f} s")
        print(f"  {'sum of medians':45s} {total:21.1f} s")


if __name__ == "__main__":
    main()
