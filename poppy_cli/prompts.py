"""Questions the CLI asks: only on a terminal, and Ctrl-C or SIGTERM ends them at once.

A command may have replaced the SIGINT/SIGTERM handlers (a recording stops on Ctrl-C): while a
question is asked, Ctrl-C raises ``KeyboardInterrupt`` again (exit 130, see ``poppy_cli.main``)
and SIGTERM ends the command with exit code 143 (128 + SIGTERM), the command's ``with`` blocks
closing what they opened. The command's handlers are put back once the answer is read.

An answer is never waited for in one blocking read (``input()``): Python runs a signal's handler
only between bytecodes, so a signal that lands just before the read starts (or in another
thread) would leave the read blocked until Enter. ``read_line`` and ``read_key`` wait for the
terminal in slices of ``POLL_S``, so a handler runs within that.
"""

from __future__ import annotations

import os
import select
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

import typer

EXIT_TERMINATED = 128 + signal.SIGTERM
POLL_S = 0.1
"""The longest a signal waits for its handler while a prompt waits for the terminal."""


def interactive() -> bool:
    """Whether a question can be asked: stdin is a terminal."""
    return sys.stdin is not None and sys.stdin.isatty()


def _terminated(signum: int, frame: FrameType | None) -> None:
    from poppy_cli.output import error_line

    del signum, frame
    sys.stderr.write("\n")  # the question's line is left as it was
    error_line("terminated")
    raise SystemExit(EXIT_TERMINATED)


@contextmanager
def interruptible() -> Iterator[None]:
    """While in the block: Ctrl-C raises ``KeyboardInterrupt``, SIGTERM exits with 143."""
    if threading.current_thread() is not threading.main_thread():
        yield  # only the main thread may set handlers (and only it gets signals)
        return
    saved = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, _terminated)
    try:
        yield
    finally:
        for signum, handler in saved.items():
            signal.signal(signum, handler)


@contextmanager
def _new_line_when_aborted() -> Iterator[None]:
    """End the question's line when Ctrl-C or the end of input leaves it (the error follows)."""
    try:
        yield
    except typer.Abort:
        sys.stderr.write("\n")
        raise


def wait_readable(fd: int) -> None:
    """Return once ``fd`` can be read, looking every ``POLL_S`` so that signal handlers run."""
    while True:
        ready, _, _ = select.select([fd], [], [], POLL_S)
        if ready:
            return


def read_line() -> str:
    """A line typed on stdin ("" at the end of input), without blocking signal handlers.

    On a terminal in its usual (canonical) mode, stdin is readable once a whole line is there,
    so the read after the wait returns at once.
    """
    wait_readable(sys.stdin.fileno())
    return sys.stdin.readline()


def read_key(fd: int) -> bytes:
    """One byte from ``fd`` (a terminal in cbreak mode; b"" at its end), as ``read_line``."""
    wait_readable(fd)
    return os.read(fd, 1)


def _answer(question: str) -> str:
    """Show ``question`` on stderr and read the answer, as Click's prompts do: Ctrl-C or the
    end of input raise ``typer.Abort`` (Ctrl-C kept as its context, see ``poppy_cli.main``)."""
    try:  # a signal landing while the question is written is one at the question too
        sys.stderr.write(question)
        sys.stderr.flush()
        line = read_line()
        if not line:
            raise EOFError
    except (KeyboardInterrupt, EOFError):
        raise typer.Abort() from None
    return line.rstrip("\r\n")


def confirm(question: str, *, default: bool) -> bool | None:
    """Ask a yes/no ``question`` on stderr; None when stdin is not a terminal (nothing asked).

    Raises:
        typer.Abort: Ctrl-C (exit 130) or the end of input (exit 1) at the question.
        SystemExit: SIGTERM at the question (exit 143).
    """
    if not interactive():
        return None
    shown = f"{question} [{'Y/n' if default else 'y/N'}]: "
    with interruptible(), _new_line_when_aborted():
        while True:
            value = _answer(shown).strip().lower()
            if value in ("y", "yes"):
                return True
            if value in ("n", "no"):
                return False
            if not value:
                return default
            sys.stderr.write("Error: invalid input\n")


def ask(question: str, *, default: str = "") -> str | None:
    """Ask for a line of text on stderr; None when stdin is not a terminal (nothing asked).

    Raises:
        typer.Abort: Ctrl-C (exit 130) or the end of input (exit 1) at the question.
        SystemExit: SIGTERM at the question (exit 143).
    """
    if not interactive():
        return None
    with interruptible(), _new_line_when_aborted():
        return _answer(f"{question}: ") or default


def require_yes(question: str, *, declined: str) -> None:
    """Ask ``question`` (default: no); unless the answer is yes, print ``declined`` and exit 2.

    Without a terminal nothing is asked and nothing is done: the line says to pass --yes.
    """
    from poppy_cli.output import EXIT_USAGE, error_line

    answer = confirm(question, default=False)
    if answer:
        return
    if answer is None:
        error_line(f"{declined}: stdin is not a terminal to ask on; pass --yes")
    else:
        error_line(declined)
    raise typer.Exit(EXIT_USAGE)
