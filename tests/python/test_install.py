"""`cmake --install` into a clean prefix, then use what it installed as a user would: an external CMake
project finds the package and links the engine; the installed binary runs a shipped study; the man
page renders; bash completion completes; ksread imports and an installed plot script runs.

usage: /usr/bin/python3 test_install.py BUILD_DIR REPO_ROOT
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import h5py

BUILD = ROOT = None
PREFIX = None
TMP = None

# seed 000, Table 4: case 1a (local_weighted, k = 0, alpha1A = 0) has E = 51.03 Nm.
THESIS_1A_E = 51.03

APP_CMAKE = """cmake_minimum_required(VERSION 3.25)
project(ks_user LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 20)
find_package(kinesweep 0.1 REQUIRED)
add_executable(ks_user main.cpp)
target_link_libraries(ks_user PRIVATE kinesweep::engine)
"""

APP_MAIN = r"""// Load a study file, run its first run with the engine, print the run count and E.
#include <cstdio>
#include <variant>

#include "runner/execute.hpp"
#include "study/study.hpp"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const ks::Study study = ks::load_study(argv[1]);
  const ks::RunRef ref = study.locate(0);
  const ks::RunSpec run = study.blocks[ref.block].run(ref.local);
  ks::RunWorkspace ws;
  const ks::RunOutcome o = ks::execute(ks::Scenario::of(study), run, 0, ws);
  const auto& m = std::get<ks::TrajectoryMetrics>(o.result);
  std::printf("{\"runs\": %llu, \"status\": \"%s\", \"E\": %.17g}\n",
              static_cast<unsigned long long>(study.run_count()), std::string(o.status()).c_str(), m.E);
  return 0;
}
"""


def run(cmd, **kw):
    p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, cmd))} -> {p.returncode}\n{p.stdout}\n{p.stderr}")
    return p


def setUpModule():
    global PREFIX, TMP
    TMP = tempfile.TemporaryDirectory()
    PREFIX = os.path.join(TMP.name, "prefix")
    run(["cmake", "--install", BUILD, "--prefix", PREFIX])


def tearDownModule():
    TMP.cleanup()


def engine_compilers():
    """-D options naming the compilers the engine was built with (tests/CMakeLists.txt passes them): a
    program linking the engine's static libraries is built with the same toolchain."""
    return [f"-DCMAKE_{lang}_COMPILER={os.environ[var]}"
            for lang, var in (("CXX", "KINESWEEP_CXX_COMPILER"), ("C", "KINESWEEP_C_COMPILER")) if os.environ.get(var)]


def python_dir():
    """Where the package went: lib/python3.X/dist-packages under a prefix other than /usr (Debian's
    python3 searches it under /usr/local)."""
    return os.path.join(PREFIX, "lib", "python%d.%d" % sys.version_info[:2], "dist-packages")


