"""Episode recording: a robot, its cameras and a source of actions into a LeRobot dataset.

Each tick (``fps`` a second) reads the motors' present positions (``observation.state``), the
action of the source, and the latest frame of every camera (BGR turned RGB), and hands them to
``poppy_core.dataset.writer``. Sources: a scripted motion (the goals the robot is given),
a leader robot (its present positions), or the robot moved by hand (the action is the next
frame's state, as LeRobot's recordings of a compliant arm).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from poppy_core.dataset.writer import DatasetWriter, EpisodeSaved
from poppy_core.schedule import Periodic


class FrameSource(Protocol):
    """What recording needs of a camera: its latest frame (height x width x 3, BGR)."""

    @property
    def frame(self) -> np.ndarray: ...


class ActionSource(Protocol):
    """Where an episode's actions come from."""

    def begin(self) -> None:
        """The episode starts (start the motion, turn compliant...)."""

    def action(self, state: list[float]) -> list[float] | None:
        """This tick's action in degrees, or None: the next tick's state (by hand)."""

    def end(self) -> None:
        """The episode is over (stop the motion)."""


@dataclass
class Progress:
    """What the live line shows while an episode records."""

    episode: int
    elapsed_s: float
    frames: int
    dropped: int
    phase: str = "recording"


class Goals:
    """A scripted source: ``start`` moves the robot; the action is the motors' goals."""

    def __init__(
        self, robot: Any, motors: Sequence[str], start: Callable[[], Any], stop: Callable[[], Any]
    ) -> None:
        self._motors = [robot.motor(name) for name in motors]
        self._start, self._stop = start, stop

    def begin(self) -> None:
        self._start()

    def action(self, state: list[float]) -> list[float] | None:
        return [float(motor.goal_position) for motor in self._motors]

    def end(self) -> None:
        self._stop()


class ByHand:
    """The robot compliant, moved by a student: each action is the next frame's state."""

    def __init__(self, robot: Any, motors: Sequence[str]) -> None:
        self._motors = [robot.motor(name) for name in motors]

    def begin(self) -> None:
        for motor in self._motors:
            motor.compliant = True

    def action(self, state: list[float]) -> list[float] | None:
        return None

    def end(self) -> None:
        """The robot stays compliant between episodes (the student keeps moving it)."""


class Teleoperated:
    """Teleoperation: the action is the leader's present positions (``links``: follower motor
    -> leader motor, in the recorded order); ``start``/``stop`` run the teleoperation."""

    def __init__(
        self,
        leader: Any,
        links: Sequence[str],
        start: Callable[[], Any],
        stop: Callable[[], Any],
    ) -> None:
        self._motors = [leader.motor(name) for name in links]
        self._start, self._stop = start, stop

    def begin(self) -> None:
        self._start()

    def action(self, state: list[float]) -> list[float] | None:
        return [float(motor.present_position) for motor in self._motors]

    def end(self) -> None:
        self._stop()


class EpisodeRecorder:
    """Records episodes of ``robot`` (its ``motors``, ``cameras``) into ``writer``."""

    def __init__(
        self,
        robot: Any,
        writer: DatasetWriter,
        motors: Sequence[str],
        cameras: dict[str, FrameSource],
        source: ActionSource,
    ) -> None:
        self.writer = writer
        self.fps = writer.spec.fps
        self._motors = [robot.motor(name) for name in motors]
        self._cameras = cameras
        self.source = source

    def state(self) -> list[float]:
        """The motors' present positions, in degrees."""
        return [float(motor.present_position) for motor in self._motors]

    def images(self) -> dict[str, np.ndarray]:
        """Every camera's latest frame, RGB."""
        return {
            name: np.ascontiguousarray(cam.frame[..., ::-1]) for name, cam in self._cameras.items()
        }

    def record(
        self,
        task: str,
        duration_s: float,
        *,
        episode: int,
        stop: threading.Event,
        on_tick: Callable[[Progress], None] | None = None,
        discard: threading.Event | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> EpisodeSaved | None:
        """One episode of ``duration_s`` (or until ``stop``); None when it has no frame, or
        when ``discard`` is set at its end (its frames dropped: it is recorded again)."""
        self.writer.begin_episode(task)
        period = 1.0 / self.fps
        start = clock()
        schedule = Periodic(period, start)
        pending: tuple[list[float], list[float] | None, dict[str, np.ndarray]] | None = None
        self.source.begin()
        try:
            while not stop.is_set():
                now = clock()
                if now - start >= duration_s:
                    break
                if not schedule.due(now):
                    stop.wait(min(schedule.next_deadline - now, period))
                    continue
                schedule.advance(now)
                state = self.state()
                action = self.source.action(state)
                images = self.images()
                if pending is not None:
                    last_state, last_action, last_images = pending
                    self.writer.add_frame(last_state, last_action or state, last_images, live=True)
                pending = (state, action, images)
                if on_tick is not None:
                    on_tick(
                        Progress(
                            episode,
                            now - start,
                            self.writer.frames,
                            schedule.missed + self.writer.video_dropped,
                        )
                    )
            if pending is not None:
                last_state, last_action, last_images = pending
                self.writer.add_frame(last_state, last_action or last_state, last_images, live=True)
        finally:
            self.source.end()
        if self.writer.frames == 0 or (discard is not None and discard.is_set()):
            self.writer.discard_episode()
            return None
        return self.writer.save_episode()
