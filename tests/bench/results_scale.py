"""Results at scale: write and read back 10^5 .. 10^7-run files of a trajectory landscape and of an
IK basin study (histories none), each command against a plain h5py read of the columns it touches,
in the same script.

usage: /usr/bin/python3 tests/bench/results_scale.py build/kinesweep [--before OLD_KINESWEEP] [--analysis-before DIR]
           [--runs 100000 1000000] [--kinds trajectory ik] [--repeat 3] [--mpi] [--workdir DIR] [--keep]
           [--reuse] [--only write query compact group info pandas plot report]

For each study kind and run count: `kinesweep run` (wall time, peak RSS, file bytes per run;
alternated with --before's binary, whose write time gives the ratio new / old), then, on the file
just written, repeated --repeat times (min and median of each):
  query   --where "<metric> < <its 1st percentile>" --sort <metric> --limit 3 --columns run_id,<metric>
  compact the same without --columns (the compact default: it reads every parameter and metric of the
          pieces holding a matching row, to show the parameters that vary among the matches)
  group   --group-by method --agg min:<metric>,count
  info
  pandas  kinesweep.read.open_results(F).to_pandas() (all columns; timed inside the interpreter;
          peak RSS of that interpreter, pandas imported; the frame's bytes)
  plot    python3 -m kinesweep.plot_landscape F, and report: kinesweep.report F (wall, peak RSS, output size),
          each alternated with a fresh interpreter's h5py read of the datasets it draws (plot: the
          landscape grid of the default metric and status_code; report: /runs block, status, done,
          run_id and the metric, and every dataset of the landscape), the ratio over that read
  merge   (--mpi, trajectory) `mpirun -np 2 kinesweep run` with one thread per rank: the merge time it
          prints against a `cp` of its two shard files (hard-linked as they appear, so the copy reads
          the shards as the merge found them; coreutils' cp copies inside the kernel) and against `dd
          bs=1M` of them (the same bytes read into a buffer and written, as a program's copy does)
against h5py reading the columns each touches (query: the metric, run_id and done; compact: every
parameter and metric, block, status and done; group: method, the metric and done; info: the
columns info reads; pandas: every /runs column).
--reuse takes a file already in --workdir (from --keep) instead of writing it; --only times just the
steps named. Ratios over the h5py read are what the targets are stated in. Run with Debian's /usr/bin/python3.
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ANALYSIS = os.path.join(HERE, "..", "..", "analysis")
ANALYSIS_ENV = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [ANALYSIS, os.environ.get("PYTHONPATH")])))

TRAJECTORY = """[study]
name = "scale_trajectory"
histories = "none"
[[block]]
name = "local"
kind = "trajectory"
[block.axes]
method = ["local_weighted"]
alpha1A = {{ from = -20, to = 30, count = {a} }}
k = {{ from = 0, to = 1, count = {b} }}
"""
IK = """[study]
name = "scale_ik"
histories = "none"
[[block]]
name = "basins"
kind = "ik"
problem = "scara"
lambda = 0.1
target_x = 50.0
target_y = -80.0
target_z = 10.0
q0_3 = 50.0
max_iter = 50
[block.axes]
method = ["lm"]
q0_1 = {{ from = -180, to = 180, count = {a} }}
q0_2 = {{ from = -180, to = 180, count = {b} }}
"""
METRIC = {"trajectory": "E", "ik": "iterations"}
# The plain read a plot or the report is measured against: a fresh interpreter importing h5py and
# reading the datasets it draws whole (the commands start an interpreter too).
READ = """
import sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    for name in sys.argv[2:]:
        f[name][()]
