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

from e2e_common import TempDirTest, runs_column

KS = REPO = None

# One block per kind and IK family, every key omitted (the planar family is chosen by its problem;
# SCARA and planar IK blocks go in separate studies: their columns' units differ).
STUDIES = {
    "walk": """
[study]
name = "walk"
histories = "none"

[[block]]
name = "t"
kind = "trajectory"

[[block]]
name = "s"
kind = "ik"

# global_spline's own columns exist in blocks that run it
[[block]]
name = "g"
kind = "trajectory"
method = "global_spline"

# the task placement's columns (and ik_error) exist in blocks that name one of them
[[block]]
name = "pl"
kind = "trajectory"
task_rotation = 0.0
""",
    "walk_planar": """
[study]
name = "walk_planar"
histories = "none"

[[block]]
name = "t"
kind = "trajectory"

[[block]]
name = "p"
kind = "ik"
problem = "planar3r_position"
"""}
BLOCK_FAMILY = {("walk", "t"): ("trajectory", ""), ("walk", "s"): ("ik", "scara"), ("walk", "g"): ("trajectory", ""),
                ("walk", "pl"): ("trajectory", ""),
                ("walk_planar", "t"): ("trajectory", ""), ("walk_planar", "p"): ("ik", "planar3r")}


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


# IK metrics whose unit follows the problem family (engine/schema/ik_table.cpp): the SCARA's residual
# is in mm, a planar 3R problem's mixes m and rad; the SCARA's third joint is a length (mm), a planar
# 3R's an angle (rad). `kinesweep schema` shows the SCARA's.
PER_PROBLEM_UNITS = {"error": {"mm", "problem units"}, "q_final_3": {"mm", "rad"}}

class SchemaWalk(TempDirTest):
    @classmethod
    def setUpClass(cls):
        out = subprocess.run([KS, "schema", "--format", "json"], capture_output=True, text=True, check=True).stdout
        cls.schema = json.loads(out)
        # the seed robot's families (a chain robot's tables are walked by test_robots.py's studies)
        cls.tables = {(k["kind"], k["family"]): k for k in cls.schema["kinds"] if not k["family"].startswith("chain")}

    def run_walk(self):
        """name -> results file of each walk study."""
        outs = {}
        for name, text_ in STUDIES.items():
            study = self.write(name + ".toml", text_)
            outs[name] = os.path.join(self.dir, name + ".h5")
            r = subprocess.run([KS, "run", study, "-o", outs[name], "-q"], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
        return outs

    def test_every_column_is_self_described_and_omitted_keys_store_the_defaults(self):
        for name, out in self.run_walk().items():
            with h5py.File(out, "r") as f:
                self.check_file(name, f["runs"])

    def check_file(self, name, runs):
        blocks = runs_column(runs["block"]).tolist()
        for (kind, family), table in self.tables.items():
            rows = [i for i, b in enumerate(blocks) if BLOCK_FAMILY[(name, b)] == (kind, family)]
            if not rows:
                continue
            global_rows = [i for i in rows if blocks[i] == "g"]
            placement_rows = [i for i in rows if blocks[i] == "pl"]
            for p in table["params"]:
                only_global = p.get("effect_when") == ["global_spline"]
                if only_global and not global_rows:
                    continue  # a study without global_spline blocks has none of its columns
                only_placement = p["name"].startswith("task_")
                if only_placement and not placement_rows:
                    continue  # nor one without a block that places its task the placement's
                with self.subTest(study=name, kind=kind, family=family, param=p["name"]):
                    ds = runs[p["name"]]
                    self.assertEqual(text(ds.attrs["role"]), "parameter")
                    self.assertIn(kind, text(ds.attrs["kinds"]).split(","))
                    self.assertEqual(text(ds.attrs["unit"]), p["unit"])
                    self.assertIn(p["description"], text(ds.attrs["description"]))
                    if p["name"] == "problem":
                        continue  # the planar block names its problem
                    first = (global_rows if only_global else placement_rows if only_placement else rows)[0]
                    stored, default = runs_column(ds)[first], p["default"]
                    if p["type"] == "str":
                        self.assertEqual(stored, default)
                    elif default is None:
                        self.assertTrue(math.isnan(stored))
                    else:
                        self.assertEqual(float(stored), float(default))
            for m in table["metrics"]:
                if m["name"].startswith("opt_") and not global_rows:
                    continue
                if m["name"] == "ik_error" and not placement_rows:
                    continue
                with self.subTest(study=name, kind=kind, metric=m["name"]):
                    ds = runs[m["name"]]
                    self.assertEqual(text(ds.attrs["role"]), "metric")
                    if kind == "ik" and m["name"] in PER_PROBLEM_UNITS:  # the schema shows the SCARA's
                        self.assertIn(text(ds.attrs["unit"]), PER_PROBLEM_UNITS[m["name"]] | {m["unit"]})
                    else:
                        self.assertEqual(text(ds.attrs["unit"]), m["unit"])
                    self.assertIn(kind, text(ds.attrs["kinds"]).split(","))
        for col in self.schema["bookkeeping"]:
            self.assertEqual(text(runs[col].attrs["role"]), "bookkeeping")
            self.assertEqual(text(runs[col].attrs["kinds"]), "")

    def test_info_and_ksread_show_every_parameter_and_metric_with_its_role(self):
        out = self.run_walk()["walk"]
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
        from kinesweep import read as ksread
        with ksread.open_results(out) as r:
            roles = r.roles()
            for (kind, family), table in self.tables.items():
                if family == "planar3r":
                    continue  # its own study (the same parameter names)
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
