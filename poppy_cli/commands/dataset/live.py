"""lerobot-record's keys on a terminal, and the live line of a recording.

Right arrow ends the episode (saved) or the reset under way, left arrow ends the episode and
records it again (the frames are dropped), Esc (or Enter, or Ctrl-C) stops the recording after
saving the episode under way, as ``lerobot-record`` does. The terminal is in cbreak mode while
recording (a key counts without Enter; Ctrl-C still interrupts) and restored after.
"""

from __future__ import annotations

import os
import select
import signal
import sys
import threading
from contextlib import ExitStack
from typing import Any

from poppy_cli.output import err_console
from poppy_core.motion.recording_session import ENTER, ESC, LEFT, RIGHT, Controls

LIVE_EVERY_S = 0.25
POLL_S = 0.1
_SEQUENCES = {b"[C": RIGHT, b"OC": RIGHT, b"[D": LEFT, b"OD": LEFT}


def parse_keys(data: bytes) -> list[str]:
    """The keys in what a terminal sent: arrows (``ESC [ C``), a lone Esc, Enter; others dropped."""
    keys: list[str] = []
    at = 0
    while at < len(data):
        byte = data[at : at + 1]
        if byte in (b"\n", b"\r"):
            keys.append(ENTER)
            at += 1
        elif byte == b"\x1b":
            tail = data[at + 1 : at + 3]
            if tail in _SEQUENCES:
                keys.append(_SEQUENCES[tail])
                at += 3
            elif tail[:1] in (b"[", b"O"):  # another sequence (up arrow, F1...): skip it
                at += 2
                while at < len(data) and not 0x40 <= data[at] <= 0x7E:
                    at += 1
                at += 1
            else:
                keys.append(ESC)
                at += 1
        else:
            at += 1
    return keys


class Keys(Controls):
    """The session's controls (``recording_session.Controls``) pressed by the keys of a
    terminal, and by SIGINT and SIGTERM (stop)."""

    def __init__(self) -> None:
        super().__init__()
        self.on_terminal = False

    def install(self, stack: ExitStack) -> None:
        """SIGINT and SIGTERM stop; on a terminal, the keys are read (until ``stack`` closes)."""

        def interrupted(*_: Any) -> None:
            self.stop.set()
            self.ending.set()

        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, interrupted)
        if sys.stdin is None or not sys.stdin.isatty():
            return
        import termios
        import tty

        fd = sys.stdin.fileno()
        try:
            saved = termios.tcgetattr(fd)
            tty.setcbreak(fd, termios.TCSANOW)
        except termios.error:
            return
        self.on_terminal = True
        closing = threading.Event()
        reader = threading.Thread(
            target=self._read, args=(fd, closing), name="dataset keys", daemon=True
        )
        reader.start()

        def restore() -> None:
            closing.set()
            reader.join(2 * POLL_S + 1.0)
            termios.tcsetattr(fd, termios.TCSADRAIN, saved)

        stack.callback(restore)

    def _read(self, fd: int, closing: threading.Event) -> None:
        try:
            while not closing.is_set():
                ready, _, _ = select.select([fd], [], [], POLL_S)
                if not ready:
                    continue
                data = os.read(fd, 64)
                if not data:
                    return
                if data.endswith(b"\x1b") or data[-2:] in (b"\x1b[", b"\x1bO"):
                    # the rest of an arrow's sequence may come a moment later
                    more, _, _ = select.select([fd], [], [], 0.05)
                    if more:
                        data += os.read(fd, 64)
                for key in parse_keys(data):
                    self.press(key)
        except (OSError, ValueError):
            return


class Live:
    """The live line on stderr (a terminal), a line per episode elsewhere."""

    def __init__(self, episodes: int, episode_s: float, *, show: bool) -> None:
        self.episodes, self.episode_s, self.show = episodes, episode_s, show
        self.dropped = 0
        self._last = -1.0
        self._terminal = show and err_console.is_terminal

    def hint(self, keys: Keys) -> str:
        if keys.on_terminal:
            return "→ ends the episode, ← records it again, Esc stops"
        return "Ctrl-C stops"

    def update(self, progress: Any) -> None:
        self.dropped = progress.dropped
        if not self._terminal or progress.elapsed_s - self._last < LIVE_EVERY_S:
            return
        self._last = progress.elapsed_s
        sys.stderr.write(
            f"\r episode {progress.episode + 1}/{self.episodes}  {progress.elapsed_s:5.1f}/"
            f"{self.episode_s:g} s  {progress.frames} frames  {progress.dropped} dropped   "
        )
        sys.stderr.flush()

    def _line(self, text: str) -> None:
        self._last = -1.0
        if self.show:
            end = "\n" if self._terminal else ""
            err_console.print(f"{end}{text}", highlight=False, markup=False)

    def done(self, episode: Any) -> None:
        self._line(
            f"episode {episode.index} saved: {episode.frames} frames "
            f"({episode.duration_s:.1f} s), {self.dropped} dropped"
        )

    def again(self, number: int) -> None:
        self._line(f"episode {number + 1}/{self.episodes} dropped: recording it again")

    def reset(self, number: int, reset_s: float) -> None:
        if self.show:
            err_console.print(
                f"reset: {reset_s:g} s before episode {number + 1}/{self.episodes} (→ skips it)",
                highlight=False,
                markup=False,
            )
