"""Fault control of running emulators: one-line commands (``unplug 3 5``, ``drop 0.01``, ``lose 2``)
typed in a terminal, piped by a test script, or scheduled (``--unplug 3@10+5``).

Commands (case-insensitive; ``BUS`` is a bus name, every bus when left out):

====================  =========================================================================
``unplug ID [S]``     motor ID goes silent (for S seconds, then it is plugged back)
``plug ID``           motor ID answers again
``unplug #N``         the N-th motor of the bus (1-based, as given) leaves the line, whatever
                      its ID (a kit of motors all at ID 1: ``poppy emulate --motors XL-320:1*6``)
``plug #N``           the N-th motor is back on the line
``corrupt P [BUS]``   each reply byte gets a bit flipped with probability P (0-1)
``drop P [BUS]``      each reply is lost with probability P (0-1)
``delay MS [BUS]``    every reply comes MS milliseconds late
``lose [S] [BUS]``    the whole line goes away for S seconds (default 2), as an unplugged adapter
``status``            one line per bus: where it is served, its faults
``help``              the commands
====================  =========================================================================
"""

from __future__ import annotations

import heapq
import itertools
import logging
import math
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial

from poppy_core import checks
from poppy_core.emulator.bus_servers import Endpoint
from poppy_core.errors import ArgumentError
from poppy_core.schedule import Worker

logger = logging.getLogger(__name__)

DEFAULT_LOSS_S = 2.0
HELP = (
    "commands: unplug ID [SECONDS] | plug ID | unplug #N | plug #N | corrupt P [BUS] | "
    "drop P [BUS] | delay MS [BUS] | lose [SECONDS] [BUS] | status | help"
)


class ControlError(ValueError):
    """A command that cannot be run; the message says what was wrong, in one line."""


@dataclass(frozen=True)
class ScheduledUnplug:
    """``ID@T`` or ``ID@T+D``: unplug motor ``motor_id`` at ``at_s`` (for ``duration_s``)."""

    motor_id: int
    at_s: float
    duration_s: float | None = None

    @classmethod
    def parse(cls, text: str) -> ScheduledUnplug:
        """Parse ``ID@T`` or ``ID@T+D`` (seconds after the start).

        Raises:
            ControlError: not of that form.
        """
        ident, sep, when = text.partition("@")
        at_text, plus, duration_text = when.partition("+")
        try:
            if not sep or not ident.strip().isdigit():
                raise ValueError
            motor_id = int(ident)
            at_s = _seconds(at_text)
            duration_s = _seconds(duration_text) if plus else None
        except ValueError:
            raise ControlError(
                f"{text!r} is not ID@SECONDS or ID@SECONDS+SECONDS (e.g. 3@10 or 3@10+5)"
            ) from None
        return cls(motor_id, at_s, duration_s)


SECONDS = f"0-{checks.MAX_DURATION_S:g}"
"""What a duration of a fault command may be (a day at most)."""
MAX_REPLY_DELAY_MS = 10_000.0
"""The longest delay (or adapter latency) added to a reply: far past every timeout of a bus."""


def _seconds(text: str, high: float = checks.MAX_DURATION_S) -> float:
    """Seconds 0 up to ``high`` (a day); ValueError for anything else (1e309, nan, -1)."""
    try:
        return checks.in_range(float(text), 0.0, high)
    except ArgumentError:
        raise ValueError(text) from None


