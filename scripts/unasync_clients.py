"""Write the blocking client's verbs from the asyncio client's: one source for both.

The verbs of ``AsyncClient`` are written once, as coroutines (``c2rviz/clients/aio_*``);
this script writes their blocking twins by dropping ``async``/``await`` and renaming
``Async*``, as httpcore builds its sync half with ``unasync``, then formats them with
ruff. The generated files are checked in; ``tests/clients/test_unasync.py`` fails when
one is out of date (``--check`` says the same from the command line).

    python scripts/unasync_clients.py           # rewrite the generated files
    python scripts/unasync_clients.py --check   # exit 1 if one is out of date
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CLIENTS = ROOT / "c2rviz" / "clients"

SOURCES = {
    "aio_verbs.py": (
        "verbs.py",
        "``Client``'s verbs (``Verbs``), the blocking twins of ``aio_verbs.AsyncVerbs``.",
    ),
    "aio_scene_verbs.py": (
        "scene_verbs.py",
        "``Client``'s methods for the scene: markers, trails, recordings, workcell objects.",
    ),
}
"""Each source, the file written from it, and that file's docstring."""

RULES = [
    (r"\basync def\b", "def"),
    (r"\basync with\b", "with"),
    (r"\basync for\b", "for"),
    (r"\bawait ", ""),
    (r"\b__aenter__\b", "__enter__"),
    (r"\b__aexit__\b", "__exit__"),
    (r"\b__aiter__\b", "__iter__"),
    (r"\bAsync(Verbs|SceneVerbs)\b", r"\1"),
    (r"\basync client\b", "client"),
]
"""Regular expression and replacement, applied in order (the whole of unasync)."""

DOCSTRING = re.compile(r'\A"""(?:.|\n)*?"""\n', re.M)


def unasync(source: str, name: str, doc: str) -> str:
    """The blocking twin of ``source`` (the text of ``name``), before formatting."""
    text = DOCSTRING.sub("", source, count=1)
    for pattern, replacement in RULES:
        text = re.sub(pattern, replacement, text)
    head = (
        f"# Written by scripts/unasync_clients.py from c2rviz/clients/{name}: do not edit;\n"
        f"# edit {name}, then run `python scripts/unasync_clients.py`.\n"
    )
    return f'{head}"""{doc}"""\n{text}'


def formatted(text: str, target: Path) -> str:
    """``text`` as ruff formats it (the project's settings)."""
    done = subprocess.run(
        [sys.executable, "-m", "ruff", "format", "--stdin-filename", str(target), "-"],
        input=text,
        capture_output=True,
        text=True,
        cwd=ROOT,
        check=True,
    )
    return done.stdout


def generated() -> dict[Path, str]:
    """Each generated file and the text it should hold."""
    out = {}
    for name, (target, doc) in SOURCES.items():
        path = CLIENTS / target
        out[path] = formatted(unasync((CLIENTS / name).read_text(), name, doc), path)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if a file is stale")
    args = parser.parse_args(argv)
    stale = [
        path for path, text in generated().items() if not path.exists() or path.read_text() != text
    ]
    if args.check:
        for path in stale:
            print(f"{path.relative_to(ROOT)} is out of date: run python scripts/unasync_clients.py")
        return 1 if stale else 0
    for path, text in generated().items():
        if path in stale:
            path.write_text(text)
            print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
