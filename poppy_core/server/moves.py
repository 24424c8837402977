"""``MoveService``: record, save, play, stop and delete moves of poppy's move library by name.

Recordings live in memory until saved; saved moves go to the library (``moves_dir()``), never to
the working directory. Names follow the library's one rule (``check_name``: letters, digits,
``. _ -`` and spaces, starting with a letter or a digit, no ``/``), so a URL can never reach a
path outside the library, and a move the CLI recorded is one every client can play. A server
stopping saves the takes not yet saved (recordings in progress, takes kept after a failed save):
to the library when the name is free there, else to ``fallback_path()``, as ``poppy record``
does.
"""

from __future__ import annotations

import json
import logging
import threading
from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from poppy_core.errors import ConfigError, FileError
from poppy_core.motion import (
    Move,
    MovePlayer,
    MoveRecorder,
    check_name,
    delete_move,
    encode_pypot,
    fallback_path,
    list_moves,
    load_move,
    read_move,
    save_move,
    write_move,
)
from poppy_core.motion.leases import Lease, MotorLeases, motor_leases
from poppy_core.robot import Robot
from poppy_core.server.errors import ApiError
from poppy_core.server.start_time import StartTimes, check_start_at

logger = logging.getLogger(__name__)

MAX_RECORDINGS = 8
"""Recordings running at once (each is a thread)."""
RECORD_TIP = "start by recording a move with /records/<move_name>/record.json"
PLAY_TIP = "start by playing a move with /records/<move_name>/play.json"


@dataclass(frozen=True)
class SavedTake:
    """A take a stopping server saved: its name, where it went, how long it is."""

    name: str
    path: Path
    frames: int
    in_library: bool
    """False when the library could not have it (name taken, full disk): a temporary file."""


def check_move_name(name: str) -> str:
    """``name`` if it can name a library move (the library's ``check_name``), else
    ``ApiError("invalid")``."""
    try:
        return check_name(name)
    except ConfigError as exc:
        raise ApiError("invalid", str(exc), pypot_status=400) from None


