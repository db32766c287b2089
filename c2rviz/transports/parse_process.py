"""Parsing in a process of its own: ``ParseProcess``, for the doors' large inputs.

A 1 MiB CRCL document takes about 300 ms to read into commands, a 1 MB rosbridge frame
about 150 ms to decode and check, nearly all of it Python holding the interpreter's
lock: on a thread it still takes that lock from the event loop, so every client waits
its share. A ``ParseProcess`` runs such a parse in a child process with its own lock.

- **Lazy.** The child (``python -c ...serve()``, importing what the parse needs, a
  few seconds) starts on the first job, not with the program.
- **One job at a time, in the order they came.** Each door has one; its clients' large
  inputs queue for it in turn (each connection waits for its own before its next). It
  runs niced (``NICE``): on a busy machine the loop gets a free core first.
- **What crosses back is cheap to take in.** Unpickling 7000 waypoints costs the loop
  about 100 ms, as much as a long turn. So the child cuts every list or tuple longer
  than ``LONG`` into pickles of ``SLICE_ITEMS`` items (``pack``), and the loop unpickles
  them a few at a time (``unpack``), serving the other clients after each
  ``UNPACK_TURN_S``.
- **A child that dies costs one job.** Its caller hears ``ProcessLost`` (so does a job
  not answered within ``DEADLINE_S``, or a child not ready within ``START_S``: the child
  is killed); the next job starts a new child. A job whose caller gives up (its client
  left) still runs to its end, so the pipe stays in step.

An error the parsed code raises (a ``CrclError``, a ``RosbridgeError``) crosses as
its class and fields (``plan_process``'s rule) and is raised again here.
"""

from __future__ import annotations

import asyncio
import contextlib
import io
import logging
import os
import pickle
import signal
import struct
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO, Final

from ..errors import C2rvizError
from ..session.plan_process import portable_error, rebuilt_error

log = logging.getLogger("c2rviz.parse")

LONG: Final = 512
"""A list or tuple longer than this crosses back in slices [items]."""
SLICE_ITEMS: Final = 64
"""Items of a long list or tuple in one pickle (a 1 MiB document's waypoints: 110)."""
UNPACK_TURN_S: Final = 0.0005
"""The loop's unpickling before the other clients' turn [s]."""
DEADLINE_S: Final = 60.0
"""A job unanswered this long kills its child [s] (a 1 MiB parse takes about 0.3 s)."""
START_S: Final = 120.0
"""A child not ready for jobs this long after it started is killed [s] (its imports take
a few seconds)."""
NICE: Final = 10
"""How much lower the child's scheduling priority is than the server's (``os.nice``): on
a busy machine the loop is served first, and the sender of large inputs waits."""
_HEADER: Final = struct.Struct("<Q")
_ROOT: Final = str(Path(__file__).resolve().parents[2])  # where this ``c2rviz`` is found
_CHILD: Final = (  # (this c2rviz, whatever the working directory holds)
    f"import sys; sys.path.insert(0, {_ROOT!r}); "
    "from c2rviz.transports.parse_process import serve; serve()"
)


class ProcessLost(C2rvizError):
    """The parsing process died, or did not answer in time, before it answered a job."""

    def __init__(self, name: str, why: str) -> None:
        self.name, self.why = name, why
        super().__init__(f"the {name} process {why} (see the server log); a new one takes the next")


class _Packer(pickle.Pickler):
    """Pickles one answer; each long list or tuple goes in ``parts`` first, in slices."""

    def __init__(self, file: BinaryIO, parts: list[tuple[int, object]], seen: dict[int, Any]):
        super().__init__(file, pickle.HIGHEST_PROTOCOL)
        self.parts, self.seen = parts, seen

    def persistent_id(self, obj: Any) -> int | None:
        kind = type(obj)
        if (kind is not list and kind is not tuple) or len(obj) <= LONG:
            return None
        known = self.seen.get(id(obj))
        if known is not None:
            return int(known[0])
        number = len(self.seen)
        self.seen[id(obj)] = (number, obj)  # (obj kept: its id stays its own)
        for start in range(0, len(obj), SLICE_ITEMS):
            self.parts.append((number, _dumps(list(obj[start : start + SLICE_ITEMS]), self)))
        self.parts.append((number, kind.__name__))  # the end: its kind
        return number

    def reducer_override(self, obj: Any) -> Any:
        if isinstance(obj, BaseException):
            return rebuilt_error, (portable_error(obj),)
        return NotImplemented


def _dumps(obj: object, packer: _Packer) -> bytes:
    out = io.BytesIO()
    _Packer(out, packer.parts, packer.seen).dump(obj)
    return out.getvalue()


class _Unpacker(pickle.Unpickler):
    def __init__(self, data: bytes, sequences: dict[int, Any]) -> None:
        super().__init__(io.BytesIO(data))
        self.sequences = sequences

    def persistent_load(self, pid: Any) -> Any:
        return self.sequences[pid]


def pack(obj: object) -> bytes:
    """``obj`` pickled for ``unpack``: its long lists and tuples in slices, first."""
    root = _Packer(io.BytesIO(), [], {})
    main = _dumps(obj, root)
    return pickle.dumps((root.parts, main), pickle.HIGHEST_PROTOCOL)


async def unpack(data: bytes) -> Any:
    """What ``pack`` packed, unpickled on the loop ``UNPACK_TURN_S`` at a time."""
    parts, main = pickle.loads(data)  # (a list of bytes: no time)
    sequences: dict[int, Any] = {}
    began = time.perf_counter()
    for number, part in parts:
        if isinstance(part, bytes):
            sequences.setdefault(number, []).extend(_Unpacker(part, sequences).load())
        elif part == "tuple":
            sequences[number] = tuple(sequences.pop(number, ()))
        if time.perf_counter() - began > UNPACK_TURN_S:
            await asyncio.sleep(0)  # the other clients' turn
            began = time.perf_counter()
    return _Unpacker(main, sequences).load()


