#!/usr/bin/python3
"""Source-tree entry of `python3 -m kinesweep.importance` (the same command; see its --help)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from kinesweep._alias import alias  # noqa: E402

alias(__name__, "kinesweep.importance")
