"""The run kinds' meaning as a results file records it (/kinds/<kind>): the same as the Python
readers' fallback for older files (kstypes.KIND_MEANING), objectives = every numeric metric column
of the kind plus failure_rate (read from the /runs column attributes), history arrays named and
united as the runs' histories are written; every metric's display name recorded once per column and
landscape metric, the same in both, read by ksread (and the fallback table for older files agrees).

usage: /usr/bin/python3 test_kinds.py KINESWEEP_BINARY ANALYSIS_DIR
"""
import os
import subprocess
import sys
import tempfile
import unittest

import h5py

from e2e_common import TempDirTest, history, runs_column

KS = None

STUDY = """
[study]
name = "kinds"
histories = "full"

[robot]
l = [1.0, 1.0, 0.5, 0.5]
m = [5.0, 2.0, 0.5, 0.5]
b = 0.1

[[block]]
name = "traj"
kind = "trajectory"
[block.axes]
alpha1A = [0, 10]
k = [0, 0.5]

[[block]]
name = "scara"
kind = "ik"
problem = "scara"
method = "newton"
[block.axes]
q0_1 = [-30, 30]
"""


def strings(values):
    return [v.decode() if isinstance(v, bytes) else str(v) for v in values]


class Kinds(TempDirTest):
    @classmethod
    def setUpClass(cls):
        cls.shared = tempfile.TemporaryDirectory()
        study = os.path.join(cls.shared.name, "kinds.toml")
        with open(study, "w") as f:
            f.write(STUDY)
        cls.out = os.path.join(cls.shared.name, "kinds.h5")
        r = subprocess.run([KS, "run", study, "-o", cls.out, "-q"], capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr

    @classmethod
    def tearDownClass(cls):
        cls.shared.cleanup()

    def test_the_file_records_each_kind_it_holds(self):
        from kinesweep import kinds as kstypes
        with h5py.File(self.out, "r") as f:
            self.assertEqual(sorted(f["kinds"]), ["ik", "trajectory"])
            for kind in ("trajectory", "ik"):
                a = {k: strings(v) for k, v in f["kinds"][kind].attrs.items()}
                fallback = kstypes.KIND_MEANING[kind]
                for key in ("statuses", "good_statuses", "ranking", "key_metrics", "history_arrays",
                            "resume_context"):
                    self.assertEqual(a[key], fallback[key], f"{kind} {key}")
                self.assertEqual(a["good_statuses"], a["statuses"][:1])
                # objectives: every numeric metric column of the kind, in /runs order, and failure_rate
                numeric = []
                for c in strings(f["runs"].attrs["columns"]):
                    at = f["runs"][c].attrs
                    kinds = [k for k in strings([at["kinds"]])[0].split(",") if k]
                    if strings([at["role"]])[0] == "metric" and (not kinds or kind in kinds) \
                            and strings([at["type"]])[0] != "str":
                        numeric.append(c)
                self.assertEqual(a["objectives"], numeric + ["failure_rate"], kind)
            self.assertIn("tau4_inf", strings(f["kinds"]["trajectory"].attrs["objectives"]))
            self.assertNotIn("tau5_inf", strings(f["kinds"]["trajectory"].attrs["objectives"]))

    def test_history_arrays_are_the_ones_written(self):
        with h5py.File(self.out, "r") as f:
            blocks = runs_column(f["runs"]["block"]).tolist()
            traj, ik = blocks.index("traj"), blocks.index("scara")
            t = f["kinds"]["trajectory"].attrs
            h = history(f, traj)
            self.assertEqual(list(h), strings(t["history_arrays"]))
            self.assertEqual(h["q"].shape[1], 4)  # the 4R arm's joints
            from kinesweep.history import Histories
            units = [u for _n, _a, u in Histories(f).read(traj)]
            self.assertEqual(units, strings(t["history_units"]))
            self.assertEqual(list(history(f, ik)), strings(f["kinds"]["ik"].attrs["history_arrays"]))

    def test_ksread_reads_the_meaning_and_falls_back_for_older_files(self):
        from kinesweep import read as ksread
        with ksread.open_results(self.out) as res:
            m = res.kind_meaning("ik")
            self.assertEqual(m["ranking"], ["iterations", "error"])
            self.assertEqual(res.landscape("traj").objective, "E")
            self.assertEqual(res.landscape("traj").status_grids(), ("ok", "status_code"))
        old = os.path.join(self.dir, "old.h5")
        with open(self.out, "rb") as a, open(old, "wb") as b:
            b.write(a.read())
        with h5py.File(old, "r+") as f:
            del f["kinds"]
        with ksread.open_results(old) as res:
            self.assertEqual(res.kind_meaning("trajectory")["good_statuses"], ["ok"])
            self.assertEqual(res.kind_meaning("nonsense"), {})


    def copy_with_kinds(self, name, edit):
        """A copy of the study's file whose /kinds attributes `edit` changes (a file written by an
        engine that declares its kinds otherwise)."""
        path = os.path.join(self.dir, name)
        with open(self.out, "rb") as a, open(path, "wb") as b:
            b.write(a.read())
        with h5py.File(path, "r+") as f:
            edit(f["kinds"])
        return path

    def test_the_commands_read_a_kinds_meaning_from_the_file(self):
        def rank_by_peak_torque(kinds):
            t = kinds["trajectory"]
            t.attrs.create("ranking", ["tau_inf"], dtype=h5py.string_dtype())
            t.attrs.create("key_metrics", ["tau_inf", "min_manipulability"], dtype=h5py.string_dtype())
        other = self.copy_with_kinds("other.h5", rank_by_peak_torque)
        from kinesweep import read as ksread
        with ksread.open_results(other) as res:
            df = res.to_pandas()
        ok = df[(df.block == "traj") & (df.status == "ok")]
        ranked = sorted(zip(ok.tau_inf, ok.run_id))  # the file's ranking: tau_inf, then run id
        self.assertNotEqual(ranked[0][1], ok.run_id[ok.E.idxmin()])  # this engine's (E) would pick another
        info = subprocess.run([KS, "info", other, "--best", "1"], capture_output=True, text=True, timeout=60)
        self.assertEqual(info.returncode, 0, info.stderr)
        self.assertIn("trajectory: tau_inf among ok runs", info.stdout)
        self.assertNotIn("trajectory: E among", info.stdout)
        # the best row of the block is the lowest tau_inf among its ok runs (not the lowest E)
        best_rows = [l.split() for l in info.stdout.splitlines() if l.strip().startswith("traj ") and " run " in l]
        self.assertEqual([int(r[2]) for r in best_rows], [ranked[0][1]], info.stdout)
        self.assertIn("tau_inf =", " ".join(" ".join(r) for r in best_rows))
        # compare's default metric is the file's ranking objective
        cmp = subprocess.run([KS, "compare", other, "--format", "csv"], capture_output=True, text=True, timeout=60)
        self.assertEqual(cmp.returncode, 0, cmp.stderr)
        self.assertIn("tau_inf", cmp.stdout)
        self.assertNotIn(",E,", cmp.stdout)
        # query's compact table shows the file's key metrics of the kind
        q = subprocess.run([KS, "query", other, "-w", "block=traj"], capture_output=True, text=True, timeout=60)
        self.assertEqual(q.returncode, 0, q.stderr)
        header = q.stdout.splitlines()[0]
        self.assertIn("min_manipulability", header)
        self.assertNotIn("E [Nm]", header)

        # a status the file declares good is counted so; one it does not is not
        def nothing_good(kinds):
            kinds["trajectory"].attrs.create("good_statuses", ["no_such_status"], dtype=h5py.string_dtype())
        none = self.copy_with_kinds("none.h5", nothing_good)
        info = subprocess.run([KS, "info", none], capture_output=True, text=True, timeout=60)
        self.assertEqual(info.returncode, 0, info.stderr)
        self.assertIn("traj: no no_such_status run", info.stdout)

    def test_every_metric_has_one_display_name_that_the_readers_use(self):
        from kinesweep import read as ksread
        from kinesweep import kinds as kstypes
        with h5py.File(self.out, "r") as f:
            shown = {}
            for c in strings(f["runs"].attrs["columns"]):
                at = f["runs"][c].attrs
                if strings([at["role"]])[0] == "metric":
                    self.assertIn("display_name", at, c)
                    shown[c] = strings([at["display_name"]])[0]
                    self.assertTrue(shown[c], c)
                else:
                    self.assertNotIn("display_name", at, c)
            for block in f["landscapes"]:
                g = f["landscapes"][block]
                for m in strings(g.attrs["metrics"]):
                    want = shown.get(m, m)  # the status grids (ok, converged, status_code): their names
                    self.assertEqual(strings([g[m].attrs["display_name"]])[0], want, f"{block}/{m}")
        self.assertEqual(shown["E"], "E (mean ‖τ‖)")
        self.assertEqual(shown["tau4_inf"], "‖τ4‖∞")
        self.assertEqual(shown["q_final_1"], "q_final_1")  # no label: the name
        # the fallback for older files says what the engine says, for every metric it lists
        for m, label in kstypes.METRIC_LABELS.items():
            if m in shown:
                self.assertEqual(label, shown[m], m)
        with ksread.open_results(self.out) as res:
            self.assertEqual(res.landscape("traj").label("tau_inf"), shown["tau_inf"])
            self.assertEqual(res.runs(["error"]).display_names["error"], shown["error"])
        old = os.path.join(self.dir, "old.h5")
        with open(self.out, "rb") as a, open(old, "wb") as b:
            b.write(a.read())
        with h5py.File(old, "r+") as f:
            del f["runs"]["E"].attrs["display_name"]
            del f["landscapes"]["traj"]["E"].attrs["display_name"]
        with ksread.open_results(old) as res:
            self.assertEqual(res.landscape("traj").label("E"), kstypes.METRIC_LABELS["E"])
            self.assertEqual(res.runs(["E"]).display_names["E"], kstypes.METRIC_LABELS["E"])

if __name__ == "__main__":
    KS = os.path.abspath(sys.argv[1])
    sys.path.insert(0, os.path.abspath(sys.argv[2]))
    unittest.main(argv=[sys.argv[0], "-v"])
