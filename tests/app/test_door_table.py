"""The door table is explicit: ``app.doors.OPENERS`` names every opener, and importing
``app.doors`` alone gives the whole table (no door joins it as a side effect of an import)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from c2rviz.app import doors


def test_importing_the_doors_alone_gives_every_opener() -> None:
    code = (
        "import sys, c2rviz.app.doors as d\n"
        "print(' '.join(o.__name__ for o in d.OPENERS))\n"
        "print('c2rviz.app.program' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.splitlines() == ["open_crcl open_rosbridge", "False"]


def test_no_module_of_the_app_fills_the_table() -> None:
    assert (doors.open_crcl, doors.open_rosbridge) == doors.OPENERS
    app = Path(doors.__file__).parent
    for path in sorted(app.glob("*.py")):
        text = path.read_text(encoding="utf-8")
        assert "OPENERS.append" not in text, path.name
        assert "noqa: F401" not in text, path.name
