"""A study written from text, run by kinesweep in a temporary directory, its /runs read back by
kinesweep.read: what the path_global_* benchmark scripts share. Run with /usr/bin/python3."""
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
from kinesweep import read as ksread  # noqa: E402


def run_study(kinesweep, text, threads="2", degrees=False):
    """The done rows of /runs (ksread's Table) of the study `text` run by `kinesweep`."""
    with tempfile.TemporaryDirectory() as tmp:
        study, out = os.path.join(tmp, "study.toml"), os.path.join(tmp, "study.h5")
        with open(study, "w") as f:
            f.write(text)
        subprocess.run([kinesweep, "run", study, "-o", out, "-q", "--threads", str(threads)], check=True,
                       capture_output=True)
        with ksread.open_results(out) as r:
            return r.runs(degrees=degrees)
