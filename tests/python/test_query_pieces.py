"""`kinesweep info` and `kinesweep query` read /runs in pieces (16384 rows): on a file of several
pieces, with blocks that cross piece boundaries, their answers equal numpy's over h5py's columns.

usage: /usr/bin/python3 test_query_pieces.py KINESWEEP_BINARY
"""
import csv
import io
import re
import subprocess
import sys
import unittest

import numpy as np

from e2e_common import StudyFileTest

KS = None

# 14400 + 22500 = 36900 runs: three pieces; the second block starts inside the first piece.
STUDY = """
[study]
name = "pieces"
histories = "none"

[[block]]
name = "first"
kind = "ik"
problem = "scara"
max_iter = 12
[block.axes]
q0_1 = { from = -180, to = 180, count = 120 }
q0_2 = { from = -180, to = 180, count = 120 }

[[block]]
name = "second"
kind = "ik"
problem = "scara"
method = "lm"
max_iter = 12
[block.axes]
q0_1 = { from = -170, to = 170, count = 150 }
q0_2 = { from = -170, to = 170, count = 150 }
"""


def ks(*args):
    r = subprocess.run([KS, *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout


class Pieces(StudyFileTest):
    NAME, STUDY = "pieces", STUDY

    @classmethod
    def setUpClass(cls):
        cls.KS = KS
        super().setUpClass()
        cls.out = cls.h5
        cls.block, cls.status = cls.runs["block"], cls.runs["status"]
        cls.iters, cls.error, cls.run_id = cls.runs["iterations"], cls.runs["error"], cls.runs["run_id"]

    def test_the_file_spans_several_pieces(self):
        self.assertEqual(len(self.run_id), 36900)

    def test_info_counts_and_best_rows_equal_numpy(self):
        text = ks("info", self.out, "--best", "4")
        for name, n in (("first", 14400), ("second", 22500)):
            sel = self.block == name
            line = re.search(rf"^{name}\s+ik\s+(\d+)\s+(\d+)\s+(.*)$", text, re.M)
            self.assertIsNotNone(line, text)
            self.assertEqual((int(line.group(1)), int(line.group(2))), (n, n))
            counts = dict((s, int(c)) for s, c in re.findall(r"(\w+) (\d+)", line.group(3)))
            values, numbers = np.unique(self.status[sel], return_counts=True)
            self.assertEqual(counts, dict(zip(values.tolist(), numbers.tolist())))
            good = sel & (self.status == "converged")
            order = np.lexsort((self.run_id[good], self.error[good], self.iters[good]))[:4]
            want = self.run_id[good][order].tolist()
            got = [int(x) for x in re.findall(rf"^  {name}\s+run\s+(\d+)", text, re.M)]
            self.assertEqual(got, want)

    def test_query_head_equals_the_head_of_the_whole_table(self):
        whole = ks("query", self.out).splitlines()
        head = ks("query", self.out, "-n", "5").splitlines()
        # The same compact columns (though 5 rows vary less) and rows; widths follow the rows printed.
        fields = lambda lines: [line.split() for line in lines]
        self.assertEqual(fields(head[:1] + head[2:-1]), fields(whole[:1] + whole[2:7]))
        self.assertIn("(5 of 36900 matching rows", head[-1])

    def test_query_filter_sort_limit_csv_equals_numpy(self):
        text = ks("query", self.out, "-f", "csv", "-w", "iterations<=6", "-w", "block=second", "-s", "error:desc",
                  "-n", "7", "-c", "run_id,error")
        rows = list(csv.DictReader(io.StringIO(text)))
        sel = (self.iters <= 6) & (self.block == "second") & (self.status != "")
        idx = np.nonzero(sel)[0]
        order = idx[np.lexsort((idx, -self.error[idx]))][:7]  # stable: ties in run-id order
        self.assertEqual([int(r["run_id"]) for r in rows], self.run_id[order].tolist())

    def test_query_group_by_equals_numpy(self):
        text = ks("query", self.out, "-f", "csv", "-g", "block,status", "--agg", "count,min:iterations")
        got = {(r["block"], r["status"]): (int(r["count"]), float(r["min(iterations)"]))
               for r in csv.DictReader(io.StringIO(text))}
        want = {}
        for b, s in set(zip(self.block.tolist(), self.status.tolist())):
            m = (self.block == b) & (self.status == s)
            want[(b, s)] = (int(m.sum()), float(self.iters[m].min()))
        self.assertEqual(got, want)


if __name__ == "__main__":
    KS = sys.argv[1]
    unittest.main(argv=sys.argv[:1], verbosity=2)
