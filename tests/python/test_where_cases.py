"""The --where language's shared cases (tests/query/where_cases.json), run by both implementations
on one results file: `kinesweep query --where ... --format json` and kinesweep.where.select (also
through the reader's row filter, to_pandas(where=) and runs(where=)). Each must select the rows the
case's numpy oracle selects, or refuse with the case's message and
suggestion.

usage: /usr/bin/python3 test_where_cases.py KINESWEEP_BINARY SOURCE_DIR
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

KS = None
SOURCE = None


class WhereCases(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, os.path.join(SOURCE, "analysis"))
        with open(os.path.join(SOURCE, "tests", "query", "where_cases.json")) as f:
            cls.spec = json.load(f)
        cls.tmp = tempfile.TemporaryDirectory()
        study = os.path.join(cls.tmp.name, "where_cases.toml")
        with open(study, "w") as f:
            f.write(cls.spec["study"])
        cls.out = os.path.join(cls.tmp.name, "where_cases.h5")
        r = subprocess.run([KS, "run", study, "-o", cls.out, "-q"], capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        from kinesweep import read as ksread
        with ksread.open_results(cls.out) as res:
            cls.table = res.runs(degrees=True)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def cli(self, where):
        args = [KS, "query", self.out, "--columns", "run_id", "--format", "json", "--limit", "100000"]
        for w in where:
            args += ["--where", w]
        return subprocess.run(args, capture_output=True, text=True, timeout=120)

    def test_every_case_in_both_implementations(self):
        from kinesweep import read as ksread
        from kinesweep import where as kswhere
        c = {k: (np.asarray(v, dtype=object) if np.asarray(v).dtype.kind in "OUS" else np.asarray(v))
             for k, v in self.table.items()}
        ids = np.asarray(self.table["run_id"])
        self.assertGreater(len(self.spec["cases"]), 15)
        for case in self.spec["cases"]:
            where = case["where"]
            with self.subTest(where=where):
                r = self.cli(where)
                if "oracle" in case:
                    with np.errstate(invalid="ignore"):
                        want = sorted(int(i) for i in ids[np.asarray(eval(case["oracle"], {"np": np, "c": c}), bool)])
                    self.assertGreater(len(want), 0, "a case that selects nothing tests little")
                    self.assertEqual(r.returncode, 0, r.stderr)
                    got_cli = sorted(row["run_id"] for row in json.loads(r.stdout)["rows"])
                    self.assertEqual(got_cli, want, "kinesweep query")
                    got_py = sorted(int(i) for i in ids[kswhere.select(self.table, where)])
                    self.assertEqual(got_py, want, "kswhere")
                    with ksread.open_results(self.out) as res:  # the reader's row filter
                        df = res.to_pandas(where=where)
                        t = res.runs(columns=["run_id", "E"], where=where)
                    self.assertEqual(sorted(df["run_id"].tolist()), want, "to_pandas(where=)")
                    self.assertEqual(sorted(t["run_id"].tolist()), want, "runs(where=)")
                else:
                    self.assertEqual(r.returncode, 2, r.stdout)
                    self.assertIn(case["error"], r.stderr)
                    with self.assertRaises(kswhere.WhereError) as e:
                        kswhere.select(self.table, where)
                    self.assertIn(case["error"], str(e.exception))
                    with ksread.open_results(self.out) as res, self.assertRaises(kswhere.WhereError) as e2:
                        res.to_pandas(where=where)
                    self.assertIn(case["error"], str(e2.exception))
                    if "suggest" in case:
                        self.assertIn(f"did you mean '{case['suggest']}'", r.stderr)
                        self.assertIn(f"did you mean '{case['suggest']}'", str(e.exception))


if __name__ == "__main__":
    KS = os.path.abspath(sys.argv[1])
    SOURCE = os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"])
