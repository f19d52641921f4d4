"""`cmake --install` into a clean prefix, then use what it installed as a user would: an external CMake
project finds the package and links the engine; the installed binary runs a shipped study; the man
page renders; bash completion completes; the package imports and an installed plot command runs.

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

# A consumer that leaves the standard to the compiler (GCC 12: gnu++17): the package's targets carry
# C++20 (std::span in the sensitivity header, concepts), so it builds all the same.
DEFAULT_STD_CMAKE = """cmake_minimum_required(VERSION 3.25)
project(ks_default_std LANGUAGES CXX)
find_package(kinesweep 0.1 REQUIRED)
add_executable(ks_default_std main.cpp)
target_link_libraries(ks_default_std PRIVATE kinesweep::engine)
"""

DEFAULT_STD_MAIN = r"""// Sobol' indices of f(x1, x2) = x1 on four sample rows: x1 explains everything, x2 nothing.
#include <cstdio>
#include <span>
#include <vector>

#include "runner/execute.hpp"
#include "sensitivity/sobol_indices.hpp"
#include "study/study.hpp"

int main() {
  const std::vector<double> a{1, 2, 3, 4}, b{4, 1, 3, 2};
  const std::vector<double> ab1{4, 1, 3, 2}, ab2{1, 2, 3, 4};  // AB_1 takes x1 from B, AB_2 takes x2
  ks::SobolOptions o;
  o.bootstrap = 0;
  const ks::SobolIndices s = ks::sobol_indices(a, b, {std::span<const double>(ab1), std::span<const double>(ab2)}, o);
  std::printf("%llu %.17g %.17g\n", static_cast<unsigned long long>(s.samples), s.total[0], s.total[1]);
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
                    os.path.join(python_dir(), "kinesweep", "plot_landscape.py"),
                    os.path.join(python_dir(), "kinesweep", "compat.py")]:
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

    def test_consumer_at_the_default_standard(self):
        with open(os.path.join(PREFIX, "lib/cmake/kinesweep/kinesweepTargets.cmake")) as f:
            targets = f.read()
        engine = re.search(r"set_target_properties\(kinesweep::engine PROPERTIES(.*?)\n\)", targets, re.S)
        self.assertIsNotNone(engine, "kinesweep::engine in kinesweepTargets.cmake")
        self.assertRegex(engine.group(1), r'INTERFACE_COMPILE_FEATURES "[^"]*cxx_std_20')
        src = os.path.join(TMP.name, "default_std")
        os.makedirs(src, exist_ok=True)
        with open(os.path.join(src, "CMakeLists.txt"), "w") as f:
            f.write(DEFAULT_STD_CMAKE)
        with open(os.path.join(src, "main.cpp"), "w") as f:
            f.write(DEFAULT_STD_MAIN)
        b = os.path.join(TMP.name, "default_std-build")
        run(["cmake", "-S", src, "-B", b, "-DCMAKE_BUILD_TYPE=Release", f"-DCMAKE_PREFIX_PATH={PREFIX}",
             "-DCMAKE_EXPORT_COMPILE_COMMANDS=ON", *engine_compilers()])
        with open(os.path.join(b, "compile_commands.json")) as f:
            command = json.load(f)[0]["command"]
        self.assertRegex(command, r"-std=(c|gnu)\+\+(20|2a)\b")  # set by the package, not by the project
        run(["cmake", "--build", b, "-j2"])
        samples, total1, total2 = run([os.path.join(b, "ks_default_std")]).stdout.split()
        self.assertEqual(samples, "4")
        self.assertGreater(float(total1), 0.5)  # Jansen's estimate for the one factor f depends on
        self.assertEqual(float(total2), 0.0)    # f(A) = f(AB_2) on every row

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

    def test_citation_names_attributes_a_results_file_has(self):
        with open(os.path.join(PREFIX, "share/doc/kinesweep/CITATION.cff")) as f:
            # its top-level keys with their one-line values (quotes removed); no YAML library needed
            cff = {m.group(1): m.group(2).strip().strip('"') for m in re.finditer(r"^([\w-]+):(.*)$", f.read(), re.M)}
        for key in ("cff-version", "message", "title", "authors", "version"):
            self.assertIn(key, cff)
        # The attribute names it gives: its snake_case words (engine_version, ...).
        named = set(re.findall(r"\b[a-z]+(?:_[a-z]+)+\b", cff["message"]))
        self.assertTrue(named)
        ks = os.path.join(PREFIX, "bin", "kinesweep")
        h5 = os.path.join(TMP.name, "cite.h5")
        run([ks, "run", os.path.join(PREFIX, "share/kinesweep/studies/thesis_table4.toml"), "-o", h5, "-q",
             "--overwrite"], cwd=TMP.name)
        with h5py.File(h5, "r") as f:
            root = dict(f.attrs)
        self.assertEqual(sorted(named - set(root)), [])
        self.assertEqual(root["engine_version"], cff["version"])

    def man(self):
        """The installed page as `man -l` renders it at 80 columns (plain text)."""
        if not shutil.which("man"):
            self.skipTest("man is not installed")
        env = dict(os.environ, MANWIDTH="80", MANPAGER="cat", PAGER="cat", MAN_KEEP_FORMATTING="")
        page = os.path.join(PREFIX, "share", "man", "man1", "kinesweep.1")
        return run(["man", "-l", page], env=env).stdout

    def test_man_page_sections_width_and_footer(self):
        text = self.man()
        lines = text.rstrip("\n").split("\n")
        headings = [ln for ln in lines if re.match(r"^[A-Z][A-Z ]+$", ln)]
        self.assertEqual(headings, ["NAME", "SYNOPSIS", "DESCRIPTION", "COMMANDS", "OPTIONS", "EXIT STATUS",
                                    "ENVIRONMENT", "FILES", "EXAMPLES", "SEE ALSO"])
        wide = [ln for ln in lines if len(ln) > 80]
        self.assertEqual(wide, [], "lines wider than 80 columns")
        # footer: the source field names the version and the commit, the date field is a date
        ks = os.path.join(PREFIX, "bin", "kinesweep")
        version = run([ks, "--version"]).stdout.strip()  # kinesweep 0.1.0 (<git describe>)
        m = re.match(r"kinesweep (\S+)(?: \((?:.*-g)?([0-9a-f]{40})(-dirty)?\))?$", version)
        self.assertIsNotNone(m, version)
        source = f"kinesweep {m.group(1)}"
        if m.group(2):  # a build of a modified tree (git's -dirty) is marked '+'
            source += f" (commit {m.group(2)[:7]}{'+' if m.group(3) else ''})"
        footer = re.match(r"^(.*\S)\s+(\S+)\s+KINESWEEP\(1\)$", lines[-1])
        self.assertIsNotNone(footer, lines[-1])
        self.assertEqual(footer.group(1), source)
        self.assertRegex(footer.group(2), r"^\d{4}-\d\d-\d\d$")
        # every subcommand has its subsection with the options its --help lists
        subs = re.findall(r"^  (\w+)  ", run([ks, "--help"]).stdout.split("Subcommands:", 1)[1], re.M)
        self.assertIn("sensitivity", subs)
        commands = text.split("\nCOMMANDS\n", 1)[1].split("\nOPTIONS\n", 1)[0]
        for sub in subs:
            self.assertIn(f"\n   kinesweep {sub}\n", commands)
            part = commands.split(f"\n   kinesweep {sub}\n", 1)[1].split("\n   kinesweep ", 1)[0]
            helptext = run([ks, sub, "--help"]).stdout
            for opt in re.findall(r"^  (-[-\w]+(?:,-[-\w]+)*)", helptext, re.M):
                for o in opt.split(","):
                    self.assertRegex(part, rf"(?<![\w-]){re.escape(o)}(?![\w-])", f"{sub} {o}")
        for sub in ("--bootstrap", "--where", "--group-by", "--dry-run", "share/doc/kinesweep/FORMAT.md",
                    "130", "PMI_RANK", "python3 -m kinesweep.report"):
            self.assertIn(sub, text)
        self.assertNotIn("analysis/", text)

    def test_python_commands_name_installed_commands(self):
        env = dict(os.environ, PYTHONPATH=python_dir())
        commands = run(["/usr/bin/python3", "-c", "import kinesweep; print(' '.join(kinesweep.COMMANDS))"],
                       env=env, cwd=TMP.name).stdout.split()
        self.assertIn("plot_landscape", commands)
        listing = run(["/usr/bin/python3", "-m", "kinesweep"], env=env, cwd=TMP.name).stdout
        self.assertTrue(listing.startswith("usage: python3 -m kinesweep.COMMAND"), listing[:200])
        for name in commands:
            self.assertIn(f"  {name} ", listing)
            text = run(["/usr/bin/python3", "-m", f"kinesweep.{name}", "--help"], env=env, cwd=TMP.name).stdout
            self.assertTrue(text.startswith(f"usage: python3 -m kinesweep.{name} "), f"{name}: {text[:200]}")
            self.assertNotIn("analysis/", text, name)
            self.assertIsNone(re.search(r"\b\w+\.py\b", text), name)
        # a message names the command too
        p = subprocess.run(["/usr/bin/python3", "-m", "kinesweep.plot_runs", self.results(), "--metric", "nosuch"],
                           env=env, cwd=TMP.name, capture_output=True, text=True)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertTrue(p.stderr.startswith("kinesweep.plot_runs: "), p.stderr)
        self.assertIsNone(re.search(r"\b\w+\.py\b", p.stderr), p.stderr)

    RESULTS = None

    def results(self):
        """A results file of the completion study: a grid block with histories, a Saltelli design and
        an optimisation (written once)."""
        if Install.RESULTS is None:
            study = os.path.join(TMP.name, "complete.toml")
            with open(study, "w") as f:
                f.write(COMPLETION_STUDY)
            Install.RESULTS = os.path.join(TMP.name, "complete.h5")
            run([os.path.join(PREFIX, "bin", "kinesweep"), "run", study, "-o", Install.RESULTS, "-q", "--overwrite"],
                cwd=TMP.name)
        return Install.RESULTS

    def complete(self, *words, cwd=None):
        """What _kinesweep offers for COMP_WORDS = words (the last being completed), one per line."""
        script = os.path.join(PREFIX, "share/bash-completion/completions/kinesweep")
        arr = " ".join("'%s'" % w for w in words)
        cmd = (f"source '{script}'; COMP_WORDS=({arr}); COMP_CWORD={len(words) - 1}; _kinesweep; "
               "printf '%s\\n' \"${COMPREPLY[@]}\"")
        return [w for w in run(["bash", "-c", cmd], cwd=cwd or TMP.name).stdout.split("\n") if w]

    def test_bash_completion_options(self):
        ks = os.path.join(PREFIX, "bin", "kinesweep")
        self.assertEqual(self.complete(ks, "qu"), ["query"])
        self.assertEqual(sorted(self.complete(ks, "")),
                         sorted(["run", "info", "query", "sensitivity", "compare", "schema", "robot", "table4",
                                 "--version", "-h", "--help"]))
        # Each subcommand's options are those its --help lists.
        for sub in ("run", "info", "query", "schema", "robot", "sensitivity", "compare", "table4"):
            helptext = run([ks, sub, "--help"]).stdout
            listed = set(re.findall(r"(?<![\w-])(--?[a-zA-Z][\w-]*)", helptext.split("Options:", 1)[-1]))
            offered = set(self.complete(ks, sub, "-"))
            self.assertEqual(offered, listed, sub)
        # fixed values
        self.assertEqual(self.complete(ks, "run", "s.toml", "--histories", ""), ["full", "none", "every="])
        self.assertEqual(self.complete(ks, "run", "s.toml", "--lanes", ""), ["1", "4", "8"])
        self.assertEqual(self.complete(ks, "schema", "--format", ""), ["markdown", "json"])
        self.assertEqual(self.complete(ks, "sensitivity", "x.h5", "--format", ""), ["table", "json"])
        self.assertEqual(self.complete(ks, "query", "x.h5", "-f", "c"), ["csv"])
        self.assertEqual(self.complete(ks, "query", "x.h5", "--format", "=", "j"), ["json"])  # --format=j

    def test_bash_completion_files(self):
        ks = os.path.join(PREFIX, "bin", "kinesweep")
        d = os.path.join(TMP.name, "files")
        os.makedirs(os.path.join(d, "sub"), exist_ok=True)
        for name in ("a.h5", "b.hdf5", "c.toml", "d.urdf", "e.txt"):
            open(os.path.join(d, name), "w").close()
        for sub in ("info", "query", "sensitivity"):
            self.assertEqual(sorted(self.complete(ks, sub, "", cwd=d)), ["a.h5", "b.hdf5", "sub"], sub)
        self.assertEqual(sorted(self.complete(ks, "run", "", cwd=d)), ["c.toml", "sub"])
        self.assertEqual(sorted(self.complete(ks, "run", "c.toml", "-o", "", cwd=d)), ["a.h5", "b.hdf5", "sub"])
        self.assertEqual(sorted(self.complete(ks, "robot", "", cwd=d)), ["c.toml", "d.urdf", "sub"])

    def test_bash_completion_values_from_the_file(self):
        ks = os.path.join(PREFIX, "bin", "kinesweep")
        h5 = self.results()
        schema = json.loads(run([ks, "schema", "--format", "json"]).stdout)
        metric_names = {m["name"] for k in schema["kinds"] for m in k["metrics"]}
        with h5py.File(h5, "r") as f:
            columns = [c.decode() if isinstance(c, bytes) else c for c in f["runs"].attrs["columns"]]
            blocks = sorted(set(kinesweep_text(f["runs"]["block"])))
            optimizations = sorted(f["optimizations"].keys())
            layouts = [x.decode() if isinstance(x, bytes) else x for x in f["histories"].attrs["layouts"]]
            arrays = sorted(layouts[int(f["histories"]["layout"][0])].split(","))  # run 0's arrays (FORMAT.md)
        # columns for --where, --sort (and COL:desc), --columns (comma lists), --group-by
        self.assertEqual(sorted(self.complete(ks, "query", h5, "-w", "")), sorted(columns))
        self.assertEqual(sorted(self.complete(ks, "query", h5, "--sort", "alpha")),
                         sorted([c for c in columns if c.startswith("alpha")]
                                + [c + ":desc" for c in columns if c.startswith("alpha")]))
        self.assertEqual(self.complete(ks, "query", h5, "--columns", "E,run_"),
                         ["E," + c for c in columns if c.startswith("run_")])
        # sensitivity: the file's blocks and metric columns
        self.assertEqual(sorted(self.complete(ks, "sensitivity", h5, "--block", "")), blocks)
        self.assertEqual(sorted(self.complete(ks, "sensitivity", h5, "--metric", "")),
                         sorted(c for c in columns if c in metric_names))
        self.assertEqual(self.complete(ks, "sensitivity", h5, "--metric", "tau_"), ["tau_inf"])
        # --agg: count or FN:COL; bash splits at ':' (COMP_WORDBREAKS), readline replaces what follows it
        self.assertEqual(self.complete(ks, "query", h5, "-g", "block", "--agg", ""),
                         ["count", "min:", "max:", "mean:", "median:", "sum:", "argmin:", "argmax:"])
        self.assertEqual(self.complete(ks, "query", h5, "-g", "block", "--agg", "count,arg"),
                         ["count,argmin:", "count,argmax:"])
        self.assertEqual(sorted(self.complete(ks, "query", h5, "--agg", "min", ":", "")), sorted(columns))
        self.assertEqual(self.complete(ks, "query", h5, "--agg", "min", ":", "E_"),
                         [c for c in columns if c.startswith("E_")])
        # --history: the arrays of the run given by --run; --optimization: the file's optimisations
        self.assertEqual(sorted(self.complete(ks, "query", h5, "--run", "0", "--history", "")),
                         sorted(arrays + ["all"]))
        self.assertEqual(self.complete(ks, "query", h5, "--optimization", ""), optimizations)


def kinesweep_text(d):
    """A label column as str values (an HDF5 enum with its names, or strings)."""
    names = h5py.check_enum_dtype(d.dtype)
    if names:
        by_code = {v: k for k, v in names.items()}
        return [by_code[int(x)] for x in d[()]]
    return [x.decode() if isinstance(x, bytes) else str(x) for x in d[()]]


# A grid block with full histories, a Saltelli design and an optimisation: every kind of value the
# completion reads from a results file.
COMPLETION_STUDY = """
[study]
name = "complete"
histories = "full"
[robot]
inertia = "thesis_m11"
[[block]]
name = "grid"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = [0, 10]
[[block]]
name = "design"
kind = "trajectory"
method = "local_weighted"
saltelli = { count = 4, seed = 1 }
[block.axes]
alpha1A = { saltelli = { from = -20, to = 30 } }
k = { saltelli = { from = 0, to = 0.2 } }
[[optimize]]
name = "h1"
preset = "1h"
variables = { alpha1A = [-30, 10], k = [0, 1] }
[optimize.global]
algorithm = "GN_ESCH"
population = 4
max_evals = 8
"""


if __name__ == "__main__":
    BUILD, ROOT = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    del sys.argv[1:3]
    unittest.main(verbosity=2)
