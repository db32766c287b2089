#!/usr/bin/env python3
"""Play a c2rviz command file: ``python fileplayer.py commands/motoman.txt``.

A thin wrapper around ``c2rviz.clients.player.main`` (also installed as ``c2rviz-play``);
it runs from a checkout without installing c2rviz. See ``--help``.
"""

import sys
from pathlib import Path

try:
    import c2rviz  # noqa: F401
except ImportError:  # not installed: use the checkout this file lives in
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from c2rviz.clients.player import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
