"""`poppy` run in a pseudo-terminal it owns, as a user's shell would run it.

The command's stdin, stdout and stderr are the pty, and the pty is its controlling terminal: a
``\\x03`` typed on it is Ctrl-C (the terminal sends SIGINT to the command's process group), and
``isatty()`` is true, so the command asks its questions.
"""

from __future__ import annotations

import codecs
import os
import re
import select
import signal
import sys
import time
from collections.abc import Mapping

from tests.helpers.cli import POPPY, command_env
from tests.helpers.processes import start_on_pty
from tests.helpers.waiting import scaled

# setsid, then the pty (stdin) becomes the controlling terminal, then poppy replaces the shim
_SHIM = (
    "import fcntl, os, sys, termios\n"
    "os.setsid()\n"
    "fcntl.ioctl(0, termios.TIOCSCTTY, 0)\n"
    "os.execv(sys.argv[1], sys.argv[1:])\n"
)
CTRL_C = b"\x03"
_STYLE = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


class Terminal:
    """`poppy ARGS...` on a pty of its own; ``shown`` is everything it printed so far."""

    def __init__(self, *args: str, env: Mapping[str, str] | None = None) -> None:
        # a hang is reported with its threads' stacks (``wait``)
        full = dict(os.environ, PYTHONFAULTHANDLER="1", **command_env(env))
        self.proc, self.master, slave = start_on_pty(
            [sys.executable, "-c", _SHIM, *POPPY, *args], full
        )
        os.close(slave)
        self.shown = ""
        # a character split between two reads ("µ" is 2 bytes) is decoded once whole
        self._decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")

    @property
    def text(self) -> str:
        """What it printed, without styles and cursor moves, lines ending in ``\\n``."""
        return _STYLE.sub("", self.shown).replace("\r\n", "\n")

    def read_until(self, text: str, timeout_s: float = 60) -> str:
        """Read what the command prints until ``text`` shows (or it ends, or ``timeout_s``)."""
        deadline = time.monotonic() + scaled(timeout_s)
        while text not in self.shown and time.monotonic() < deadline:
            if not self._read(0.2):
                break
        return self.text

    def type(self, keys: bytes) -> None:
        """Type ``keys`` on the terminal (``CTRL_C``, ``b"y\\n"``)."""
        os.write(self.master, keys)

    def signal(self, signum: signal.Signals) -> None:
        self.proc.send_signal(signum)

    def wait(self, timeout_s: float = 60) -> int:
        """The command's exit code once it ended (what it printed is read on the way).

        Raises:
            AssertionError: it did not end within ``timeout_s``; the message ends with what it
                printed, then the stacks of its threads (faulthandler's dump on SIGABRT).
        """
        deadline = time.monotonic() + scaled(timeout_s)
        while self.proc.poll() is None and time.monotonic() < deadline:
            self._read(0.2)
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGABRT)  # PYTHONFAULTHANDLER: its threads' stacks
            end = time.monotonic() + 10
            while self.proc.poll() is None and time.monotonic() < end:
                self._read(0.2)
            while self._read(0.05):
                pass
            raise AssertionError(
                f"the command did not end within {timeout_s:g} s; it printed, then its "
                f"threads were:\n{self.text[-6000:]}"
            )
        code = self.proc.wait()
        while self._read(0.05):
            pass
        return code

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        os.close(self.master)

    def _read(self, wait_s: float) -> bool:
        """Read what is there within ``wait_s``; False once the terminal is closed."""
        ready, _, _ = select.select([self.master], [], [], wait_s)
        if not ready:
            return True
        try:
            chunk = os.read(self.master, 4096)
        except OSError:  # EIO: the command ended and closed its side
            return False
        self.shown += self._decoder.decode(chunk)
        return bool(chunk)
