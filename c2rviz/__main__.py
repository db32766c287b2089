"""``python -m c2rviz``: the same as the ``c2rviz`` command."""

import sys

from .cli import main

sys.exit(main())
