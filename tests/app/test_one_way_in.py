"""The session is the one way in (issue 35): no door writes to the world's log of commands
or changes a session's fields itself.

What the world hears of a command (``World.note``, ``World.refused``, ``World.replied``)
is told by ``c2rviz/session/notes.py``, and a session's settings change through its own
methods (``set_speed``, ``set_motion``...): this test reads every module outside
``c2rviz/session/`` and ``c2rviz/world/`` and fails on a call of those world methods or
an assignment to an attribute of a session.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "c2rviz"
INSIDE = ("session", "world")  # the session and the world may
TOLD = {"note", "refused", "replied"}  # World's methods that tell the observers of a command


def _outside() -> list[Path]:
    return sorted(
        path for path in PACKAGE.rglob("*.py") if path.relative_to(PACKAGE).parts[0] not in INSIDE
    )


def _last_name(node: ast.expr) -> str | None:
    """``world`` for ``world``, ``self.world`` and ``ctl.session.world``; else None."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        return node.attr
    return None


def trespasses(source: str) -> list[str]:
    """What ``source`` (a module's text) does that only the session may: each as
    ``line: text``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            owner = _last_name(node.func.value)
            if node.func.attr in TOLD and owner is not None and owner.lower().endswith("world"):
                found.append(f"{node.lineno}: {ast.unparse(node.func)}(...)")
        targets: list[ast.expr] = []
        if isinstance(node, ast.Assign):
            targets = [t for target in node.targets for t in _flat(target)]
        elif isinstance(node, (ast.AugAssign, ast.AnnAssign)):
            targets = [node.target]
        for target in targets:
            if isinstance(target, ast.Attribute):
                owner = _last_name(target.value)
                if owner is not None and owner.lower().endswith("session"):
                    found.append(f"{node.lineno}: {ast.unparse(target)} = ...")
    return found


def _flat(target: ast.expr) -> list[ast.expr]:
    if isinstance(target, (ast.Tuple, ast.List)):
        return [t for element in target.elts for t in _flat(element)]
    return [target]


@pytest.mark.parametrize(
    "line",
    [
        "world.note(source, line, True)",
        "self.session.world.replied(source, line, 'ok')",
        "ctl.session.world.refused(robot, source, line, error)",
        "session.speed = 50.0",
        "ctl.session.lspeed = m_s",
        "self.session.motion = 'on'",
        "hangup, self.session.hangup = self.session.hangup, None",
        "session.speed += 1",
    ],
)
def test_the_reader_catches_each_way_round(line: str) -> None:
    assert trespasses(line)


@pytest.mark.parametrize(
    "line",
    [
        "session.set_speed(50.0)",
        "said = session.said('/joint_command'); said.refuse(error)",
        "self.session = Session(services)",
        "notes.note(x)",
        "world.set_q(q, name, source)",
    ],
)
def test_the_reader_lets_the_session_api_through(line: str) -> None:
    assert trespasses(line) == []


def test_no_module_outside_the_session_and_the_world_goes_round_it() -> None:
    found = {
        str(path.relative_to(PACKAGE.parent)): hits
        for path in _outside()
        if (hits := trespasses(path.read_text(encoding="utf-8")))
    }
    assert found == {}
