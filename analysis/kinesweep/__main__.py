"""`python3 -m kinesweep`: the package's commands, each with its --help."""
import importlib

from kinesweep import COMMANDS

if __name__ == "__main__":
    print("usage: python3 -m kinesweep.COMMAND [--help] ...\n\ncommands:")
    for name in COMMANDS:
        doc = (importlib.import_module("kinesweep." + name).__doc__ or "").strip().splitlines()
        print(f"  {name:20s} {doc[0] if doc else ''}")
