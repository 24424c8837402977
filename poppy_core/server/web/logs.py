"""``LogBuffer``: the last log lines of the server kept in memory for the web page, and on
the server's stderr (WARNING and above) when nothing else shows them."""

from __future__ import annotations

import itertools
import logging
import sys
import threading
import unicodedata
from collections import deque
from typing import Any

LOGGERS = ("poppy_core", "poppy_cli", "uvicorn.error")
"""The loggers whose records the page shows (the server's own logging, not a shell)."""
MAX_LINES = 500
STDERR_FORMAT = "%(levelname)s %(name)s: %(message)s"


def printable(text: str) -> str:
    """``text`` with its control characters (terminal escapes) shown as ``\\xNN``, lines kept."""
    return "".join(
        c if c in "\n\t" or unicodedata.category(c) != "Cc" else f"\\x{ord(c):02x}" for c in text
    )


class StderrWarnings(logging.Handler):
    """WARNING and above on the current ``sys.stderr``, unless another handler shows them.

    Python prints a WARNING nobody handles on stderr (``logging.lastResort``), but only while no
    handler at all sees it: the page's ``LogBuffer`` would silence it. This handler stands in for
    that last resort: it writes a record when no handler besides the pages' would, so a lost
    bus is on the server's terminal whether or not logging was configured (``--verbose``
    configures it, and then this one stays quiet).
    """

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.setFormatter(logging.Formatter(STDERR_FORMAT))

    def shows(self, record: logging.LogRecord) -> bool:
        """True when this handler is the one to show ``record``: no other handler of its logger
        or of the loggers above takes it (the pages' buffers do not count), and no other
        ``StderrWarnings`` (another app of this process) comes first."""
        first: StderrWarnings | None = None
        logger: logging.Logger | None = logging.getLogger(record.name)
        while logger is not None:
            for handler in logger.handlers:
                if isinstance(handler, StderrWarnings):
                    first = first or handler
                elif not isinstance(handler, LogBuffer) and record.levelno >= handler.level:
                    return False  # configured logging shows it
            if not logger.propagate:
                break
            logger = logger.parent
        return first is self  # the first one met writes, once

    def emit(self, record: logging.LogRecord) -> None:
        if not self.shows(record):
            return
        try:
            stream = sys.stderr
            if stream is not None:
                stream.write(printable(self.format(record)) + "\n")
                stream.flush()
        except Exception:
            self.handleError(record)


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
        self._stderr = StderrWarnings()

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
        """Listen to the server's loggers (and keep their warnings on stderr)."""
        for name in LOGGERS:
            logging.getLogger(name).addHandler(self)
            logging.getLogger(name).addHandler(self._stderr)

    def detach(self) -> None:
        """Stop listening."""
        for name in LOGGERS:
            logging.getLogger(name).removeHandler(self)
            logging.getLogger(name).removeHandler(self._stderr)
