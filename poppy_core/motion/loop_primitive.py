"""``LoopPrimitive``: a primitive calling ``update()`` at a fixed rate, drift-free."""

from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING

from poppy_core import checks
from poppy_core.motion.primitive import Primitive
from poppy_core.schedule import RateMeter, Ticker

if TYPE_CHECKING:
    from poppy_core.robot import Robot


class LoopPrimitive(Primitive):
    """A primitive calling ``update()`` at ``freq`` Hz, drift-free, until stopped.

    Its updates fall at ``t0 + k * period``: ``t0`` is when ``run`` begins, or the
    ``shared_start`` of a start through a gate with a start time (a fleet's robots then update
    on one grid; a thread that woke late updates at once, with the value due now, and goes on
    on the grid). After a pause it goes on on its grid (the periods paused are skipped).

    Args:
        robot: the robot to act on.
        freq: update rate in Hz.
    """

    def __init__(self, robot: Robot, freq: float) -> None:
        super().__init__(robot)
        self.update_freq = freq
        self._meter = RateMeter(window=10)
        self._recent: deque[float] = deque(maxlen=10)
        self._loop_last: float | None = None

    @property
    def update_freq(self) -> float:
        """Updates per second (takes effect at the next (re)start)."""
        return self._freq

    @update_freq.setter
    def update_freq(self, value: float) -> None:
        # a floor on the period (no spinning) and a ceiling (no wait too long for a timer)
        self._freq = checks.rate(value, "update_freq")

    @property
    def period_s(self) -> float:
        """Seconds between two updates."""
        return 1.0 / self._freq

    @property
    def period(self) -> float:
        """pypot's name for ``period_s``; setting it sets ``update_freq`` (at the next start)."""
        return self.period_s

    @period.setter
    def period(self, value: float) -> None:
        self.update_freq = 1.0 / checks.period(value, "period")

    @property
    def update_rate_hz(self) -> float:
        """Measured update rate over the last updates (0 until two ran)."""
        return self._meter.rate_hz

    @property
    def recent_update_frequencies(self) -> list[float]:
        """The last (up to 10) instantaneous update rates, most recent first."""
        return list(reversed(self._recent))

    def update(self) -> None:
        """One step of the behaviour, called at ``update_freq``."""

    def run(self) -> None:
        """Call ``update()`` on a drift-free schedule; late updates skip missed periods.

        An ``update`` that raises ends the primitive (pypot's story: the primitive's ``error``,
        ``wait_to_stop`` raises ``PrimitiveError``), so the ticker retries nothing.
        """
        self._meter = RateMeter(window=10)
        self._recent.clear()
        self._loop_last = None
        ticker = Ticker(self.name, self.update_freq, self._loop_tick, retry=())
        ticker.run(self._stop_event, self.shared_start)

    def _loop_tick(self, now: float) -> None:
        if self.should_pause():
            self.wait_to_resume()
            self._loop_last = None
            return
        self.update()
        self._meter.tick(now)
        if self._loop_last is not None and now > self._loop_last:
            self._recent.append(1.0 / (now - self._loop_last))
        self._loop_last = now
