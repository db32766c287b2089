"""The browser folder's shared programs: one Motoman program and page per worker for the
tests that need only the arm at home (``browser_support.LastingProgram``), one with the page
in its own process for ``test_browser_page_process.py``'s runs of the same tests."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from browser_support import FreshContexts, LastingProgram


def lasting(
    chromium: FreshContexts, factory: pytest.TempPathFactory, *args: str
) -> Iterator[LastingProgram]:
    with chromium.marked():
        program = LastingProgram(chromium, factory.mktemp("recordings"), *args)
    try:
        yield program
    finally:
        with chromium.marked():
            program.close()


@pytest.fixture(scope="session")
def motoman(
    chromium: FreshContexts, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[LastingProgram]:
    """The Motoman's program and page, shared (``LastingProgram.session`` for each test)."""
    yield from lasting(chromium, tmp_path_factory)


@pytest.fixture(scope="session")
def motoman_page_process(
    chromium: FreshContexts, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[LastingProgram]:
    """The same with ``--page-process``: the page served by a process of its own."""
    yield from lasting(chromium, tmp_path_factory, "--page-process")


@pytest.fixture
def own_motoman(
    chromium: FreshContexts, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[LastingProgram]:
    """A Motoman program and page of the test's own (the look-back test: shared, its
    page-process run once waited 180 s for a look back that never came, in a full run)."""
    yield from lasting(chromium, tmp_path_factory)


@pytest.fixture
def own_motoman_page_process(
    chromium: FreshContexts, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[LastingProgram]:
    """The same with ``--page-process``."""
    yield from lasting(chromium, tmp_path_factory, "--page-process")
