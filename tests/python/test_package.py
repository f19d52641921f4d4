"""analysis/ as one Python package: `python3 -m kinesweep.NAME` runs each command (analysis/ holds no
scripts beside the package), the former flat module names are the package's modules (one module
object) after `import kinesweep.compat` and not before, and importing the package does not import
h5py until the reader is used.

usage: /usr/bin/python3 test_package.py KINESWEEP REPO_ROOT
"""
import os
import subprocess
import sys
import tempfile
import unittest

KS, ROOT = sys.argv[1], sys.argv[2]
ANALYSIS = os.path.join(ROOT, "analysis")
ENV = dict(os.environ, PYTHONPATH=ANALYSIS)
# The former flat names and the package modules they stand for (kinesweep.compat.OLD_NAMES).
FORMER = {"ksread": "read", "kswhere": "where", "kshistory": "history", "kslive": "live", "kstypes": "kinds",
          "kssolutions": "solutions", "ksplot": "plotting", "plot_landscape": "plot_landscape",
          "plot_histories": "plot_histories", "plot_cases": "plot_cases", "plot_basins": "plot_basins",
          "plot_convergence": "plot_convergence", "plot_runs": "plot_runs",
          "compare_landscapes": "compare_landscapes", "importance": "importance", "report": "report",
          "make_examples": "make_examples"}
TMP = tempfile.TemporaryDirectory()
H5 = os.path.join(TMP.name, "t4.h5")


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, check=True, cwd=TMP.name, **kw)


def setUpModule():
    run([KS, "run", os.path.join(ROOT, "studies", "thesis_table4.toml"), "-o", H5, "-q"])


def tearDownModule():
    TMP.cleanup()


class Package(unittest.TestCase):
    def test_lists_its_commands(self):
        sys.path.insert(0, ANALYSIS)
        import kinesweep
        out = run(["/usr/bin/python3", "-m", "kinesweep"], env=ENV).stdout
        for name in kinesweep.COMMANDS:
            self.assertIn(name, out)
            self.assertTrue(os.path.exists(os.path.join(ANALYSIS, "kinesweep", name + ".py")), name)
        self.assertEqual([f for f in os.listdir(ANALYSIS) if f.endswith(".py")], [])

    def test_commands_run_as_modules(self):
        for name in ("plot_cases", "plot_histories"):
            with self.subTest(name):
                out = run(["/usr/bin/python3", "-m", "kinesweep." + name, H5, "-o", os.path.join(TMP.name, "a.png"),
                           "--print-data"], env=ENV).stdout
                self.assertTrue(out.strip().startswith("{"), out[:200])
                h = run(["/usr/bin/python3", "-m", "kinesweep." + name, "--help"], env=ENV).stdout
                self.assertTrue(h.startswith(f"usage: python3 -m kinesweep.{name} "), h[:200])

    def test_former_names_after_compat(self):
        code = ("import importlib, sys; sys.path.insert(0, %r)\n" % ANALYSIS +
                "import kinesweep.compat\n"
                "assert kinesweep.compat.OLD_NAMES == {o: 'kinesweep.' + n for o, n in %r.items()}\n" % FORMER +
                "assert 'h5py' not in sys.modules and 'matplotlib' not in sys.modules\n"
                "for old, new in kinesweep.compat.OLD_NAMES.items():\n"
                "    assert importlib.import_module(old) is importlib.import_module(new), old\n"
                "    assert sys.modules[old] is sys.modules[new], old\n"
                "import ksread, kinesweep\n"
                "from kswhere import select\n"
                "assert select is kinesweep.where.select\n"
                "r = kinesweep.open_results(%r)\n" % H5 +
                "assert isinstance(r, ksread.Results)\n"
                "print(len(r.runs()['E']))\n")
        self.assertEqual(run(["/usr/bin/python3", "-c", code]).stdout.strip(), "21")

    def test_former_names_need_compat(self):
        code = ("import sys; sys.path.insert(0, %r)\n" % ANALYSIS +
                "import kinesweep.read\n"
                "try:\n"
                "    import ksread\n"
                "except ModuleNotFoundError:\n"
                "    print('not found')\n")
        self.assertEqual(run(["/usr/bin/python3", "-c", code]).stdout.strip(), "not found")

    def test_compat_leaves_a_module_of_the_same_name_on_the_path(self):
        """A user's own report.py (or importance.py) on sys.path is found before the old name's alias."""
        own = os.path.join(TMP.name, "own")
        os.makedirs(own, exist_ok=True)
        with open(os.path.join(own, "report.py"), "w") as f:
            f.write("MINE = True\n")
        code = ("import sys; sys.path.insert(0, %r); sys.path.insert(0, %r)\n" % (ANALYSIS, own) +
                "import kinesweep.compat, report, ksplot\n"
                "print(getattr(report, 'MINE', False), ksplot.__name__)\n")
        self.assertEqual(run(["/usr/bin/python3", "-c", code]).stdout.split(), ["True", "kinesweep.plotting"])

    def test_importing_the_package_does_not_import_h5py(self):
        code = ("import sys; sys.path.insert(0, %r)\n" % ANALYSIS +
                "import kinesweep, kinesweep.where, kinesweep.kinds\n"
                "print('h5py' in sys.modules)\n"
                "kinesweep.open_results\n"
                "print('h5py' in sys.modules)\n")
        self.assertEqual(run(["/usr/bin/python3", "-c", code]).stdout.split(), ["False", "True"])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
