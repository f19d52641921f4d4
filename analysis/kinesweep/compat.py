"""The package's former flat module names, for old scripts: after `import kinesweep.compat`,
`import ksread` (or `from kswhere import select`, `import plot_landscape`) imports the package module
that name stands for, and the two names are one module object (sys.modules["ksread"] is
kinesweep.read). Each old name is imported on first use only: importing this module imports none of
them (no h5py, matplotlib or scikit-learn until an old name asks for it).

    import kinesweep.compat  # noqa: F401  (analysis/ on sys.path, or the package installed)
    import ksread
    r = ksread.open_results("results/thesis_table4.h5")

New code imports the package: `from kinesweep import read`. The old script paths (analysis/NAME.py)
are gone: a command runs as `python3 -m kinesweep.NAME`.
"""
import importlib
import importlib.abc
import importlib.machinery
import sys

OLD_NAMES = {
    "ksread": "kinesweep.read",
    "kshistory": "kinesweep.history",
    "kslive": "kinesweep.live",
    "kstypes": "kinesweep.kinds",
    "kswhere": "kinesweep.where",
    "kssolutions": "kinesweep.solutions",
    "ksplot": "kinesweep.plotting",
    "plot_landscape": "kinesweep.plot_landscape",
    "plot_histories": "kinesweep.plot_histories",
    "plot_cases": "kinesweep.plot_cases",
    "plot_basins": "kinesweep.plot_basins",
    "plot_convergence": "kinesweep.plot_convergence",
    "plot_runs": "kinesweep.plot_runs",
    "compare_landscapes": "kinesweep.compare_landscapes",
    "importance": "kinesweep.importance",
    "report": "kinesweep.report",
    "make_examples": "kinesweep.make_examples",
}


class _OldNames(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds an old name and loads it as its package module (imported, then registered under both names)."""

    def find_spec(self, name, path=None, target=None):
        if name not in OLD_NAMES:
            return None
        return importlib.machinery.ModuleSpec(name, self)

    def create_module(self, spec):
        return importlib.import_module(OLD_NAMES[spec.name])

    def exec_module(self, module):
        pass  # the package module ran when create_module imported it


# Last on sys.meta_path: a module of the same name found on sys.path (a user's own report.py) still wins.
if not any(isinstance(f, _OldNames) for f in sys.meta_path):
    sys.meta_path.append(_OldNames())
