"""Before vs after: one study run alternately by two kinesweep binaries, N times each (histories
none unless --histories says otherwise; the pair's order swaps every round), then each binary's min
and median wall time and CPU time (user + system of the run) and the ratios B / A. On a shared,
noisy machine only such same-script ratios mean anything, and the median of each round's own ratio
(its two runs are seconds apart) follows the load least; the CPU time leaves out the waits for a
core that other processes' load adds to the wall time. "runs" is the sum of the file's /runs wall_time column
(each run's own execution, without the writer and the setup; read with h5py when it is there).
The results files go to a temporary directory ($TMPDIR). --args-a / --args-b add arguments to one
side's `run`, so one binary can be compared with itself (e.g. A = B, --args-a="--lanes 1").

usage: /usr/bin/python3 tests/bench/compare_builds.py BIN_A BIN_B STUDY.toml [--runs 5] [--threads 1]
       [--histories none] [--args-a "..."] [--args-b "..."]
"""
import argparse
import os
import shlex
import statistics
import subprocess
import tempfile
import time

try:
    import h5py
except ImportError:  # the runs' own time is then left out
    h5py = None


def runs_time(path):
    """Sum of /runs/wall_time [s] of a results file, None when it has no such column."""
    if h5py is None:
        return None
    with h5py.File(path, "r") as f:
        return float(f["runs/wall_time"][()].sum()) if "runs/wall_time" in f else None


def main():
    p = argparse.ArgumentParser()
    p.add_argument("a")
    p.add_argument("b")
    p.add_argument("study")
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--histories", default="none")
    p.add_argument("--args-a", default="", help="extra arguments of A's run (one string, shell words)")
    p.add_argument("--args-b", default="", help="extra arguments of B's run")
    args = p.parse_args()
    times = {"a": [], "b": []}
    cpu = {"a": [], "b": []}
    runs = {"a": [], "b": []}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.runs):
            for which in (("a", "b") if r % 2 == 0 else ("b", "a")):  # neither always runs first
                out = os.path.join(tmp, which + ".h5")
                cmd = [getattr(args, which), "run", args.study, "-o", out, "--overwrite", "-q",
                       "--threads", str(args.threads), "--histories", args.histories]
                cmd += shlex.split(getattr(args, "args_" + which))
                t0 = time.perf_counter()
                proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL)
                _, status, usage = os.wait4(proc.pid, 0)
                times[which].append(time.perf_counter() - t0)
                proc.returncode = os.waitstatus_to_exitcode(status)
                if proc.returncode != 0:
                    raise subprocess.CalledProcessError(proc.returncode, cmd)
                cpu[which].append(usage.ru_utime + usage.ru_stime)
                runs[which].append(runs_time(out))
    for which in ("a", "b"):
        t, c = times[which], cpu[which]
        print(f"{which}: {getattr(args, which)} {getattr(args, 'args_' + which)}: min {min(t):.3f} s, median {statistics.median(t):.3f} s ({len(t)} runs); "
              f"CPU min {min(c):.3f} s, median {statistics.median(c):.3f} s")
    name = os.path.basename(args.study)
    have_runs = all(x is not None for x in runs["a"] + runs["b"])
    if have_runs:
        for which in ("a", "b"):
            t = runs[which]
            print(f"{which}: runs min {min(t):.3f} s, median {statistics.median(t):.3f} s")
    for label, v in (("wall", times), ("CPU", cpu)) + ((("runs", runs),) if have_runs else ()):
        paired = statistics.median(b / a for a, b in zip(v["a"], v["b"]))  # each round's two runs
        print(f"{name}: {label} median b/a = {statistics.median(v['b']) / statistics.median(v['a']):.3f}, "
              f"min b/a = {min(v['b']) / min(v['a']):.3f}, median of the rounds' b/a = {paired:.3f}")


if __name__ == "__main__":
    main()
