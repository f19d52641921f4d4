"""The old flat names of the package's modules (analysis/ksread.py, analysis/plot_landscape.py, ...)
as aliases: imported, the name is the package module itself (sys.modules entry, so `import ksread`
and `from kinesweep import read` give one module object); run as a script, the module runs as
`python3 -m kinesweep.<name>` would run it."""
import importlib
import runpy
import sys


def alias(name, target):
    if name == "__main__":
        runpy.run_module(target, run_name="__main__", alter_sys=True)
    else:
        sys.modules[name] = importlib.import_module(target)
