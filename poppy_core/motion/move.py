"""``Move``: motor positions sampled at a fixed framerate, with interpolation between frames."""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from typing import IO, Any

import numpy as np
import numpy.typing as npt

from poppy_core.errors import ArgumentError, UnknownMotorError
from poppy_core.motion.move_bounds import (  # re-exported: the bounds of a Move
    MAX_FRAMERATE_HZ,
    MAX_MOTORS,
    MAX_POSITION_DEG,
    MAX_SPEED_DPS,
    MAX_VALUES,
    MIN_FRAMERATE_HZ,
    FloatArray,
    check_size,
    resample,
)
from poppy_core.motion.move_pypot import bad_move, parse_pypot, pypot_json
from poppy_core.motion.plots import plot_move

__all__ = [
    "MAX_FRAMERATE_HZ",
    "MAX_MOTORS",
    "MAX_POSITION_DEG",
    "MAX_SPEED_DPS",
    "MAX_VALUES",
    "MIN_FRAMERATE_HZ",
    "FloatArray",
    "Move",
    "PositionArray",
    "check_size",
    "resample",
]


class PositionArray(np.ndarray[Any, np.dtype[np.float64]]):
    """A move's positions array that pypot scripts may also call: ``move.positions()``."""

    move: Move | None = None

    def __call__(self) -> dict[float, dict[str, list[float]]]:
        if self.move is None:
            raise TypeError("only a move's own positions can be called")
        return self.move.timed_positions()