def _probability(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0.0 <= value <= 1.0:
        raise ControlError(f"{what} takes a probability between 0 and 1, not {text!r}")
    return value


class EmulatorControl:
    """Runs fault commands on named emulator servers, now or at a given time.

    Timed actions (``unplug 3 5`` plugging back, ``ScheduledUnplug``) run in a small thread
    started on the first one; :meth:`close` stops it.

    Args:
        servers: bus name -> running server.
        clock: monotonic clock in seconds.
    """

    def __init__(
        self,
        servers: Mapping[str, Endpoint],
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.servers = dict(servers)
        self._clock = clock
        self._cond = threading.Condition()
        self._events: list[tuple[float, int, str, Callable[[], None]]] = []
        self._order = itertools.count()
        self._worker: Worker | None = None
        self._closed = False

    # ------------------------------------------------------------------ commands

    def execute(self, line: str) -> str:
        """Run one command line and say what was done (one line).

        Raises:
            ControlError: unknown command, bad value, unknown motor or bus.
        """
        words = line.split()
        if not words:
            return ""
        name, args = words[0].lower(), words[1:]
        if name == "help":
            return HELP
        if name == "status":
            return "\n".join(self._status(bus) for bus in self.servers)
        handler = {
            "unplug": self._unplug,
            "plug": self._plug,
            "corrupt": self._corrupt,
            "drop": self._drop,
            "delay": self._delay,
            "lose": self._lose,
        }.get(name)
        if handler is None:
            raise ControlError(f"unknown command {words[0]!r}; {HELP}")
        return handler(args)

    def _server_of_motor(self, motor_id: int) -> Endpoint:
        for server in self.servers.values():
            if any(m.id == motor_id for m in server.bus.motors):
                return server
        known = sorted(m.id for s in self.servers.values() for m in s.bus.motors)
        raise ControlError(f"no motor {motor_id} (motors: {', '.join(map(str, known))})")

    def _motor_id(self, args: list[str], usage: str) -> int:
        if not args or not args[0].isdigit():
            raise ControlError(f"usage: {usage}")
        return int(args[0])

    def _buses(self, args: list[str], usage: str) -> list[str]:
        if len(args) > 1:
            raise ControlError(f"usage: {usage}")
        if not args:
            return list(self.servers)
        if args[0] not in self.servers:
            raise ControlError(f"no bus {args[0]!r} (buses: {', '.join(self.servers)})")
        return [args[0]]

    def _place(self, args: list[str], verb: str) -> str | None:
        """``#N`` (with the bus name when there are several): run ``verb`` on the N-th motor.

        Returns:
            What was done, or None when the arguments are not ``#N [BUS]``.
        """
        if not args or not args[0].startswith("#"):
            return None
        usage = f"{verb} #N [BUS] (N: the motor's place on the bus, from 1)"
        text = args[0][1:]
        if not text.isdigit() or len(args) > 2:
            raise ControlError(f"usage: {usage}")
        buses = self._buses(args[1:], usage)
        if len(buses) > 1:
            raise ControlError(f"usage: {usage}: name the bus ({', '.join(buses)})")
        bus = self.servers[buses[0]].bus
        try:
            (bus.attach if verb == "plug" else bus.detach)(int(text))
        except KeyError as exc:
            raise ControlError(str(exc.args[0])) from None
        return f"motor #{text} {verb}ged"

    def _unplug(self, args: list[str]) -> str:
        usage = "unplug ID [SECONDS]"
        placed = self._place(args, "unplug")
        if placed is not None:
            return placed
        motor_id = self._motor_id(args, usage)
        if len(args) > 2:
            raise ControlError(f"usage: {usage}")
        server = self._server_of_motor(motor_id)
        duration = None
        if len(args) == 2:
            try:
                duration = _seconds(args[1])
            except ValueError:
                raise ControlError(f"usage: {usage} (seconds {SECONDS})") from None
        server.bus.unplug(motor_id)
        if duration is None:
            return f"motor {motor_id} unplugged"
        self.at(self._clock() + duration, f"plug {motor_id}", partial(server.bus.plug, motor_id))
        return f"motor {motor_id} unplugged for {duration:g} s"

    def _plug(self, args: list[str]) -> str:
        placed = self._place(args, "plug")
        if placed is not None:
            return placed
        motor_id = self._motor_id(args, "plug ID")
        self._server_of_motor(motor_id).bus.plug(motor_id)
        return f"motor {motor_id} plugged"

    def _set_fault(self, args: list[str], knob: str, parse: Callable[[str], float]) -> list[str]:
        usage = f"{knob} VALUE [BUS]"
        if not args:
            raise ControlError(f"usage: {usage}")
        value = parse(args[0])
        buses = self._buses(args[1:], usage)
        for bus in buses:
            setattr(self.servers[bus].bus, knob, value)
        return buses

    def _corrupt(self, args: list[str]) -> str:
        buses = self._set_fault(args, "corrupt_rate", lambda t: _probability(t, "corrupt"))
        return f"corrupt {args[0]} on {', '.join(buses)}"

    def _drop(self, args: list[str]) -> str:
        buses = self._set_fault(args, "drop_rate", lambda t: _probability(t, "drop"))
        return f"drop {args[0]} on {', '.join(buses)}"

    def _delay(self, args: list[str]) -> str:
        def milliseconds(text: str) -> float:
            try:
                return _seconds(text, MAX_REPLY_DELAY_MS) / 1000.0
            except ValueError:
                raise ControlError(
                    f"delay takes milliseconds 0-{MAX_REPLY_DELAY_MS:g}, not {text!r}"
                ) from None

        buses = self._set_fault(args, "extra_delay_s", milliseconds)
        return f"delay {args[0]} ms on {', '.join(buses)}"

    def _lose(self, args: list[str]) -> str:
        usage = "lose [SECONDS] [BUS]"
        duration = DEFAULT_LOSS_S
        if args and args[0] not in self.servers:
            try:
                duration = _seconds(args[0])
            except ValueError:
                raise ControlError(f"usage: {usage} (seconds {SECONDS})") from None
            args = args[1:]
        buses = self._buses(args, usage)
        for bus in buses:
            self.servers[bus].lose(duration)
        return f"{', '.join(buses)} lost for {duration:g} s"

    def _status(self, name: str) -> str:
        server = self.servers[name]
        bus = server.bus
        unplugged = [str(m.id) for m in bus.motors if bus.faults.is_unplugged(m.id)]
        unplugged += [f"#{n}" for n in range(1, len(bus.motors) + 1) if not bus.is_attached(n)]
        return (
            f"{name}: {server.url} {'up' if server.connected else 'DOWN'}, "
            f"corrupt {bus.corrupt_rate:g}, drop {bus.drop_rate:g}, "
            f"delay {bus.extra_delay_s * 1000:g} ms, "
            f"unplugged: {', '.join(unplugged) or 'none'}"
        )

    # ------------------------------------------------------------------ timed actions

    def schedule(self, unplugs: list[ScheduledUnplug], start: float | None = None) -> None:
        """Unplug (and plug back) motors at times counted from ``start`` (default: now).

        Raises:
            ControlError: an unknown motor.
        """
        origin = self._clock() if start is None else start
        for item in unplugs:
            bus = self._server_of_motor(item.motor_id).bus
            motor_id = item.motor_id
            self.at(origin + item.at_s, f"unplug {motor_id}", partial(bus.unplug, motor_id))
            if item.duration_s is not None:
                back = origin + item.at_s + item.duration_s
                self.at(back, f"plug {motor_id}", partial(bus.plug, motor_id))

    def at(self, when: float, what: str, action: Callable[[], None]) -> None:
        """Run ``action`` at ``when`` (the control's clock) in the control's thread; one already
        due, with nothing due before it, runs now, before this returns (``--unplug 2@0``: motor 2
        is away before the emulator says where it serves, however late its thread would run)."""
        with self._cond:
            if self._closed:
                return
            due_before = bool(self._events) and self._events[0][0] <= when
            if when <= self._clock() and not due_before:
                self._act(what, action)
                return
            heapq.heappush(self._events, (when, next(self._order), what, action))
            if self._worker is None:
                self._worker = Worker("emulator control", self._run)
                self._worker.start()
            self._cond.notify()

    def _run(self, stopping: threading.Event) -> None:
        """Runs the actions when due until ``close`` (its condition is the loop's wake-up)."""
        while True:
            with self._cond:
                while not self._closed and (not self._events or self._events[0][0] > self._clock()):
                    timeout = self._events[0][0] - self._clock() if self._events else None
                    self._cond.wait(timeout)
                if self._closed:
                    return
                _, _, what, action = heapq.heappop(self._events)
            self._act(what, action)

    @staticmethod
    def _act(what: str, action: Callable[[], None]) -> None:
        try:
            action()
            logger.info("emulator control: %s", what)
        except Exception:
            logger.exception("emulator control: %s failed", what)

    def close(self) -> None:
        """Forget pending timed actions and stop the thread."""
        with self._cond:
            self._closed = True
            self._events.clear()
            self._cond.notify()
        if self._worker is not None:
            self._worker.close(2.0)  # joins (but from its own thread)
