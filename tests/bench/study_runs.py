"""A study written from text, run by kinesweep in a temporary directory, its /runs read back by
kinesweep.read: what the path_global_* benchmark scripts share. Run with /usr/bin/python3."""
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
from kinesweep import read as ksread  # noqa: E402


# The 7-DOF arm (studies/robots/arm7.urdf) on its square in space, each side `d` seconds, sampled every
# 4 ms and integrated by RK4: the [robot] and [task] tables of the path_global_arm7 benchmarks
# (format with urdf= and d=).
ARM7_SQUARE = """
[robot]
urdf = "{urdf}"
base = "base_link"
tip = "tool"
gravity = [0, 0, -9.81]

[task]
vertices = [[0.5, -0.1, 0.4], [0.5, 0.1, 0.4], [0.5, 0.1, 0.6], [0.5, -0.1, 0.6], [0.5, -0.1, 0.4]]
durations = [{d}, {d}, {d}, {d}]
integrator = "rk4"
dt = 0.004
"""


def run_study(kinesweep, text, threads="2", degrees=False):
    """The done rows of /runs (ksread's Table) of the study `text` run by `kinesweep` (without the best
    runs' grid verification: only /runs is read)."""
    with tempfile.TemporaryDirectory() as tmp:
        study, out = os.path.join(tmp, "study.toml"), os.path.join(tmp, "study.h5")
        with open(study, "w") as f:
            f.write(text)
        subprocess.run([kinesweep, "run", study, "-o", out, "-q", "--threads", str(threads), "--no-verify-best"], check=True,
                       capture_output=True)
        with ksread.open_results(out) as r:
            return r.runs(degrees=degrees)
