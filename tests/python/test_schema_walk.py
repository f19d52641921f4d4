"""The parameter and metric tables, end to end: every parameter and metric `kinesweep schema`
declares appears in /runs with its unit, role and kinds attributes (read by h5py), in `kinesweep
info`, and in ksread with its role; and a study that omits every key stores each table default.

usage: /usr/bin/python3 test_schema_walk.py KINESWEEP_BINARY REPO_DIR
"""
import json
import math
import os
import subprocess
import sys
import unittest

import h5py

from e2e_common import TempDirTest

KS = REPO = None

# One block per kind and IK family, every key omitted (the planar family is chosen by its problem).
STUDY = """
[study]
name = "walk"
histories = "none"

[[block]]
name = "t"
kind = "trajectory"

[[block]]
name = "s"
kind = "ik"

[[block]]
name = "p"
kind = "ik"
problem = "planar3r_position"
"""
BLOCK_FAMILY = {"t": ("trajectory", ""), "s": ("ik", "scara"), "p": ("ik", "planar3r")}


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


class SchemaWalk(TempDirTest):
    @classmethod
    def setUpClass(cls):
        out = subprocess.run([KS, "schema", "--format", "json"], capture_output=True, text=True, check=True).stdout
        cls.schema = json.loads(out)
        cls.tables = {(k["kind"], k["family"]): k for k in cls.schema["kinds"]}

    def run_walk(self):
        study = self.write("walk.toml", STUDY)
        out = os.path.join(self.dir, "walk.h5")
        r = subprocess.run([KS, "run", study, "-o", out, "-q"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        return out

    def test_every_column_is_self_described_and_omitted_keys_store_the_defaults(self):
        out = self.run_walk()
        with h5py.File(out, "r") as f:
            runs = f["runs"]
            blocks = [text(b) for b in runs["block"][()]]
            for (kind, family), table in self.tables.items():
                row = [i for i, b in enumerate(blocks) if BLOCK_FAMILY[b] == (kind, family)][0]
                for p in table["params"]:
                    with self.subTest(kind=kind, family=family, param=p["name"]):
                        ds = runs[p["name"]]
                        self.assertEqual(text(ds.attrs["role"]), "parameter")
                        self.assertIn(kind, text(ds.attrs["kinds"]).split(","))
                        if family != "planar3r":  # a column shared by both families keeps the first's unit
                            self.assertEqual(text(ds.attrs["unit"]), p["unit"])
                        self.assertIn(p["description"], text(ds.attrs["description"]))
                        if p["name"] == "problem":
                            continue  # the planar block names its problem
                        stored, default = ds[row], p["default"]
                        if p["type"] == "str":
                            self.assertEqual(text(stored), default)
                        elif default is None:
                            self.assertTrue(math.isnan(stored))
                        else:
                            self.assertEqual(float(stored), float(default))
                for m in table["metrics"]:
                    with self.subTest(kind=kind, metric=m["name"]):
                        ds = runs[m["name"]]
                        self.assertEqual(text(ds.attrs["role"]), "metric")
                        self.assertEqual(text(ds.attrs["unit"]), m["unit"])
                        self.assertIn(kind, text(ds.attrs["kinds"]).split(","))
            for name in self.schema["bookkeeping"]:
                self.assertEqual(text(runs[name].attrs["role"]), "bookkeeping")
                self.assertEqual(text(runs[name].attrs["kinds"]), "")

    def test_info_and_ksread_show_every_parameter_and_metric_with_its_role(self):
        out = self.run_walk()
        info = subprocess.run([KS, "info", out], capture_output=True, text=True)
        self.assertEqual(info.returncode, 0, info.stderr)
        lines = {}
        for line in info.stdout.splitlines():
            for label in ("parameters", "metrics"):
                for kind in ("trajectory", "ik"):
                    head = f"{label} {kind}: "
                    if line.strip().startswith(head):
                        lines[(label, kind)] = [c.split(" [")[0] for c in line.strip()[len(head):].split(", ")]
        sys.path.insert(0, os.path.join(REPO, "analysis"))
        import ksread
        with ksread.open_results(out) as r:
            roles = r.roles()
            for (kind, family), table in self.tables.items():
                for p in table["params"]:
                    self.assertIn(p["name"], lines[("parameters", kind)])
                    self.assertEqual(roles[p["name"]], "parameter")
                    self.assertIn(p["name"], r.parameters(kind))
                for m in table["metrics"]:
                    self.assertIn(m["name"], lines[("metrics", kind)])
                    self.assertEqual(roles[m["name"]], "metric")
                    self.assertIn(m["name"], r.metrics(kind))


if __name__ == "__main__":
    KS, REPO = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"])