class Install(unittest.TestCase):
    def test_layout(self):
        for rel in ["bin/kinesweep", "include/kinesweep/study/study.hpp", "include/kinesweep/runner/execute.hpp",
                    "lib/cmake/kinesweep/kinesweepConfig.cmake", "lib/cmake/kinesweep/kinesweepTargets.cmake",
                    "share/man/man1/kinesweep.1", "share/bash-completion/completions/kinesweep",
                    "share/kinesweep/studies/thesis_table4.toml", "share/kinesweep/studies/robots/arm7.urdf",
                    "share/doc/kinesweep/analysis.md", "share/doc/kinesweep/FORMAT.md", "share/doc/kinesweep/README.md",
                    "share/doc/kinesweep/LICENSE", "share/doc/kinesweep/CITATION.cff",
                    os.path.join(python_dir(), "kinesweep", "__init__.py"),
                    os.path.join(python_dir(), "kinesweep", "plot_landscape.py")]:
            self.assertTrue(os.path.exists(os.path.join(PREFIX, rel)), rel)
        self.assertTrue(glob.glob(os.path.join(PREFIX, "lib", "libks_*.a")))
        self.assertFalse(os.path.exists(os.path.join(PREFIX, "include", "kinesweep", "cli")))

    def test_external_project_links_the_engine(self):
        src = os.path.join(TMP.name, "app")
        os.makedirs(src, exist_ok=True)
        with open(os.path.join(src, "CMakeLists.txt"), "w") as f:
            f.write(APP_CMAKE)
        with open(os.path.join(src, "main.cpp"), "w") as f:
            f.write(APP_MAIN)
        b = os.path.join(TMP.name, "app-build")
        run(["cmake", "-S", src, "-B", b, "-DCMAKE_BUILD_TYPE=Release", f"-DCMAKE_PREFIX_PATH={PREFIX}",
             *engine_compilers()])
        run(["cmake", "--build", b, "-j2"])
        out = json.loads(run([os.path.join(b, "ks_user"),
                              os.path.join(PREFIX, "share/kinesweep/studies/thesis_table4.toml")]).stdout)
        self.assertEqual(out["runs"], 21)  # Table 4's 21 cases
        self.assertEqual(out["status"], "ok")
        self.assertAlmostEqual(out["E"], THESIS_1A_E, delta=0.01 * THESIS_1A_E)

    def test_installed_binary_runs_a_shipped_study_and_the_scripts_read_it(self):
        ks = os.path.join(PREFIX, "bin", "kinesweep")
        h5 = os.path.join(TMP.name, "t4.h5")
        run([ks, "run", os.path.join(PREFIX, "share/kinesweep/studies/thesis_table4.toml"), "-o", h5, "-q"],
            cwd=TMP.name)
        with h5py.File(h5, "r") as f:
            self.assertEqual(int(f["runs"]["done"][()].sum()), 21)
        env = dict(os.environ, PYTHONPATH=python_dir())
        p = run(["/usr/bin/python3", "-c",
                 "import kinesweep; r = kinesweep.open_results(%r); print(len(r.runs()), kinesweep.__file__)" % h5],
                env=env, cwd=TMP.name)
        n, where = p.stdout.split()
        self.assertEqual(n, "21")
        self.assertTrue(where.startswith(python_dir()), where)  # the installed package, not the source tree
        png = os.path.join(TMP.name, "cases.png")
        run(["/usr/bin/python3", "-m", "kinesweep.plot_cases", h5, "-o", png], env=env, cwd=TMP.name)
        self.assertGreater(os.path.getsize(png), 1000)

    def test_man_page_renders(self):
        if not shutil.which("man"):
            self.skipTest("man is not installed")
        env = dict(os.environ, MANPATH=os.path.join(PREFIX, "share", "man"), MANWIDTH="100", MANPAGER="cat",
                   PAGER="cat")
        text = run(["man", "kinesweep"], env=env).stdout
        self.assertIn("kinesweep", text)
        for sub in ("COMMAND RUN", "COMMAND QUERY", "COMMAND SENSITIVITY", "--bootstrap", "--where", "--group-by",
                    "--dry-run", "share/doc/kinesweep/FORMAT.md"):
            self.assertIn(sub, text)

    def complete(self, *words):
        script = os.path.join(PREFIX, "share/bash-completion/completions/kinesweep")
        arr = " ".join("'%s'" % w for w in words)
        cmd = (f"source '{script}'; COMP_WORDS=({arr}); COMP_CWORD={len(words) - 1}; _kinesweep; "
               "printf '%s\\n' \"${COMPREPLY[@]}\"")
        return [w for w in run(["bash", "-c", cmd], cwd=TMP.name).stdout.split("\n") if w]

    def test_bash_completion(self):
        ks = os.path.join(PREFIX, "bin", "kinesweep")
        self.assertEqual(self.complete(ks, "qu"), ["query"])
        # Each subcommand's options are those its --help lists.
        for sub in ("run", "info", "query", "schema", "robot"):
            helptext = run([ks, sub, "--help"]).stdout
            listed = set(re.findall(r"(?<![\w-])(--?[a-zA-Z][\w-]*)", helptext.split("Options:", 1)[-1]))
            offered = set(self.complete(ks, sub, "-"))
            self.assertEqual(offered, listed, sub)
        # Column names of the results file on the line.
        h5 = os.path.join(TMP.name, "cols.h5")
        run([ks, "run", os.path.join(PREFIX, "share/kinesweep/studies/thesis_table4.toml"), "-o", h5, "-q",
             "--overwrite"], cwd=TMP.name)
        with h5py.File(h5, "r") as f:
            columns = [c.decode() if isinstance(c, bytes) else c for c in f["runs"].attrs["columns"]]
        self.assertEqual(sorted(self.complete(ks, "query", h5, "-w", "")), sorted(columns))
        self.assertEqual(self.complete(ks, "query", h5, "--sort", "alpha"),
                         sorted(c for c in columns if c.startswith("alpha")))


if __name__ == "__main__":
    BUILD, ROOT = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    del sys.argv[1:3]
    unittest.main(verbosity=2)
