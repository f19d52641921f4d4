"""Source-tree name of kinesweep.where: `import kswhere` with analysis/ on sys.path is that module."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from kinesweep._alias import alias  # noqa: E402

alias(__name__, "kinesweep.where")
