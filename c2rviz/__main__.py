"""``python -m c2rviz``: the same as the ``c2rviz`` command."""

import sys

from .app.cli import main

sys.exit(main())
