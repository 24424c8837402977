"""A recording session: the episodes and resets of an ``EpisodeRecorder``, steered by
lerobot-record's three controls, with its live state; the one loop the CLI and the server run.

Right arrow (``end_episode``) ends the episode (saved) or the reset under way; left arrow
(``rerecord``) ends the episode and records it again (its frames dropped); Esc (``stop``) stops
the recording after saving the episode under way, as ``lerobot-record`` does.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

from poppy_core.errors import ArgumentError

if TYPE_CHECKING:  # the writer's modules (pyarrow, PyAV) load when a recording starts
    from poppy_core.motion.episodes import EpisodeRecorder, Progress

RIGHT, LEFT, ESC, ENTER = "right", "left", "esc", "enter"
MAX_EPISODES = 10_000
MAX_EPISODE_S = 3600.0


def check_episodes(episodes: object) -> int:
    """A number of episodes: a whole number, 1 to 10000."""
    if (
        isinstance(episodes, bool)
        or not isinstance(episodes, int)
        or not 1 <= episodes <= MAX_EPISODES
    ):
        raise ArgumentError(
            f"{episodes!r}: give 1 to {MAX_EPISODES} episodes", field="episodes", value=episodes
        )
    return episodes


def check_seconds(value: object, name: str, low: float) -> float:
    """A length in seconds, ``low`` to an hour."""
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or not low <= value <= MAX_EPISODE_S
    ):
        raise ArgumentError(
            f"{value!r}: give {low:g} to {MAX_EPISODE_S:g} seconds", field=name, value=value
        )
    return float(value)


class Controls:
    """What the keys (or the page's buttons) asked: ``ending`` ends the episode or reset under
    way, ``rerecord`` drops that episode to record it again, ``stop`` ends the recording."""

    def __init__(self) -> None:
        self.ending = threading.Event()
        self.rerecord = threading.Event()
        self.stop = threading.Event()

    def press(self, key: str) -> None:
        """``RIGHT``, ``LEFT``, ``ESC`` or ``ENTER`` (as Esc)."""
        if key == LEFT:
            self.rerecord.set()
        elif key in (ESC, ENTER):
            self.stop.set()
        self.ending.set()

    def next_part(self) -> None:
        """An episode or a reset begins: the keys pressed before are spent."""
        self.ending.clear()
        self.rerecord.clear()
        if self.stop.is_set():
            self.ending.set()


class Listener(Protocol):
    """Who shows the session (the CLI's live line)."""

    def update(self, progress: Progress) -> None:
        """A tick of the episode under way."""

    def done(self, episode: Any) -> None:
        """An episode was saved (an ``EpisodeSaved``)."""

    def again(self, number: int) -> None:
        """Episode ``number`` (from 0) was dropped: it is recorded again."""

    def reset(self, number: int, reset_s: float) -> None:
        """The reset before episode ``number`` (from 0) begins."""


@dataclass(frozen=True)
class SessionPlan:
    """What to record: ``episodes`` of ``episode_s`` of ``task``, ``reset_s`` between them."""

    task: str
    episodes: int
    episode_s: float
    reset_s: float


class RecordingSession:
    """Runs ``plan`` on ``recorder`` (``run``); ``status`` is safe from any thread."""

    def __init__(
        self,
        recorder: EpisodeRecorder,
        plan: SessionPlan,
        controls: Controls | None = None,
        listener: Listener | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.recorder, self.plan = recorder, plan
        self.controls = controls if controls is not None else Controls()
        self.listener = listener
        self.saved: list[Any] = []
        self.dropped = 0
        self.rerecorded = 0
        self._clock = clock
        self._lock = threading.Lock()
        self._phase = "starting"
        self._number = 0
        self._since = clock()
        self._progress: Progress | None = None

    def run(self) -> list[Any]:
        """Every episode, each followed by a reset but the last; the saved ones."""
        plan, keys = self.plan, self.controls
        try:
            while self._number < plan.episodes and not keys.stop.is_set():
                keys.next_part()
                self._enter("recording")
                episode = self.recorder.record(
                    plan.task,
                    plan.episode_s,
                    episode=self._number,
                    stop=keys.ending,
                    discard=keys.rerecord,
                    on_tick=self._tick,
                )
                again = keys.rerecord.is_set() and not keys.stop.is_set()
                last = self._progress
                if episode is not None:
                    with self._lock:
                        self.saved.append(episode)
                        self.dropped += last.dropped if last is not None else 0
                    if self.listener is not None:
                        self.listener.done(episode)
                elif again:
                    with self._lock:
                        self.rerecorded += 1
                    if self.listener is not None:
                        self.listener.again(self._number)
                if not again:
                    self._number += 1
                if self._number < plan.episodes and plan.reset_s > 0 and not keys.stop.is_set():
                    keys.next_part()
                    self._enter("resetting")
                    if self.listener is not None:
                        self.listener.reset(self._number, plan.reset_s)
                    keys.ending.wait(plan.reset_s)
        finally:
            self._enter("done")
        return self.saved

    def _enter(self, phase: str) -> None:
        with self._lock:
            self._phase, self._since, self._progress = phase, self._clock(), None

    def _tick(self, progress: Progress) -> None:
        with self._lock:
            self._progress = progress
        if self.listener is not None:
            self.listener.update(progress)

    def status(self) -> dict[str, Any]:
        """Episode i/N (from 1), phase (starting, recording, resetting, done), time in the
        phase and its length, this episode's frames and dropped frames, the saved episodes."""
        with self._lock:
            phase, progress = self._phase, self._progress
            elapsed = progress.elapsed_s if progress is not None else self._clock() - self._since
            length = {"recording": self.plan.episode_s, "resetting": self.plan.reset_s}
            return {
                "phase": phase,
                "episode": min(self._number + 1, self.plan.episodes),
                "episodes": self.plan.episodes,
                "elapsed_s": round(elapsed if phase != "done" else 0.0, 3),
                "duration_s": length.get(phase, 0.0),
                "frames": progress.frames if progress is not None else 0,
                "dropped": progress.dropped if progress is not None else 0,
                "dropped_total": self.dropped,
                "rerecorded": self.rerecorded,
                "saved": [
                    {"episode": e.index, "frames": e.frames, "duration_s": round(e.duration_s, 3)}
                    for e in self.saved
                ],
            }
