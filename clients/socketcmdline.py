#!/usr/bin/env python3
"""The interactive c2rviz command line, as in the seed: ``python socketcmdline.py``.

A thin wrapper around ``c2rviz.clients.repl.main`` (also installed as ``c2rviz-cli``);
it runs from a checkout without installing c2rviz. See ``--help``.
"""

import sys
from pathlib import Path

try:
    import c2rviz  # noqa: F401
except ImportError:  # not installed: use the checkout this file lives in
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from c2rviz.clients.repl import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
