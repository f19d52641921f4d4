"""The trajectory kernel in lanes against the lane probe (lane_probe.hpp), from bench_lane_probe run
in one process: CPU time per run (counter per_run) of Kernel/1, /4, /8, Probe/1, /4, /8 (the probe
computing E only: the per-step arithmetic) and ProbeMetrics/1, /4, /8 (the probe computing every
metric the kernel stores for these runs: E, E_M, tau_inf, min manipulability, the torque and power
integrals, tracking errors, final alpha, peak joint power, end joint rate, end kinetic energy), min
and median of the repetitions, and the ratios of things measured in the same process: kernel /
probe at 8 and at 4 lanes against each probe (<= 1.0 is the requirement at 8, like for like: the
same metrics), kernel 1 lane / kernel 8 lanes (>= 7 required), and the probes' own 1 / 8. --rounds N runs the binary N times and prints every round (the machine is
shared: the spread between rounds is part of the figure).

usage: /usr/bin/python3 tests/bench/lane_probe_ratios.py build/bench/bench_lane_probe [--rounds 1]
       [--repetitions 7] [--interleave]
"""
import argparse
import json
import subprocess


def run_once(binary, repetitions, interleave):
    cmd = [binary, f"--benchmark_repetitions={repetitions}", "--benchmark_report_aggregates_only=true",
           "--benchmark_format=json"]
    if interleave:
        cmd.append("--benchmark_enable_random_interleaving=true")
    out = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    per_run = {}  # (name, aggregate) -> seconds
    for b in out["benchmarks"]:
        if b.get("run_type") != "aggregate" or "per_run" not in b:
            continue
        per_run[(b["run_name"], b["aggregate_name"])] = b["per_run"]
    return cmd, per_run


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--repetitions", type=int, default=7)
    ap.add_argument("--interleave", action="store_true", help="--benchmark_enable_random_interleaving=true")
    a = ap.parse_args()
    names = ["Kernel/1", "Kernel/4", "Kernel/8", "Probe/1", "Probe/4", "Probe/8", "ProbeMetrics/1", "ProbeMetrics/4",
             "ProbeMetrics/8"]
    for r in range(a.rounds):
        cmd, pr = run_once(a.binary, a.repetitions, a.interleave)
        if r == 0:
            print(" ".join(cmd))
        print(f"round {r + 1}: per run [us], min / median of {a.repetitions}")
        for n in names:
            if (n, "min") in pr:
                print(f"  {n:15s} {pr[(n, 'min')] * 1e6:8.2f} / {pr[(n, 'median')] * 1e6:8.2f}")
        ratios = [("kernel 8 / probe(all metrics) 8", "Kernel/8", "ProbeMetrics/8"),
                  ("kernel 4 / probe(all metrics) 4", "Kernel/4", "ProbeMetrics/4"),
                  ("kernel 8 / probe(E only) 8", "Kernel/8", "Probe/8"),
                  ("kernel 4 / probe(E only) 4", "Kernel/4", "Probe/4"),
                  ("kernel 1 / kernel 8", "Kernel/1", "Kernel/8"),
                  ("probe(all metrics) 1 / 8", "ProbeMetrics/1", "ProbeMetrics/8"),
                  ("probe(E only) 1 / 8", "Probe/1", "Probe/8")]
        for label, x, y in ratios:
            if (x, "min") in pr and (y, "min") in pr:
                print(f"  {label:32s} {pr[(x, 'min')] / pr[(y, 'min')]:6.3f} (min) "
                      f"{pr[(x, 'median')] / pr[(y, 'median')]:6.3f} (median)")


if __name__ == "__main__":
    main()
