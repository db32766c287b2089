"""The browser view, kept under its old name: ``ViserScene`` lives in ``c2rviz.view``."""

from __future__ import annotations

from .view.viser_scene import RECENT_COMMANDS, ViserScene

__all__ = ["RECENT_COMMANDS", "ViserScene"]
