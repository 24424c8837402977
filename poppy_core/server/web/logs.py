"""``LogBuffer``: the last log lines of the server kept in memory for the web page."""

from __future__ import annotations

import itertools
import logging
import threading
from collections import deque
from typing import Any

LOGGERS = ("poppy_core", "poppy_cli", "uvicorn.error")
"""The loggers whose records the page shows (the server's own logging, not a shell)."""
MAX_LINES = 500


class LogBuffer(logging.Handler):
    """A handler keeping the last ``max_lines`` records, each numbered (for ``?after=``).

    Args:
        max_lines: records kept; older ones are dropped.
    """

    def __init__(self, max_lines: int = MAX_LINES) -> None:
        super().__init__(logging.NOTSET)
        self._lines: deque[dict[str, Any]] = deque(maxlen=max_lines)
        self._numbers = itertools.count(1)
        self._lock_lines = threading.Lock()
        self.setFormatter(logging.Formatter("%(message)s"))

    def emit(self, record: logging.LogRecord) -> None:
        try:
            message = self.format(record)
        except Exception:  # a bad format string: show what was logged rather than nothing
            message = str(record.msg)
        with self._lock_lines:
            self._lines.append(
                {
                    "n": next(self._numbers),
                    "time": record.created,
                    "level": record.levelname,
                    "logger": record.name,
                    "message": message.splitlines()[0] if message else "",
                }
            )

    def lines(self, after: int = 0, limit: int = 200) -> list[dict[str, Any]]:
        """The records numbered above ``after``, the newest ``limit`` of them, oldest first."""
        with self._lock_lines:
            found = [line for line in self._lines if line["n"] > after]
        return found[-limit:]

    def attach(self) -> None:
        """Listen to the server's loggers."""
        for name in LOGGERS:
            logging.getLogger(name).addHandler(self)

    def detach(self) -> None:
        """Stop listening."""
        for name in LOGGERS:
            logging.getLogger(name).removeHandler(self)