class MoveService:
    """The recorders and players of one robot, by move name.

    Args:
        robot: the robot.
        starts: where a play with a ``start_at`` is armed (the service's; its own without one).
        leases: who drives each motor (the robot's ``motor_leases`` without one).
    """

    def __init__(
        self, robot: Robot, starts: StartTimes | None = None, leases: MotorLeases | None = None
    ) -> None:
        self.robot = robot
        self.starts = starts if starts is not None else StartTimes()
        self.leases = leases if leases is not None else motor_leases(robot)
        self._lock = threading.Lock()
        self._recorders: dict[str, MoveRecorder] = {}
        self._players: dict[str, MovePlayer] = {}
        self._closing = threading.Lock()
        self._starting = threading.Lock()
        """Held while a playback is checked, built, started and registered (one at a time), and
        by ``stop``/``stop_all``/``close``: a stop never misses a playback being started."""
        self._closed = False
        self.saved_on_close: list[SavedTake] = []
        """The takes ``close()`` saved (a server says where on stopping)."""
        self._lengths: dict[Path, tuple[tuple[int, int], float | None, int | None]] = {}

    # -- library -------------------------------------------------------------------------------

    def names(self) -> list[str]:
        """The library's moves by name."""
        return sorted({entry.name for entry in list_moves()})

    def entries(self) -> list[dict[str, Any]]:
        """The library's moves: name, format, size, duration and frames (None: unreadable)."""
        answer = []
        listed = list_moves()
        with self._lock:  # forget the files gone
            for gone in set(self._lengths) - {entry.path for entry in listed}:
                del self._lengths[gone]
        for entry in listed:
            duration_s, frames = self._length(entry.path)
            answer.append(
                {
                    "name": entry.name,
                    "format": entry.format,
                    "size_bytes": entry.size_bytes,
                    "duration_s": duration_s,
                    "frames": frames,
                }
            )
        return answer

    def _length(self, path: Path) -> tuple[float | None, int | None]:
        """A library file's duration and frames, read once per version of the file."""
        try:
            stat = path.stat()
        except OSError:
            return None, None
        key = (stat.st_mtime_ns, stat.st_size)
        with self._lock:
            known = self._lengths.get(path)
        if known is not None and known[0] == key:
            return known[1], known[2]
        try:
            move = read_move(path)
            length: tuple[float | None, int | None] = (round(move.duration_s, 3), len(move))
        except (ConfigError, FileError, OSError):
            length = (None, None)
        with self._lock:
            self._lengths[path] = (key, *length)
        return length

    def load(self, name: str) -> Move:
        """The library move ``name``, or ``ApiError("not_found")``."""
        check_move_name(name)
        if name not in self.names():
            raise ApiError("not_found", f"no move {name!r} in the library", tip=RECORD_TIP)
        try:
            return load_move(name)
        except ConfigError as exc:
            raise ApiError("not_found", str(exc), tip=RECORD_TIP) from None

    def value(self, name: str) -> Move:
        """The move being recorded under ``name`` (so far), else the library's."""
        check_move_name(name)
        with self._lock:
            recorder = self._recorders.get(name)
        return recorder.move if recorder is not None else self.load(name)

    def delete(self, name: str) -> None:
        """Delete a library move (``ApiError("not_found")`` if there is none)."""
        check_move_name(name)
        if name not in self.names():
            raise ApiError(
                "not_found", f"no move {name!r} in the library to delete", tip=RECORD_TIP
            )
        delete_move(name)

    # -- recording -----------------------------------------------------------------------------

    def record(self, name: str, motors: Sequence[str] | None = None) -> MoveRecorder:
        """Start recording ``name`` (restarting a recording of that name).

        Raises:
            ApiError: bad name, unknown motor, or too many recordings running.
        """
        check_move_name(name)
        known = {m.name for m in self.robot.motors} | set(self.robot.motorgroups)
        unknown = [m for m in motors or () if m not in known]
        if unknown:
            raise ApiError(
                "not_found",
                f"unknown motors: {', '.join(unknown)}",
                tip='give motors as a list or a comma-separated string, e.g. {"motors": ["m1"]}',
            )
        with self._lock:
            self._check_open()
            old = self._recorders.pop(name, None)
            if old is not None:
                old.stop()
            if len(self._recorders) >= MAX_RECORDINGS:
                raise ApiError(
                    "conflict", f"{MAX_RECORDINGS} recordings already run: save one first"
                )
            recorder = MoveRecorder(self.robot, motors=list(motors) if motors else None)
            recorder.start()
            self._recorders[name] = recorder
        return recorder

    def recording(self) -> list[str]:
        """Names being recorded (and takes kept after a failed save)."""
        with self._lock:
            return sorted(self._recorders)

    def recording_live(self) -> list[str]:
        """Names whose recorder still samples (not the takes kept after a failed save)."""
        with self._lock:
            return sorted(n for n, r in self._recorders.items() if r.recording)

    def save(self, name: str) -> Move:
        """Stop recording ``name`` and save it to the library (stopping a playback of it).

        A failed save (full disk, read-only library) answers 507 and keeps the recording, stopped,
        so that a later save of the same name writes it once there is room.
        """
        check_move_name(name)
        with self._lock:
            recorder = self._recorders.get(name)
            player = self._players.get(name)
        if recorder is None:
            raise ApiError("conflict", f"the move {name!r} is not being recorded", tip=RECORD_TIP)
        move = recorder.stop()
        if len(move) == 0:
            with self._lock:
                self._recorders.pop(name, None)
            raise ApiError("conflict", f"the recording {name!r} holds no frame yet")
        try:
            save_move(move, name)
        except FileError as exc:
            logger.warning("saving move %s failed, the recording is kept: %s", name, exc)
            raise ApiError(
                "storage",
                f"the recording {name!r} could not be saved ({exc}); it is kept: "
                "save it again once there is room",
                tip="free some space, then save again",
            ) from None
        with self._lock:
            if self._recorders.get(name) is recorder:
                del self._recorders[name]
        if player is not None and player.playing:
            player.stop()
        logger.info("saved move %s (%d frames)", name, len(move))
        return move

    # -- playing -------------------------------------------------------------------------------

    def play(
        self,
        name: str,
        speed: float = 1.0,
        backwards: bool = False,
        ramp_s: float | None = None,
        refuse_playing: bool = False,
        *,
        start_at: float | None = None,
        writer: Hashable | None = None,
        client: str = "",
    ) -> MovePlayer:
        """Play a library move; ``ramp_s``: the ramp to its first frame (None: from the
        distance; give it to a fleet's robots so that, wherever each one is, they play in phase
        from the shared start); ``start_at``: the shared start (wall clock, ``check_start_at``):
        the playback is armed now and starts then (None: now).

        A move plays once at a time: a second play of a move that is playing starts nothing and
        answers the playback running, as pypot's ``start_move_player`` does (its REST, ZMQ and
        Snap! routes), or, with ``refuse_playing`` (the v1 API), is refused with
        ``ApiError("conflict")``. The check, the start and the registration are one step, so two
        plays at once never start two players, and ``stop`` reaches the one started.

        The playback leases the move's motors until it ends (``client``: who asked). With a
        ``writer`` (a strict surface: v1, Zenoh) a motor another owner drives refuses the play;
        without (pypot's routes, Snap!, ZMQ) it plays anyway, leasing the motors free.

        Raises:
            MotorLeasedError: with a ``writer``, a motor another owner drives (nothing starts).
            ApiError: bad name, no such move, a move that cannot be played, already playing
                (``refuse_playing``), or the service closed.
            ArgumentError: a ``start_at`` too far from now.
        """
        check_move_name(name)
        when = check_start_at(start_at)
        with self._starting:
            self._check_open()
            with self._lock:
                running = self._players.get(name)
            if running is not None and running.playing:
                if refuse_playing:
                    raise ApiError(
                        "conflict",
                        f"the move {name!r} is already playing: stop it first",
                        tip=f"POST /api/v1/moves/{name}/stop, then play it again",
                    )
                return running
            move = self.load(name)
            try:
                player = MovePlayer(
                    self.robot, move, speed=speed, backwards=backwards, ramp_s=ramp_s
                )
            except ConfigError as exc:
                raise ApiError("invalid", str(exc)) from None
            except ValueError as exc:
                raise ApiError("invalid", f"cannot play {name!r}: {exc}") from None
            lease = Lease("move", name, client, stop=f"POST /api/v1/moves/{name}/stop")
            self.leases.take(lease, list(move.motors), strict=writer is not None)
            try:
                player.start(gate=self.starts.gate(when))  # with a start_at: armed now
            except BaseException:
                self.leases.release(lease)
                raise
            lease.alive = lambda: player.playing
            with self._lock:
                self._players[name] = player  # a stop before the start time finds it, cancels it
        return player

    def playing(self) -> list[str]:
        """Names being played."""
        with self._lock:
            return sorted(n for n, p in self._players.items() if p.playing)

    def stop(self, name: str) -> None:
        """Stop playing ``name`` (``ApiError("conflict")`` when it was never played)."""
        check_move_name(name)
        with self._starting, self._lock:  # a play of it under way is registered first
            player = self._players.get(name)
        if player is None:
            raise ApiError(
                "conflict", f"the move {name!r} has not been played", tip=PLAY_TIP, pypot_status=400
            )
        player.stop()

    def stop_all(self) -> list[str]:
        """Stop every playback, those being started included; the names that were playing."""
        with self._starting, self._lock:
            players = dict(self._players)
        playing = sorted(name for name, player in players.items() if player.playing)
        for player in players.values():
            player.stop()
        return playing

    def _check_open(self) -> None:
        if self._closed:
            raise ApiError("unavailable", "the server is stopping: nothing new starts")

    def close(self) -> list[SavedTake]:
        """Stop every playback and recording, and save the takes not saved yet; nothing starts
        after (``ApiError("unavailable")``).

        A recording in progress and a take kept after a failed save go to the library under
        their name when it is free there (a saved move is never replaced), else to
        ``fallback_path()``; a take nothing could hold is logged as lost. A second call (the
        app's lifespan and ``poppy serve`` both close) waits for the first and saves nothing new.

        Returns:
            The takes saved by this call (all of them are in ``saved_on_close``).
        """
        with self._closing:
            with self._starting, self._lock:  # nothing starts after this
                self._closed = True
                recorders = dict(self._recorders)
                players = list(self._players.values())
                self._recorders.clear()
                self._players.clear()
            for player in players:
                try:
                    player.stop()
                except Exception as exc:  # the others are stopped and the takes saved anyway
                    logger.warning("stopping a playback on closing failed: %s", exc)
            saved = []
            for name, recorder in sorted(recorders.items()):
                try:
                    take = self._save_on_close(name, recorder)
                except Exception as exc:
                    logger.warning("saving the take %s on closing failed: %s", name, exc)
                    continue
                if take is not None:
                    saved.append(take)
            self.saved_on_close.extend(saved)
            return saved

    def _save_on_close(self, name: str, recorder: MoveRecorder) -> SavedTake | None:
        try:
            move = recorder.stop()
        except FileError:  # a checkpoint file failed: the take is still held
            move = recorder.move
        if len(move) == 0:
            return None
        try:
            path = save_move(move, name, replace=False)
            in_library = True
        except FileError as exc:
            logger.info("the library cannot have the take %s (%s): saving it elsewhere", name, exc)
            try:
                path = write_move(move, fallback_path(name), replace=False)
            except FileError as again:
                logger.error("the take %s (%d frames) is lost: %s", name, len(move), again)
                return None
            in_library = False
        logger.info("saved the take %s (%d frames) to %s on closing", name, len(move), path)
        return SavedTake(name, path, len(move), in_library)


def pypot_positions(move: Move) -> dict[str, Any]:
    """A move's frames as pypot's ``{time: {motor: [position, speed]}}``."""
    positions = json.loads(encode_pypot(move))["positions"]
    assert isinstance(positions, dict)
    return positions
