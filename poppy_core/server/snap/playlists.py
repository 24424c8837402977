"""Several library moves played at once or one after the other (the Snap! blocks "play moves …").

pypot's Snap! library did this in the browser (a fork per move, or a loop waiting on each);
here the server does it, so one block call is enough and the moves follow each other without
the browser's round trips. Every move is checked (name, in the library, playable) before any
starts. A sequence runs in a thread that starts each move when the one before ends; stopping
one of its moves ("stop move", or the server closing) ends the sequence.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Sequence

from poppy_core.errors import PoppyError
from poppy_core.motion import MovePlayer
from poppy_core.schedule import Worker
from poppy_core.server.errors import ApiError
from poppy_core.server.moves import MoveService

logger = logging.getLogger(__name__)

MAX_MOVES = 64
"""The most moves one call plays (a list longer than this is a mistake)."""


class Playlists:
    """The moves played together or in sequence on one robot.

    Args:
        moves: the robot's move service (library, players).
    """

    def __init__(self, moves: MoveService) -> None:
        self.moves = moves
        self._lock = threading.Lock()
        self._sequences: list[tuple[frozenset[str], Worker]] = []

    def _check(self, names: Sequence[str]) -> float:
        """The total duration of ``names`` at speed 1 (each is loaded: unknown ones refused)."""
        if not names:
            raise ApiError("invalid", "no move given, e.g. wave;hello")
        if len(names) > MAX_MOVES:
            raise ApiError("invalid", f"{len(names)} moves: at most {MAX_MOVES} in one call")
        known = {motor.name for motor in self.moves.robot.motors}
        total = 0.0
        for name in names:
            move = self.moves.load(name)
            missing = [motor for motor in move.motors if motor not in known]
            if missing:
                raise ApiError(
                    "invalid",
                    f"the move {name!r} drives motors this robot lacks: {', '.join(missing)}",
                )
            total += move.duration_s
        return total

    def together(self, names: Sequence[str], speed: float) -> float:
        """Start every move now; the longest one's duration (s) at ``speed``."""
        self._check(names)
        players: list[MovePlayer] = []
        try:
            for name in names:
                players.append(self.moves.play(name, speed, client="Snap!"))
        except (ApiError, PoppyError):
            for player in players:  # all or none
                player.stop()
            raise
        return max(player.duration_s for player in players)

    def in_sequence(self, names: Sequence[str], speed: float) -> float:
        """Start the first move now and each next one when the one before ends; the total (s)."""
        total = self._check(names) / speed
        first = self.moves.play(names[0], speed, client="Snap!")
        rest = list(names[1:])
        worker = Worker(
            f"snap-sequence-{names[0]}",
            lambda stopping: self._run(stopping, rest, speed, first, entry),
        )
        entry = (frozenset(names), worker)
        with self._lock:
            self._sequences.append(entry)
        worker.start()
        return total

    def sequences(self) -> list[list[str]]:
        """The moves of each sequence still running (sorted names)."""
        with self._lock:
            return [sorted(names) for names, _ in self._sequences]

    def stop(self, name: str) -> None:
        """End every sequence holding ``name`` (the move itself is stopped by the caller)."""
        with self._lock:
            for names, worker in self._sequences:
                if name in names:
                    worker.request_stop()

    def _run(
        self,
        cancel: threading.Event,
        rest: list[str],
        speed: float,
        player: MovePlayer,
        entry: tuple[frozenset[str], Worker],
    ) -> None:
        current = ""
        try:
            for current in rest:
                while not player.wait(0.2):
                    if cancel.is_set():
                        return
                if cancel.is_set() or player.stopped or player.error is not None:
                    return  # stopped ("stop move", the server closing) or failed
                player = self.moves.play(current, speed, client="Snap!")
        except (ApiError, PoppyError) as exc:
            logger.warning("a sequence of moves stopped at %r: %s", current, exc)
        finally:
            with self._lock:
                if entry in self._sequences:
                    self._sequences.remove(entry)
