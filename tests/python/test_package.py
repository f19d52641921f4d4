"""analysis/ as one Python package: `python3 -m kinesweep.NAME` runs each command, the source-tree
scripts analysis/NAME.py run the same command with the same output, the former module names are the
package's modules (one module object), and importing the package does not import h5py until the
reader is used.

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
ALIASES = {"ksread": "read", "kswhere": "where", "kshistory": "history", "kslive": "live", "kstypes": "kinds",
           "kssolutions": "solutions", "ksplot": "plotting"}
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
            self.assertTrue(os.path.exists(os.path.join(ANALYSIS, name + ".py")), name)

    def test_module_and_script_give_the_same_command(self):
        for name, extra in (("plot_cases", ["--print-data"]), ("plot_histories", ["--print-data"])):
            with self.subTest(name):
                a = run(["/usr/bin/python3", "-m", "kinesweep." + name, H5, "-o", os.path.join(TMP.name, "a.png"),
                         *extra], env=ENV).stdout
                b = run(["/usr/bin/python3", os.path.join(ANALYSIS, name + ".py"), H5, "-o",
                         os.path.join(TMP.name, "a.png"), *extra]).stdout
                self.assertTrue(a.strip())
                self.assertEqual(a, b)
                h = run(["/usr/bin/python3", os.path.join(ANALYSIS, name + ".py"), "--help"]).stdout
                self.assertIn("usage:", h)

    def test_former_names_are_the_package_modules(self):
        code = ("import importlib, sys; sys.path.insert(0, %r)\n" % ANALYSIS +
                "for old, new in %r.items():\n" % ALIASES +
                "    assert importlib.import_module(old) is importlib.import_module('kinesweep.' + new), old\n"
                "import ksread, kinesweep\n"
                "r = kinesweep.open_results(%r)\n" % H5 +
                "assert isinstance(r, ksread.Results)\n"
                "print(len(r.runs()['E']))\n")
        self.assertEqual(run(["/usr/bin/python3", "-c", code]).stdout.strip(), "21")

    def test_importing_the_package_does_not_import_h5py(self):
        code = ("import sys; sys.path.insert(0, %r)\n" % ANALYSIS +
                "import kinesweep, kinesweep.where, kinesweep.kinds\n"
                "print('h5py' in sys.modules)\n"
                "kinesweep.open_results\n"
                "print('h5py' in sys.modules)\n")
        self.assertEqual(run(["/usr/bin/python3", "-c", code]).stdout.split(), ["False", "True"])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
