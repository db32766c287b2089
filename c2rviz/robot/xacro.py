"""Expanding a ``.xacro`` robot description into URDF text, without ROS.

xacro answers ``$(find NAME)`` through ROS's package index; here it asks the
caller's package search instead (``sources.RobotSource.find_package``). That
swap uses xacro 2.x internals, so it lives here alone, under a lock (xacro
keeps module-level state), and is undone after each expansion.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path

from ..errors import ConfigError, RobotError

_xacro_lock = threading.Lock()  # xacro keeps module-level state


def parse_xacro_args(args: Mapping[str, str] | Iterable[str]) -> dict[str, str]:
    """``name:=value`` strings (or a mapping) as a dict for xacro.

    Raises:
        ConfigError: an entry that is not ``name:=value``.
    """
    if isinstance(args, Mapping):
        return dict(args)
    parsed = {}
    for arg in args:
        name, sep, value = arg.partition(":=")
        if not sep or not name.strip():
            raise ConfigError(f"--xacro-arg {arg!r} is not name:=value")
        parsed[name.strip()] = value
    return parsed


def expand_xacro(
    path: Path, args: dict[str, str], find_package: Callable[[str], Path | None]
) -> str:
    """Run xacro on ``path``; ``$(find NAME)`` gives ``find_package(NAME)``.

    Args:
        path: The ``.xacro`` file.
        args: Values for its ``$(arg name)``.
        find_package: The folder of package NAME, or None when it is nowhere.

    Raises:
        RobotError: xacro is missing, or the file does not expand (the message says
            why, and how to give a missing argument or package).
    """
    try:
        import xacro
        from xacro import substitution_args
    except ImportError as exc:  # pragma: no cover - xacro is a dependency
        raise RobotError(f"{path} is a xacro file and xacro is not installed: {exc}") from exc

    def find(name: str) -> str:
        folder = find_package(name)
        if folder is None:
            raise substitution_args.SubstitutionException(
                f"package {name!r} not found in --package-path, ROS_PACKAGE_PATH, "
                f"AMENT_PREFIX_PATH or the folders above {path.parent} "
                "(give the folder that holds it with --package-path DIR or NAME=DIR)"
            )
        return str(folder)

    # xacro answers $(find NAME) through ROS's package index; swap in our search
    # (these are xacro 2.x internals: without them, xacro's own lookup stays).
    patch = hasattr(substitution_args, "_eval_find") and hasattr(substitution_args, "_eval_dict")
    with _xacro_lock:
        if patch:
            saved = substitution_args._eval_find, substitution_args._eval_dict.get("find")
            substitution_args._eval_find = find
            substitution_args._eval_dict["find"] = find
        try:
            return xacro.process_file(str(path), mappings=args).toprettyxml(indent="  ")
        except Exception as exc:  # xacro raises all sorts; each is a bad description
            problem = _xacro_problem(exc)
            if "argument" in problem.lower():
                problem += " (give it with --xacro-arg name:=value)"
            raise RobotError(f"cannot expand {path}: {problem}") from exc
        finally:
            if patch:
                substitution_args._eval_find, substitution_args._eval_dict["find"] = saved


def _xacro_problem(exc: Exception) -> str:
    """What xacro raised, as one line without class names or repeats.

    xacro wraps an error in a substitution such as ``$(find NAME)`` as
    ``XacroException(f"{type(e)}: {e}", exc=e)``, whose text is then
    ``<class '...'>: {e} {e}``; only ``{e}`` (and any suffix) is kept.
    """
    text = str(exc)
    inner = getattr(exc, "exc", None)
    if inner is not None:
        wrapped = f"{type(inner)}: {inner}"
        if text.startswith(wrapped):
            text = text[len(wrapped) :]
    return " ".join(text.split()) or type(exc).__name__
