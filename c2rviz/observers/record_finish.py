"""Finishing a recording, in a thread: the bag ended, each command file put together, the
exporters run, and every file renamed from its private name into its own."""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from ..world.state import RobotState
from .record_files import RecordFiles
from .recorded import Recorded
from .recorder import Recorder

if TYPE_CHECKING:  # rosbags is loaded at the first recording, not at start
    from .bag_recorder import BagRecorder

__all__ = ["Exporter", "Recording", "finish"]

log = logging.getLogger("c2rviz.record")

Exporter = Callable[[Recorded, RobotState], Path]
"""Writes one more file from a finished recording (blocking, run in a thread) next to its
CSV and returns its path, such as ``view.record_page.write_html``'s NAME.html."""


@dataclass(eq=False)
class Recording:
    """One running recording: its name, a recorder per robot, and the bag."""

    name: str
    recorders: dict[str, Recorder]
    bag: BagRecorder | None
    bag_files: RecordFiles
    t0: float

    @property
    def stems(self) -> set[str]:
        """The names its files take (NAME, and NAME.ROBOT for each robot of a cell's)."""
        return {self.name, *(r.name for r in self.recorders.values())}


def finish(
    recording: Recording, states: dict[str, RobotState], exporters: Sequence[Exporter]
) -> list[Recorded]:
    """End the bag, put each command file together, run the exporters, and put every file
    in place (blocking: for a thread). What cannot be written is reported in ``error``."""
    bag: Path | None = None
    bag_error: str | None = None
    if recording.bag is not None:
        try:
            bag_error = recording.bag.close()
            bag = recording.bag_files.publish_bag()
        except Exception as exc:  # the txt and csv stand whatever the bag does
            bag_error = bag_error or f"the bag: {exc}"
            log.warning("recording %s: the bag is not in place: %s", recording.name, exc)
    out = []
    for robot, recorder in recording.recorders.items():
        recorded = recorder.finish()
        files = recorder.files
        html = None
        for export in exporters:
            try:
                _fresh(files, ".html")
                html = export(recorded, states[robot])
            except Exception as exc:  # the txt and csv stand; the rest is a bonus
                files.discard(".html")
                why = exc.strerror or exc if isinstance(exc, OSError) else exc
                log.warning(
                    "recording %s: no page written (%s.html): %s; its other files stand",
                    recorded.name,
                    recorded.name,
                    why,
                )
        try:
            txt = files.publish(recorded.txt) if recorded.txt is not None else None
            csv = files.publish(recorded.csv)
            if html is not None and html.name.startswith(files.stem):
                html = files.publish(html)
        except OSError as exc:
            why = f"cannot put it in place: {exc.strerror or exc}"
            log.warning("recording %s: %s (its files are %s.*)", recorded.name, why, files.stem)
            out.append(replace(recorded, error=recorded.error or why, bag=bag))
            continue
        error = recorded.error or (f"bag {bag_error}" if bag_error else None)
        out.append(replace(recorded, txt=txt, csv=csv, html=html, bag=bag, error=error))
    return out


def _fresh(files: RecordFiles, suffix: str) -> None:
    """Create the private file an exporter writes (so it opens a new file of ours, never a
    link someone put there)."""
    os.close(files.create(suffix))