def serve(reader: BinaryIO | None = None, writer: BinaryIO | None = None) -> None:
    """The child: read ``(fn, args)`` jobs, answer each ``pack(("ok", fn(*args)))`` or
    ``pack(("error", exc))``, until its input ends (the server closed it, or died)."""
    if writer is None:  # stdout is the answers' pipe: anything printed goes to stderr
        writer = os.fdopen(os.dup(1), "wb")
        os.dup2(2, 1)
    reader = reader or sys.stdin.buffer
    with contextlib.suppress(ValueError, OSError):
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # the server's Ctrl-C is the server's
    with contextlib.suppress(AttributeError, OSError):
        os.nice(NICE)  # a free core goes to the server's loop first
    writer.write(_HEADER.pack(0))  # ready
    writer.flush()
    while True:
        header = reader.read(_HEADER.size)
        if len(header) < _HEADER.size:
            return
        fn, args = pickle.loads(reader.read(_HEADER.unpack(header)[0]))
        try:
            answer = pack(("ok", fn(*args)))
        except BaseException as exc:
            try:
                answer = pack(("error", exc))
            except Exception as unpicklable:
                answer = pack(("error", RuntimeError(f"parse answer: {unpicklable!r}")))
        writer.write(_HEADER.pack(len(answer)) + answer)
        writer.flush()


class ParseProcess:
    """A child process that runs parse jobs one at a time, started on the first job.

    Args:
        name: What it is called in errors and the log ("CRCL parsing").
        deadline_s: A job unanswered this long kills the child [s].
    """

    def __init__(self, name: str, deadline_s: float = DEADLINE_S) -> None:
        self.name, self.deadline_s = name, deadline_s
        self.started = 0
        """Children started so far (one more after each one lost)."""
        self.busy = False
        """A job is with the child now."""
        self._child: asyncio.subprocess.Process | None = None
        self._turn = asyncio.Lock()  # (its waiters go in the order they came)
        self._current: asyncio.Future[bytes] | None = None

    @property
    def pid(self) -> int | None:
        """The child's process id, while it runs."""
        return None if self._child is None else self._child.pid

    async def run(self, fn: Callable[..., Any], *args: Any) -> Any:
        """``fn(*args)`` in the child (``fn`` a module-level function, ``args`` and the
        result picklable): its result, or its exception raised here.

        Raises:
            ProcessLost: the child died or did not answer within ``deadline_s``.
        """
        job = asyncio.ensure_future(self._job(fn, args))
        try:
            answer = await asyncio.shield(job)
        except asyncio.CancelledError:
            if not self.busy or self._current is not job:
                job.cancel()  # not begun: dropped; begun: it reads its answer, unused
            raise
        kind, value = await unpack(answer)
        if kind == "error":
            raise value
        return value

    async def _job(self, fn: Callable[..., Any], args: tuple[Any, ...]) -> bytes:
        async with self._turn:
            self._current = asyncio.current_task()
            self.busy = True
            try:
                request = pickle.dumps((fn, args), pickle.HIGHEST_PROTOCOL)
                try:
                    child = await self._started()
                    return await asyncio.wait_for(self._ask(child, request), self.deadline_s)
                except asyncio.TimeoutError:
                    raise await self._lost(f"did not answer within {self.deadline_s:g} s") from None
                except (ConnectionError, asyncio.IncompleteReadError):
                    raise await self._lost(None) from None
            finally:
                self.busy = False
                self._current = None

    async def _started(self) -> asyncio.subprocess.Process:
        """The child, started if it is not running, once it is ready for jobs."""
        child = self._child
        if child is not None and child.returncode is None:
            return child
        child = self._child = await asyncio.create_subprocess_exec(
            sys.executable, "-c", _CHILD, stdin=asyncio.subprocess.PIPE,
            stdout=asyncio.subprocess.PIPE,
        )  # fmt: skip
        self.started += 1
        assert child.stdout is not None
        await asyncio.wait_for(child.stdout.readexactly(_HEADER.size), START_S)  # (ready)
        log.info("started the %s process (pid %d)", self.name, child.pid)
        return child

    async def _ask(self, child: asyncio.subprocess.Process, request: bytes) -> bytes:
        assert child.stdin is not None and child.stdout is not None
        child.stdin.write(_HEADER.pack(len(request)) + request)
        await child.stdin.drain()
        header = await child.stdout.readexactly(_HEADER.size)
        return await child.stdout.readexactly(_HEADER.unpack(header)[0])

    async def _lost(self, why: str | None) -> ProcessLost:
        """The child is lost: kill it, reap it, log why; the error for its job's caller
        (``why`` None: it ended by itself)."""
        child, self._child = self._child, None
        if child is None:  # (closed meanwhile: the server stops)
            return ProcessLost(self.name, why or "was closed")
        with contextlib.suppress(ProcessLookupError):
            child.kill()
        code = await child.wait()
        why = why or f"ended without an answer (exit code {code})"
        log.error("the %s process (pid %d) %s", self.name, child.pid, why)
        return ProcessLost(self.name, why)

    async def close(self) -> None:
        """End the child (its input closes; it is killed if it lingers)."""
        child, self._child = self._child, None
        if child is None or child.returncode is not None:
            return
        assert child.stdin is not None
        child.stdin.close()
        try:
            await asyncio.wait_for(child.wait(), 2.0)
        except asyncio.TimeoutError:
            with contextlib.suppress(ProcessLookupError):
                child.kill()
            await child.wait()