class Move:
    """A recorded motion: frame ``i`` holds every motor's position at ``i / framerate`` seconds.

    Positions are degrees in the robot's user frame (what ``Motor.present_position`` reads).

    Args:
        framerate: frames per second (> 0).
        motors: the motor names, one per column.
        positions: shape ``(frames, len(motors))``, degrees.
        speeds: the same shape in deg/s, or None (pypot files carry them; playback ignores them).
        metadata: free header fields (``created``, ``robot``, ``description``...), JSON-ready.

    Raises:
        ArgumentError: a framerate out of range, duplicate or empty motor names, a wrong shape,
            a value that is not a finite number or out of range, a move too large (see
            ``check_size``). It is also a ``ValueError``.
    """

    def __init__(
        self,
        framerate: float,
        motors: Sequence[str] = (),
        positions: npt.ArrayLike = (),
        *,
        speeds: npt.ArrayLike | None = None,
        metadata: Mapping[str, Any] | None = None,
    ) -> None:
        rate = float(framerate)
        if not math.isfinite(rate) or rate <= 0:
            raise ArgumentError(
                f"framerate must be a positive number, got {framerate!r}",
                field="framerate",
                value=framerate,
            )
        names = tuple(str(m) for m in motors)
        if any(not n for n in names):
            raise ArgumentError("motor names must not be empty", field="motors", value=names)
        if len(set(names)) != len(names):
            raise ArgumentError(
                f"motor names must be unique, got {', '.join(names)}", field="motors", value=names
            )
        self.framerate = rate
        self.motors = names
        self.positions = self._checked(positions, "positions", MAX_POSITION_DEG)
        check_size(rate, len(self.positions), len(names))
        self.speeds = None if speeds is None else self._checked(speeds, "speeds", MAX_SPEED_DPS)
        if self.speeds is not None and self.speeds.shape != self.positions.shape:
            raise ArgumentError(
                "speeds must have the same shape as positions", field="speeds", value=None
            )
        self.metadata: dict[str, Any] = dict(metadata or {})

    def _checked(self, values: npt.ArrayLike, what: str, bound: float) -> FloatArray:
        try:
            array = np.array(values, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ArgumentError(f"{what} must be numbers ({exc})", field=what) from None
        if array.size == 0:
            array = array.reshape(0, len(self.motors))
        if array.ndim != 2 or array.shape[1] != len(self.motors):
            raise ArgumentError(
                f"{what} must have shape (frames, {len(self.motors)}), got {array.shape}",
                field=what,
            )
        if not np.all(np.isfinite(array)):
            raise ArgumentError(f"{what} must be finite numbers", field=what)
        if array.size and float(np.max(np.abs(array))) > bound:
            worst = float(np.max(np.abs(array)))
            raise ArgumentError(
                f"{what} must be within ±{bound:g}, got {worst:g}", field=what, value=worst
            )
        return array

    @classmethod
    def from_frames(
        cls,
        framerate: float,
        frames: Sequence[Mapping[str, float]],
        *,
        metadata: Mapping[str, Any] | None = None,
    ) -> Move:
        """Build a move from frames given as ``{motor: degrees}`` dicts (same motors in each).

        Raises:
            ArgumentError: frames that do not all name the same motors.
        """
        motors = list(frames[0]) if frames else []
        rows = []
        for index, frame in enumerate(frames):
            if set(frame) != set(motors):
                raise ArgumentError(
                    f"frame {index} names other motors than frame 0", field="frames", value=index
                )
            rows.append([float(frame[m]) for m in motors])
        return cls(framerate, motors, rows, metadata=metadata)

    # -- pypot's Move API -----------------------------------------------------------------------

    def add_position(self, pos: Mapping[str, Any], time: float | None = None) -> None:
        """Append a frame, as pypot's ``move.add_position(pos, time)``.

        Args:
            pos: motor name -> degrees, or -> ``[degrees, speed]`` as pypot's recorder stores.
            time: the frame's time; frames are kept in order at the framerate, so it is only
                checked to come after the previous frame's.

        Raises:
            ArgumentError: a frame whose motors differ from the move's, a value that is not a
                number, a time before the last frame's.
        """
        names = tuple(pos)
        if len(self) == 0 and not self.motors:
            self.motors = names
            self.positions = np.empty((0, len(names)))
        if set(names) != set(self.motors):
            raise ArgumentError(
                f"the frame's motors ({', '.join(names)}) are not the move's "
                f"({', '.join(self.motors)})",
                field="pos",
                value=names,
            )
        if time is not None and len(self) and float(time) < self.duration_s:
            raise ArgumentError(
                f"frame time {time} s comes before the last frame's", field="time", value=time
            )
        values = [pos[m][0] if isinstance(pos[m], list | tuple) else pos[m] for m in self.motors]
        row = self._checked([values], "pos", MAX_POSITION_DEG)
        check_size(self.framerate, len(self) + 1, len(self.motors))
        self.positions = np.vstack([self.positions, row])
        self.speeds = None

    @property
    def positions(self) -> PositionArray:
        """Shape ``(frames, motors)``, degrees; called, pypot's ``move.positions()``: time ->
        motor name -> ``[degrees, speed]``."""
        view = self._positions.view(PositionArray)
        view.move = self
        return view

    @positions.setter
    def positions(self, value: FloatArray) -> None:
        self._positions = np.asarray(value, dtype=np.float64)

    def timed_positions(self) -> dict[float, dict[str, list[float]]]:
        """pypot's ``move.positions()``: time -> motor name -> ``[degrees, speed]``."""
        speeds = self.speeds if self.speeds is not None else np.zeros_like(self.positions)
        return {
            float(t): {
                m: [float(p), float(v)] for m, p, v in zip(self.motors, prow, vrow, strict=True)
            }
            for t, prow, vrow in zip(self.times(), self.positions, speeds, strict=True)
        }

    def iterpositions(self) -> Iterator[tuple[float, dict[str, list[float]]]]:
        """pypot's ``iterpositions()``: (time, frame) pairs."""
        return iter(self.timed_positions().items())

    def save(self, file: IO[str]) -> None:
        """Write the move as pypot's move JSON to an open text file (pypot's ``save``)."""
        file.write(pypot_json(self.framerate, self.motors, self.positions, self.speeds).decode())

    @classmethod
    def load(cls, file: IO[str] | IO[bytes]) -> Move:
        """Read pypot's move JSON from an open file (pypot's ``Move.load``).

        Raises:
            ConfigError: not pypot move JSON (the file's name and the reason).
        """
        return cls.loads(file.read(), str(getattr(file, "name", "<file>")))

    @classmethod
    def loads(cls, text: str | bytes, source: str = "<json>") -> Move:
        """Read pypot's move JSON from a string (pypot's ``Move.loads``); ``source`` names it in
        errors (keys sorted as times; irregular times are resampled).

        Raises:
            ConfigError: not pypot move JSON (the source and the reason).
        """
        framerate, motors, positions, speeds = parse_pypot(text, source)
        try:
            return cls(framerate, motors, positions, speeds=speeds, metadata={})
        except ValueError as exc:
            raise bad_move(source, str(exc)) from None

    def __repr__(self) -> str:
        return (
            f"<Move {len(self)} frames at {self.framerate:g} Hz, {self.duration_s:.2f} s, "
            f"motors={list(self.motors)}>"
        )

    def __len__(self) -> int:
        return int(self.positions.shape[0])

    @property
    def period_s(self) -> float:
        """Time between two frames."""
        return 1.0 / self.framerate

    @property
    def duration_s(self) -> float:
        """Time from the first frame to the last (0 for fewer than two frames)."""
        return max(len(self) - 1, 0) / self.framerate

    def plot(self, ax: Any = None) -> Any:
        """Draw each motor's position over time on a matplotlib axis (pypot's ``move.plot(ax)``);
        without one, on a new Agg axis. Returns the axis."""
        return plot_move(self, ax)

    def times(self) -> FloatArray:
        """The time of each frame in seconds."""
        return np.arange(len(self), dtype=np.float64) / self.framerate

    def frame(self, index: int) -> dict[str, float]:
        """Frame ``index`` as ``{motor: degrees}`` (negative indexes count from the end)."""
        return dict(zip(self.motors, (float(v) for v in self.positions[index]), strict=True))

    def trajectory(self, motor: str) -> FloatArray:
        """Every position of one motor.

        Raises:
            UnknownMotorError: a motor the move does not hold.
        """
        if motor not in self.motors:
            raise UnknownMotorError(
                f"the move has no motor {motor!r} (motors: {', '.join(self.motors)})",
                motor=motor,
                known=list(self.motors),
            )
        return self.positions[:, self.motors.index(motor)].copy()

    def positions_at(self, t_s: float) -> FloatArray:
        """Positions at ``t_s`` seconds, linearly interpolated, held at both ends.

        Raises:
            ArgumentError: the move has no frame.
        """
        count = len(self)
        if count == 0:
            raise ArgumentError("an empty move has no position", field="frames", value=0)
        x = min(max(float(t_s) * self.framerate, 0.0), float(count - 1))
        low = math.floor(x)
        if low >= count - 1:
            last: FloatArray = self.positions[count - 1].copy()
            return last
        frac = x - low
        result: FloatArray = self.positions[low] * (1.0 - frac) + self.positions[low + 1] * frac
        return result

    def position_at(self, t_s: float) -> dict[str, float]:
        """``positions_at`` as ``{motor: degrees}``."""
        return dict(zip(self.motors, (float(v) for v in self.positions_at(t_s)), strict=True))

    def reversed(self) -> Move:
        """The same move played from its last frame to its first."""
        speeds = None if self.speeds is None else -self.speeds[::-1]
        return Move(
            self.framerate,
            self.motors,
            self.positions[::-1],
            speeds=speeds,
            metadata=self.metadata,
        )

    def select(self, motors: Sequence[str]) -> Move:
        """A move holding only ``motors`` (in that order).

        Raises:
            UnknownMotorError: a motor the move does not hold.
        """
        missing = [m for m in motors if m not in self.motors]
        if missing:
            raise UnknownMotorError(
                f"the move has no motor {', '.join(missing)} (motors: {', '.join(self.motors)})",
                motor=missing[0],
                known=list(self.motors),
            )
        columns = [self.motors.index(m) for m in motors]
        speeds = None if self.speeds is None else self.speeds[:, columns]
        return Move(
            self.framerate,
            motors,
            self.positions[:, columns],
            speeds=speeds,
            metadata=self.metadata,
        )

    def stats(self) -> dict[str, dict[str, float]]:
        """Per motor: ``min``, ``max``, ``mean``, ``start``, ``end`` (degrees), ``range``."""
        result: dict[str, dict[str, float]] = {}
        for index, name in enumerate(self.motors):
            column = self.positions[:, index]
            if column.size == 0:
                result[name] = {}
                continue
            low, high = float(column.min()), float(column.max())
            result[name] = {
                "min": low,
                "max": high,
                "range": high - low,
                "mean": float(column.mean()),
                "start": float(column[0]),
                "end": float(column[-1]),
            }
        return result

    def same_as(self, other: Move, tolerance_deg: float = 0.0) -> bool:
        """True when both moves hold the same motors, framerate and positions (± tolerance)."""
        return (
            self.motors == other.motors
            and math.isclose(self.framerate, other.framerate, rel_tol=1e-9)
            and self.positions.shape == other.positions.shape
            and bool(np.all(np.abs(self.positions - other.positions) <= tolerance_deg))
        )
