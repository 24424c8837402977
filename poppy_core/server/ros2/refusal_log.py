"""``Refusal`` and ``Refusals``: a ROS 2 command the node turned down, as one typed event.

Every refusal of the node (a message on ``joint_command`` or ``joint_trajectory`` that names a
compliant or unknown motor or holds a value that is not a finite number, a service that said
no) goes through ``Refusals.report``: it is counted, logged on the robot's stderr (a topic's:
one line a second at most, whatever the rate; a service's: each, as each was asked) and
handed to every listener (``listen``), which may publish it where a ROS 2 user looks (/rosout).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

logger = logging.getLogger(__name__)

LOG_EVERY_S = 1.0


@dataclass(frozen=True)
class Refusal:
    """One command turned down, nothing moved.

    Attributes:
        where: the topic or service, fully qualified (``/poppy/joint_command``).
        reason: the one-line reason (what was wrong and what to do).
        kind: ``topic`` (a message dropped) or ``service`` (a request answered ``success: false``).
        stamp: when (``time.time()``).
        error: the refusal's kind as every surface names it (``server.errors.refusal_kind``):
            ``invalid``, ``not_found``, ``conflict``...
    """

    where: str
    reason: str
    kind: str = "topic"
    stamp: float = field(default_factory=time.time)
    error: str = "invalid"


class Refusals:
    """The node's refusals: counted, logged, handed to listeners.

    Args:
        log: the logger the refusals are written to (the node's).
    """

    def __init__(self, log: logging.Logger = logger) -> None:
        self.log = log
        self.count = 0
        self.last: Refusal | None = None
        self._listeners: list[Callable[[Refusal], None]] = []
        self._last_logged = 0.0
        self._lock = threading.Lock()

    def listen(self, listener: Callable[[Refusal], None]) -> None:
        """Call ``listener(refusal)`` for each refusal from now on (in the refusing thread: keep
        it short; its exception is logged, never raised to the command's sender)."""
        with self._lock:
            self._listeners.append(listener)

    def report(self, refusal: Refusal) -> None:
        """Count ``refusal``, log it (one line a second at most), hand it to the listeners."""
        now = time.monotonic()
        with self._lock:
            self.count += 1
            self.last = refusal
            listeners = list(self._listeners)
            loud = refusal.kind == "service" or now - self._last_logged > LOG_EVERY_S
            if loud:
                self._last_logged = now
        if loud:
            self.log.warning("ROS 2: %s refused, nothing moved: %s", refusal.where, refusal.reason)
        for listener in listeners:
            try:
                listener(refusal)
            except Exception:
                logger.exception("ROS 2: a refusal listener failed")
