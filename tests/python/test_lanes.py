"""Runs in SIMD lanes give the results of runs computed one at a time, bit for bit: the same /runs,
histories and landscapes whatever `--lanes` (1, 4, 8) and `--threads`.

usage: /usr/bin/python3 test_lanes.py KINESWEEP_BINARY STUDIES_DIR
"""
import os
import subprocess
import sys
import unittest

import h5py
import numpy as np

from e2e_common import TempDirTest, bitwise_equal
from regression_hashes import hash_results

KS = None
STUDIES = None


def cpu_flags():
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("flags"):
                return set(line.split(":", 1)[1].split())
    return set()


FLAGS = cpu_flags()
WIDTHS = [1] + ([4] if "avx2" in FLAGS else []) + ([8] if {"avx512f", "avx512dq"} <= FLAGS else [])


def landscapes(path):
    with h5py.File(path, "r") as f:
        out = {}
        if "landscapes" in f:
            f["landscapes"].visititems(lambda name, d: out.__setitem__(name, d[()]) if isinstance(d, h5py.Dataset) else None)
        return out


class Lanes(TempDirTest):
    def run_study(self, name, lanes, threads, histories):
        out = os.path.join(self.dir, f"{name}_l{lanes}_t{threads}.h5")
        r = subprocess.run([KS, "run", os.path.join(STUDIES, name + ".toml"), "-o", out, "-q", "--lanes", str(lanes),
                            "--threads", str(threads), "--histories", histories], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        return out

    def check_study(self, name, histories):
        ref = self.run_study(name, 1, 1, histories)
        ref_hash, ref_land = hash_results(ref), landscapes(ref)
        self.assertTrue(ref_land or name == "thesis_table4")
        for lanes in WIDTHS:
            for threads in (1, 2):
                if (lanes, threads) == (1, 1):
                    continue
                with self.subTest(lanes=lanes, threads=threads):
                    out = self.run_study(name, lanes, threads, histories)
                    self.assertEqual(hash_results(out), ref_hash)
                    got = landscapes(out)
                    self.assertEqual(got.keys(), ref_land.keys())
                    for k in got:
                        self.assertTrue(bitwise_equal(got[k], ref_land[k]), k)

    def test_landscape_alpha_k(self):
        self.check_study("landscape_alpha_k", "none")

    def test_thesis_table4_with_full_histories(self):
        self.check_study("thesis_table4", "full")

    def test_lanes_other_than_1_4_8_are_refused(self):
        r = subprocess.run([KS, "run", os.path.join(STUDIES, "thesis_table4.toml"), "-o",
                            os.path.join(self.dir, "x.h5"), "--lanes", "3"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 2)
        self.assertIn("--lanes", r.stderr)


if __name__ == "__main__":
    KS, STUDIES = sys.argv[1], sys.argv[2]
    print("lane widths this processor runs:", WIDTHS)
    unittest.main(argv=sys.argv[:1], verbosity=2)
