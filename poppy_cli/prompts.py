"""Questions the CLI asks: only on a terminal, and Ctrl-C or SIGTERM ends them at once.

A command may have replaced the SIGINT/SIGTERM handlers (a recording stops on Ctrl-C): while a
question is asked, Ctrl-C raises ``KeyboardInterrupt`` again (exit 130, see ``poppy_cli.main``)
and SIGTERM ends the command with exit code 143 (128 + SIGTERM), the command's ``with`` blocks
closing what they opened. The command's handlers are put back once the answer is read.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

import typer

EXIT_TERMINATED = 128 + signal.SIGTERM


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


def confirm(question: str, *, default: bool) -> bool | None:
    """Ask a yes/no ``question`` on stderr; None when stdin is not a terminal (nothing asked).

    Raises:
        typer.Abort: Ctrl-C (exit 130) or the end of input (exit 1) at the question.
        SystemExit: SIGTERM at the question (exit 143).
    """
    if not interactive():
        return None
    with interruptible(), _new_line_when_aborted():
        return typer.confirm(question, default=default, err=True)


def ask(question: str, *, default: str = "") -> str | None:
    """Ask for a line of text on stderr; None when stdin is not a terminal (nothing asked).

    Raises:
        typer.Abort: Ctrl-C (exit 130) or the end of input (exit 1) at the question.
        SystemExit: SIGTERM at the question (exit 143).
    """
    if not interactive():
        return None
    with interruptible(), _new_line_when_aborted():
        answer: str = typer.prompt(question, default=default, show_default=False, err=True)
    return answer


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
