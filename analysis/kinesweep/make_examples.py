#!/usr/bin/python3
"""Regenerate results/examples/*.png (the pictures in the README's "Explore results").

    python3 -m kinesweep.make_examples [--kinesweep build/kinesweep] [--work /tmp/ks_examples]

Runs the small studies studies/examples_*.toml, studies/thesis_table4.toml and studies/placement_scara1.toml
(seconds), and the small
optimisation study below (OPTIMIZATION_STUDY, written to the work directory), then every plot script at
800x600 (basins 1200x500), dpi 100. results/examples/report.png (a screenshot of the page of
kinesweep.report, taken with headless Chromium) is not regenerated here: the analysis README says how
it was taken. It works in a kinesweep source tree only (it reads its studies/ and writes its results/).
"""
import argparse
import os
import subprocess
import sys

PACKAGE_PARENT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # analysis/ in a source tree
ROOT = os.path.dirname(PACKAGE_PARENT)  # the source tree: studies/, results/examples/, build/

# Sweep then polish for Table 4's row 1h on a 0.25 deg x 0.02 landscape near the reach boundary (where
# the optimum is), with a small GA-like global stage too (the picture shows all three stages):
# `python3 -m kinesweep.plot_landscape --optimization 1h` overlays it. 49 x 26 runs + ~500 evaluations, < 1 s.
OPTIMIZATION_STUDY = """
[study]
name = "examples_optimization"
description = "E(alpha1A, k) of local_weighted, then an optimisation of row 1h (example picture)"
histories = "none"

[robot]
inertia = "thesis_m11"

[[block]]
name = "local_weighted"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { from = -26, to = -14, step = 0.25 }
k = { from = 0, to = 0.5, step = 0.02 }

[[optimize]]
name = "1h"
preset = "1h"
variables = { alpha1A = [-26, -14], k = [0, 0.5] }
polish_from = { block = "local_weighted", best = 3 }
[optimize.global]
algorithm = "GN_ESCH"
population = 20
max_evals = 150
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 100
xtol_rel = 1e-10
"""


def main():
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.make_examples", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--kinesweep", default=os.path.join(ROOT, "build", "kinesweep"))
    p.add_argument("--work", default="/tmp/ks_examples", help="where the .h5 files go")
    p.add_argument("--out", default=os.path.join(ROOT, "results", "examples"))
    a = p.parse_args()
    if not os.path.isdir(os.path.join(ROOT, "studies")):
        raise SystemExit("make_examples regenerates a source tree's results/examples from its studies/: run it "
                         "from a kinesweep source tree (PYTHONPATH=analysis python3 -m kinesweep.make_examples), "
                         "not from an installed package")
    os.makedirs(a.work, exist_ok=True)
    os.makedirs(a.out, exist_ok=True)
    h5 = {}
    for s in ("thesis_table4", "examples_landscape", "examples_basins", "examples_convergence", "examples_lhs",
              "placement_scara1", "motion_elbow"):
        h5[s] = os.path.join(a.work, s + ".h5")
        subprocess.run([a.kinesweep, "run", os.path.join(ROOT, "studies", s + ".toml"), "-o", h5[s],
                        "--overwrite", "-q"], check=True, stdout=subprocess.DEVNULL)
    study = os.path.join(a.work, "examples_optimization.toml")
    with open(study, "w") as f:
        f.write(OPTIMIZATION_STUDY)
    h5["examples_optimization"] = os.path.join(a.work, "examples_optimization.h5")
    subprocess.run([a.kinesweep, "run", study, "-o", h5["examples_optimization"], "--overwrite", "-q"], check=True,
                   stdout=subprocess.DEVNULL)
    py = sys.executable
    jobs = [
        ("plot_landscape", h5["examples_landscape"], "landscape_E_weighted.png",
         ["--fix", "method=local_weighted", "--log", "--thesis"]),
        ("plot_landscape", h5["examples_landscape"], "landscape_tau_inf_unweighted.png",
         ["--fix", "method=local_unweighted", "--metric", "tau_inf", "--log", "--thesis"]),
        ("plot_landscape", h5["examples_basins"], "landscape_convergence.png",
         ["--metric", "convergence", "--x", "q0_1", "--y", "q0_2", "--levels", "0"]),
        ("plot_histories", h5["thesis_table4"], "histories_1a_1c_1e.png", ["--preset", "1a,1c,1e"]),
        ("plot_cases", h5["thesis_table4"], "cases_E.png", []),
        ("plot_basins", h5["examples_basins"], "basins.png", ["--size", "1200x500"]),
        ("plot_convergence", h5["examples_convergence"], "convergence.png", []),
        ("plot_landscape", h5["examples_optimization"], "landscape_optimization.png",
         ["--optimization", "1h", "--log"]),
        ("plot_runs", h5["examples_lhs"], "runs_scatter_lhs.png",
         ["--view", "scatter", "--x", "alpha1A", "--y", "k", "--facet", "method", "--size", "1100x500"]),
        ("plot_runs", h5["examples_lhs"], "runs_slice_lambda.png",
         ["--view", "slice", "--block", "lm_lambda", "--size", "1100x450"]),
        ("plot_runs", h5["examples_lhs"], "runs_parcoords.png", ["--view", "parcoords"]),
        ("plot_trade_off", h5["placement_scara1"], "trade_off_scara1.png",
         ["--mark", f"{0.108 / 0.067},{5.261 / 6.451}:Santos 2007, Table 7.5 (k = 0.9)"]),
        ("plot_motion", h5["motion_elbow"], "motion_elbow.png",
         ["--runs", "0,4", "--title", "Seed 002 7.4: the cubic through the cube (run 0), K = 4 past it (run 4)"]),
    ]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [PACKAGE_PARENT, os.environ.get("PYTHONPATH")])))
    for command, f, out, extra in jobs:
        subprocess.run([py, "-m", "kinesweep." + command, f, "-o", os.path.join(a.out, out), *extra], check=True,
                       env=env)
        shrink(os.path.join(a.out, out))
    return 0


def shrink(png, limit=120_000):
    """Lossless re-compression when Pillow is there; a 256-colour palette only for a picture still
    above `limit` bytes (the committed pictures stay under 150 KB)."""
    try:
        from PIL import Image
    except ImportError:
        return
    im = Image.open(png).convert("RGB")
    im.save(png, optimize=True)
    if os.path.getsize(png) > limit:
        im.quantize(colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE).save(png, optimize=True)


if __name__ == "__main__":
    sys.exit(main())
