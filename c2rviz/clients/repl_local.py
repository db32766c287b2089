"""The REPL's local commands: the words ``c2rviz-cli`` runs itself, as the seed's client did.

``file``, ``sleep``, ``where``, ``goto``, ``watch``, ``help``, ``q`` and ``quit``
are answered here (some by asking the server); every other line is sent as
typed by the loop in ``repl``. ``LocalCommands`` holds what they share: the
connection, where output goes, the options, and the count of lines that got
an ``error:``. How ``goto`` moves (the server's motion, or steps) is ``goto``'s.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import TextIO

from ..errors import BadArguments, C2rvizError
from ..protocol.grammar import parse_line
from ..protocol.verbs.scene import Watch
from ..protocol.verbs.seed import Joints, Sleep
from .bag_play import is_bag, play_in_repl
from .client import Client
from .connection import find_script
from .errors import ConnectionLost
from .goto import motion_of, step, target_problem, travel
from .player import play
from .script import check_robot, load_script, robot_mismatch
from .stream import Progress, shown, watch_lines

LOCAL_USAGE = {
    "file": (
        "file NAME [speed=X]",
        "play a command file (here, else commands/) or a ROS bag; X divides sleeps",
    ),
    "sleep": ("sleep S", "wait S seconds here"),
    "where": (
        "where",
        "joint names and values, in this connection's units (at a terminal; piped, the "
        "server's reply as it is)",
    ),
    "goto": (
        "goto v0,...,vn-1 [step=S] [rate=HZ]",
        "move there with the server's motion (ok on arrival; Ctrl-C stops the arm); "
        "step=/rate=: only for a server without motion, which gets small joints steps",
    ),
    "watch": ("watch [HZ]", "print the server's state and event lines until Ctrl-C"),
    "help": ("help [VERB]", "this list; with a verb: its line and its docs page"),
    "q": ("q", "leave (the server keeps running)"),
    "quit": ("quit", "stop the server, then leave"),
}
DEFAULT_STEP_DEG = 2.0


def _options(verb: str, words: list[str], allowed: Sequence[str]) -> tuple[list[str], dict]:
    """Split ``key=value`` words (positive numbers) from the rest."""
    usage = LOCAL_USAGE[verb][0]
    rest, options = [], {}
    for word in words:
        key, eq, text = word.partition("=")
        if not eq:
            rest.append(word)
            continue
        if key not in allowed:
            raise BadArguments(verb, f"unknown option {key!r}", usage)
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (value > 0 and math.isfinite(value)):
            raise BadArguments(verb, f"{key} must be a number > 0, got {text!r}", usage)
        options[key] = value
    return rest, options


class LocalCommands:
    """The local words, over one connection; ``local[verb](words)`` runs one."""

    def __init__(
        self,
        client: Client,
        *,
        out: TextIO,
        info: TextIO,
        step: float | None = None,
        rate_hz: float = 50.0,
        speed: float = 1.0,
        config: str | None = None,
    ) -> None:
        """Args:
        client: The connection (not yet open).
        out: Replies and results.
        info: Connection messages.
        step: Largest ``goto`` step, in the connection's units (default 2 degrees).
        rate_hz: ``goto`` steps per second.
        speed: ``file`` divides sleeps by this.
        config: The ``--config`` ini (where ``file`` finds the recording folder).
        """
        self.client = client
        self.config = config
        self.out = out
        self.info = info
        self.step = step
        self.rate_hz = rate_hz
        self.speed = speed
        self.errors = 0
        """Lines that got an ``error:`` (from the server or from this client)."""
        self.local: dict[str, Callable[[list[str]], bool]] = {
            "file": self._file,
            "sleep": self._sleep,
            "where": self._where,
            "goto": self._goto,
            "watch": self._watch,
            "help": self._help,
            "q": lambda words: False,
            "quit": self._quit,
        }
        """Each local word's runner: it returns False when the REPL should end."""

    def say(self, message: str) -> None:
        """A connection message (the server's text in it escaped: ``stream.shown``)."""
        print(shown(message), file=self.info, flush=True)

    def show(self, message: str) -> None:
        """A reply or a result (the server's text in it escaped: ``stream.shown``)."""
        print(shown(message), file=self.out, flush=True)

    def ask(self, line: str) -> str:
        """Send ``line``; if the connection was lost, reconnect and send it once more."""
        try:
            return self.client.ask(line)
        except ConnectionLost as exc:
            self.say(f"{exc}; reconnecting")
        return self.client.ask(line)

    def _file(self, words: list[str]) -> bool:
        rest, options = _options("file", words, ["speed"])
        if len(rest) != 1:
            raise BadArguments("file", "needs one file name", LOCAL_USAGE["file"][0])
        if is_bag(rest[0]):  # a ROS bag's joint states, checked whole, then streamed
            speed = options.get("speed", self.speed)
            self.errors += play_in_repl(self.client, rest[0], speed, self.out)
            return True
        try:
            script = load_script(find_script(rest[0], self.config), rest[0])
        except OSError as exc:
            raise C2rvizError(f"file: {exc}") from None
        client = self.client
        names = client.joint_names()
        robot = client.robot_name or "?"
        mismatch = robot_mismatch(script, robot, names)
        if mismatch is not None:
            self.say(f"warning: {mismatch}; playing it anyway")
        problems = script.all_problems() or check_robot(script, robot, names)
        for problem in problems:
            self.show(problem)
        if problems:
            self.errors += 1
            self.show(f"{script.name}: nothing was sent")
            return True
        show = Progress(self.out, self.out, in_place=False)
        degrees = client.in_degrees
        try:
            errors = play(client, script, show, speed=options.get("speed", self.speed))
        except ConnectionLost:
            self.errors += 1
            return True  # play has said where it stopped; the next command reconnects
        self.errors += errors > 0
        if not errors:
            self.show(f"{script.name}: {script.count} commands, all ok")
        self._left(script.name, degrees, None if errors else script.last_mode)
        return True

    def _left(self, name: str, degrees: bool, mode: str | None) -> None:
        """Say what a command file's own lines left set on this connection: its lines act
        as if typed here, so a ``degrees`` or ``motion`` line stays (docs/clients.md)."""
        changed = []
        if self.client.in_degrees != degrees:
            unit, back = (
                ("degrees", "radians") if self.client.in_degrees else ("radians", "degrees")
            )
            changed.append(f"in {unit} ('{back}' goes back)")
        if mode is not None:
            changed.append(f"in motion {mode}")
        if changed:
            self.say(f"{name} left this connection {' and '.join(changed)}, as its lines say")

    def _sleep(self, words: list[str]) -> bool:
        command = parse_line(" ".join(["sleep", *words]))
        assert isinstance(command, Sleep)
        time.sleep(command.seconds)
        return True

    def _where(self, words: list[str]) -> bool:
        names = self.client.joint_names()
        values = self.client.where()
        unit = "degrees" if self.client.in_degrees else "radians"
        self.show(f"{self.client.robot_name} ({unit}):")
        width = max(map(len, names))
        for i, (name, value) in enumerate(zip(names, values)):
            self.show(f"  {i}  {name:<{width}}  {value:.10g}")
        return True

    def _goto(self, words: list[str]) -> bool:
        usage = LOCAL_USAGE["goto"][0]
        rest, options = _options("goto", words, ["step", "rate"])
        try:
            command = parse_line(" ".join(["joints", *rest]))
        except BadArguments as exc:
            raise BadArguments("goto", exc.problem, usage) from None
        assert isinstance(command, Joints)
        target = list(command.values)
        client = self.client
        problem = target_problem(client, target)  # refuse before anything moves
        if problem is not None:
            raise BadArguments("goto", problem, usage)
        mode = motion_of(client.ask("motion"))
        if mode is None:  # a server from before motion: step there
            return self._step(target, options)
        arrival = travel(client, target, mode)
        if arrival.interrupted:
            self.show(f"goto: interrupted, the arm stopped: {arrival.reply}")
        elif arrival.reply.startswith("ok"):
            self.show(f"ok (goto: arrived in {arrival.seconds:.2f} s)")
        else:
            self.errors += 1
            self.show(f"goto: {arrival.reply}")
        if arrival.restored and not arrival.restored.startswith("ok"):
            self.errors += 1
            self.show(f"goto: putting back 'motion {mode}': {arrival.restored}")
        return True

    def _step(self, target: list[float], options: dict[str, float]) -> bool:
        """``goto`` on a server without motion: ``joints`` lines a step apart."""
        client = self.client
        default_step = DEFAULT_STEP_DEG if client.in_degrees else math.radians(DEFAULT_STEP_DEG)
        step_size = options.get("step", self.step or default_step)
        period_s = 1.0 / options.get("rate", self.rate_hz)
        stepped = step(client, client.where(), target, step_size, period_s)
        if not stepped.reply.startswith("ok"):
            self.errors += 1
            self.show(f"goto: stopped at step {stepped.done + 1}/{stepped.steps}: {stepped.reply}")
        else:
            self.show(f"ok (goto: {stepped.steps} steps in {stepped.seconds:.2f} s)")
        return True

    def _watch(self, words: list[str]) -> bool:
        """Print the stream (on a connection of its own) until Ctrl-C."""
        command = parse_line(" ".join(["watch", *words]))
        assert isinstance(command, Watch)
        client = self.client
        try:
            lines = watch_lines(
                client.host, client.port, command.hz, client.in_degrees, client.chosen_robot
            )
            for line in lines:
                self.show(line)
        except KeyboardInterrupt:
            return True
        raise ConnectionLost(client.host, client.port)

    def _help(self, words: list[str]) -> bool:
        if words:  # one verb: this client's own, or the server's line and docs page
            local = LOCAL_USAGE.get(words[0].lower()) if len(words) == 1 else None
            if local is not None:
                self.show(f"{local[0]}: {local[1]} (this client; see docs/clients.md)")
                return True
            reply = self.ask(" ".join(["help", *words]))
            self.show(reply)
            self.errors += not reply.startswith("ok")
            return True
        self.show("local commands (this client):")
        width = max(len(usage) for usage, _ in LOCAL_USAGE.values())
        for usage, what in LOCAL_USAGE.values():
            self.show(f"  {usage:<{width}}  {what}")
        reply = self.ask("help")
        self.show("server commands (sent as typed; # starts a comment):")
        for usage in reply.partition(": ")[2].split("; "):
            # A verb this client handles itself (where, sleep, help, quit) is listed once,
            # above: typed here, it never reaches the server as the server's own verb.
            if usage.split(" ", 1)[0].lower() not in LOCAL_USAGE:
                self.show(f"  {usage}")
        return True

    def _quit(self, words: list[str]) -> bool:
        reply = self.ask("quit")
        self.show(reply)
        self.errors += not reply.startswith("ok")
        return False