"""


def timed(cmd, env=None):
    """(wall seconds, peak RSS bytes) of a command; its output discarded. The peak is GNU time's
    (the rusage of a child forked from this interpreter would count the interpreter's pages)."""
    t0 = time.perf_counter()
    p = subprocess.run(["/usr/bin/time", "-f", "%M", *cmd], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                       text=True, env=env)
    seconds = time.perf_counter() - t0
    if p.returncode != 0:
        raise SystemExit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    return seconds, int(p.stderr.strip().splitlines()[-1]) * 1024


PANDAS = f"""
import resource, sys, time
sys.path.insert(0, {ANALYSIS!r})
from kinesweep import read
import pandas
t0 = time.perf_counter()
df = read.open_results(sys.argv[1]).to_pandas()
print(time.perf_counter() - t0, df.memory_usage(deep=True).sum())
"""


def h5py_read(path, columns):
    """Seconds to read `columns` of /runs whole with h5py (a fresh open)."""
    t0 = time.perf_counter()
    with h5py.File(path, "r") as f:
        for c in columns:
            f["runs"][c][()]
    return time.perf_counter() - t0


def stats(values):
    return min(values), statistics.median(values)


def report(name, ours, base, rss=None, extra=""):
    (mn, md), (bmn, bmd) = stats(ours), stats(base)
    line = f"  {name:<8} {mn:8.2f} s (median {md:6.2f})   h5py {bmn:6.2f} s   ratio {mn / bmn:6.2f}"
    if rss is not None:
        line += f"   peak {max(rss) / 1e6:7.0f} MB"
    print(line + extra, flush=True)


def mpi_merge(ks, study, out, args):
    """`mpirun -np 2 kinesweep run` (1 thread per rank): its merge time (from its output) against `cp`
    of its shard files, which are hard-linked as they appear so that the copy reads them as the
    merge did (just written, in the page cache)."""
    merges, copies, dds = [], [], []
    for _ in range(args.repeat):
        keep = []
        mpi_out = out + ".mpi.h5"
        p = subprocess.Popen(["mpirun", "--oversubscribe", "--allow-run-as-root", "--bind-to", "none", "-np", "2",
                              ks, "run", study, "-o", mpi_out, "--overwrite", "--threads", "1"],
                             stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        while p.poll() is None:
            for r in range(2):
                shard, link = f"{mpi_out}.rank{r}.h5", f"{out}.keep{r}.h5"
                if link not in keep and os.path.exists(shard):
                    try:
                        os.link(shard, link)
                        keep.append(link)
                    except OSError:
                        pass
            time.sleep(0.05)
        text = p.stdout.read()
        merge = float(text.split("merge ")[1].split(" s")[0])
        merges.append(merge)
        dst = out + ".copies"
        os.makedirs(dst, exist_ok=True)
        t0 = time.perf_counter()
        subprocess.run(["cp", *keep, dst], check=True)
        copies.append(time.perf_counter() - t0)
        size = sum(os.path.getsize(k) for k in keep)
        shutil.rmtree(dst)
        os.makedirs(dst, exist_ok=True)
        t0 = time.perf_counter()  # the same bytes through a user-space buffer (read, then write)
        for k in keep:
            subprocess.run(["dd", f"if={k}", f"of={os.path.join(dst, os.path.basename(k))}", "bs=1M", "status=none"],
                           check=True)
        dds.append(time.perf_counter() - t0)
        shutil.rmtree(dst)
        for k in keep:
            os.remove(k)
        os.remove(mpi_out)
    (mn, md), (cmn, cmd), (dmn, dmd) = stats(merges), stats(copies), stats(dds)
    print(f"  merge    {mn:8.2f} s (median {md:6.2f})   cp of the 2 shards ({size / 1e6:.0f} MB) {cmn:6.2f} s "
          f"(median {cmd:.2f})   ratio {mn / cmn:6.2f}   dd bs=1M of them {dmn:6.2f} s (median {dmd:.2f})   "
          f"ratio {mn / dmn:6.2f}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("kinesweep")
    ap.add_argument("--before", help="an older kinesweep binary: its write time is the reference")
    ap.add_argument("--runs", type=int, nargs="+", default=[100000, 1000000])
    ap.add_argument("--kinds", nargs="+", default=["trajectory", "ik"], choices=["trajectory", "ik"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--workdir")
    ap.add_argument("--keep", action="store_true", help="keep the files written")
    ap.add_argument("--reuse", action="store_true", help="use a file already in --workdir instead of writing it")
    steps = ["write", "query", "compact", "group", "info", "pandas", "plot", "report"]
    ap.add_argument("--only", nargs="+", choices=steps, default=steps, help="time only these steps")
    ap.add_argument("--analysis-before", metavar="DIR",
                    help="also time plot_landscape and the report of another analysis/ directory (PYTHONPATH=DIR), "
                         "alternated with this one's")
    ap.add_argument("--mpi", action="store_true", help="also time the merge of `mpirun -np 2` (trajectory) against cp")
    args = ap.parse_args()
    work = args.workdir or tempfile.mkdtemp(prefix="ks_scale_")
    os.makedirs(work, exist_ok=True)
    ks = os.path.abspath(args.kinesweep)
    try:
        for kind in args.kinds:
            for n in args.runs:
                a = int(round(n ** 0.5))
                b = n // a
                study = os.path.join(work, f"{kind}_{n}.toml")
                with open(study, "w") as f:
                    f.write((TRAJECTORY if kind == "trajectory" else IK).format(a=a, b=b))
                out = os.path.join(work, f"{kind}_{n}.h5")
                print(f"{kind}, {a * b} runs", flush=True)
                writes, before = [], []
                reused = args.reuse and os.path.exists(out)
                for _ in range(0 if reused else args.repeat if "write" in args.only else 1):
                    writes.append(timed([ks, "run", study, "-o", out, "--overwrite", "-q", "--threads",
                                         str(args.threads)]))
                    if args.before and "write" in args.only:
                        old = out + ".before.h5"
                        before.append(timed([args.before, "run", study, "-o", old, "--overwrite", "-q",
                                             "--threads", str(args.threads)]))
                size = os.path.getsize(out)
                if reused or "write" not in args.only:
                    print(f"  file     {size / 1e6:.0f} MB{' (reused)' if reused else ''}", flush=True)
                else:
                    w = [t for t, _ in writes]
                    line = (f"  write    {min(w):8.2f} s (median {statistics.median(w):6.2f})   "
                            f"peak {max(r for _, r in writes) / 1e6:5.0f} MB   {size / (a * b):6.1f} B/run")
                    if before:
                        wb = [t for t, _ in before]
                        bsize = os.path.getsize(out + ".before.h5")
                        line += (f"   before: {min(wb):.2f} s, {bsize / (a * b):.1f} B/run;"
                                 f" write ratio new/old {min(w) / min(wb):.3f} (min), "
                                 f"{statistics.median(w) / statistics.median(wb):.3f} (median)")
                        os.remove(out + ".before.h5")
                    print(line, flush=True)
                metric = METRIC[kind]
                with h5py.File(out, "r") as f:
                    v = f["runs"][metric][()]
                    cut = float(np.nanpercentile(v, 1))
                    columns = list(f["runs"])
                    info_cols = [c for c in columns
                                 if f["runs"][c].attrs.get("role") in ("parameter", b"parameter")]
                    info_cols += ["block", "status", "done", metric]
                    compact = [c for c in columns if f["runs"][c].attrs.get("role") in
                               ("parameter", b"parameter", "metric", b"metric")] + ["block", "status", "done"]
                where = ["--where", f"{metric}<{cut!r}", "--sort", metric, "--limit", "3"]
                runs = {"query": ([ks, "query", out, *where, "--columns", f"run_id,{metric}"],
                                  [metric, "run_id", "done"]),
                        "compact": ([ks, "query", out, *where], compact),
                        "group": ([ks, "query", out, "--group-by", "method", "--agg", f"min:{metric},count"],
                                  ["method", metric, "done"]),
                        "info": ([ks, "info", out], info_cols)}
                for name, (cmd, cols) in runs.items():
                    if name not in args.only:
                        continue
                    ours, rss, base = [], [], []
                    for _ in range(args.repeat):
                        t, r = timed(cmd)
                        ours.append(t)
                        rss.append(r)
                        base.append(h5py_read(out, cols))
                    report(name, ours, base, rss)
                ours, rss, base, frame = [], [], [], 0
                for _ in range(args.repeat if "pandas" in args.only else 0):
                    p = subprocess.run([sys.executable, "-c", PANDAS, out], capture_output=True, text=True, check=True)
                    seconds, frame = p.stdout.split()[-2:]
                    ours.append(float(seconds))  # to_pandas() alone (not the interpreter's start)
                    frame = int(frame)
                    base.append(h5py_read(out, columns))
                if ours:
                    t, r = timed([sys.executable, "-c", PANDAS, out])
                    rss.append(r)
                    report("pandas", ours, base, rss, f"   frame {frame / 1e6:.0f} MB (peak/frame {max(rss) / frame:.2f})")
                with h5py.File(out, "r") as f:
                    block = list(f["landscapes"])[0]
                    grids = [f"landscapes/{block}/{m}" for m in f["landscapes"][block]]
                drawn = {"plot": [f"landscapes/{block}/{'E' if kind == 'trajectory' else 'converged'}",
                                  f"landscapes/{block}/status_code"],
                         "report": [f"runs/{c}" for c in ("block", "status", "done", "run_id", metric)] + grids}
                for name, command in (("plot", "plot_landscape"), ("report", "report")):
                    if name not in args.only:
                        continue
                    ours, rss, base, base_rss, old, old_rss = [], [], [], [], [], []
                    page = out + "." + name + (".png" if name == "plot" else ".html")
                    for _ in range(args.repeat):  # alternated with the plain read of what it draws
                        t, r = timed([sys.executable, "-m", "kinesweep." + command, out, "-o", page], env=ANALYSIS_ENV)
                        ours.append(t)
                        rss.append(r)
                        t, r = timed([sys.executable, "-c", READ, out, *drawn[name]])
                        base.append(t)
                        base_rss.append(r)
                        if args.analysis_before:
                            t, r = timed([sys.executable, "-m", "kinesweep." + command, out, "-o", page],
                                         env=dict(os.environ, PYTHONPATH=args.analysis_before))
                            old.append(t)
                            old_rss.append(r)
                    (mn, md), (bmn, bmd) = stats(ours), stats(base)
                    print(f"  {name:<8} {mn:8.2f} s (median {md:6.2f})   peak {max(rss) / 1e6:7.0f} MB   "
                          f"output {os.path.getsize(page) / 1e6:.2f} MB   h5py read of what it draws "
                          f"({len(drawn[name])} datasets, a fresh interpreter) {bmn:.2f} s (median {bmd:.2f}, "
                          f"peak {max(base_rss) / 1e6:.0f} MB)   ratio {mn / bmn:.2f} (median {md / bmd:.2f})",
                          flush=True)
                    if old:
                        (omn, omd) = stats(old)
                        print(f"  {'before':<8} {omn:8.2f} s (median {omd:6.2f})   peak {max(old_rss) / 1e6:7.0f} MB   "
                              f"ratio {omn / bmn:.2f} (median {omd / bmd:.2f})   ({args.analysis_before})", flush=True)
                    os.remove(page)
                if args.mpi and kind == "trajectory":
                    mpi_merge(ks, study, out, args)
                if not args.keep:
                    os.remove(out)
    finally:
        if not args.keep and not args.workdir:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
