"""A signal at a question ends the command whichever thread the kernel gives it to.

Python runs a signal's handler in the main thread between bytecodes. A question read by one
blocking ``input()`` never gets there when the signal comes just before the read starts, or goes
to another thread: `poppy teleop` then waited at its return-delay question after Ctrl-C or
SIGTERM until someone pressed Enter (found under load by ``test_prompts_on_a_terminal``). Here
the main thread blocks both signals while a second thread takes them, which makes that case
certain rather than a matter of timing.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from collections.abc import Iterator
from typing import Any

import pytest

from tests.helpers.cli import command_env
from tests.helpers.processes import read_until, start_on_pty
from tests.helpers.waiting import scaled

_SCRIPT = """
import signal, sys, threading, time
import poppy_cli.main as cli_main
from poppy_cli import prompts

threading.Thread(target=time.sleep, args=(3600,), daemon=True).start()  # takes the signals
signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
question = sys.argv[1]
if question == "confirm":
    cli_main.app = lambda **_: print("answer:", prompts.confirm("Go on?", default=True))
else:
    cli_main.app = lambda **_: print("answer:", prompts.ask("Which one?"))
cli_main.main()
"""
SHOWN = {"confirm": "Go on? [Y/n]: ", "ask": "Which one?: "}
_STYLE = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


@pytest.fixture
def started() -> Iterator[list[tuple[Any, int]]]:
    procs: list[tuple[Any, int]] = []
    yield procs
    for proc, master in procs:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        os.close(master)


def _rest(master: int, proc: Any) -> str:
    """What the command prints until it ends (or 30 s), without styles."""
    return _STYLE.sub("", read_until(master, None, timeout_s=30, proc=proc))


def _asking(started: list[tuple[Any, int]], question: str) -> tuple[Any, int]:
    env = dict(os.environ, **command_env())
    proc, master, slave = start_on_pty([sys.executable, "-c", _SCRIPT, question], env)
    os.close(slave)
    started.append((proc, master))
    shown = read_until(master, SHOWN[question], proc=proc)
    assert SHOWN[question] in shown, shown
    return proc, master


@pytest.mark.parametrize("question", ["confirm", "ask"])
@pytest.mark.parametrize(
    ("signum", "code", "line"),
    [(signal.SIGINT, 130, "error: interrupted"), (signal.SIGTERM, 143, "error: terminated")],
)
def test_a_signal_taken_by_another_thread_ends_the_question(
    started: list[tuple[Any, int]], question: str, signum: int, code: int, line: str
) -> None:
    proc, master = _asking(started, question)
    proc.send_signal(signum)
    shown = _rest(master, proc)
    try:
        ended = proc.wait(timeout=scaled(30))
    except subprocess.TimeoutExpired:
        raise AssertionError(f"still at the question 60 s after the signal: {shown!r}") from None
    assert ended == code, shown
    assert line in shown and "Traceback" not in shown and "answer:" not in shown


@pytest.mark.parametrize(
    ("typed", "answer"),
    [(b"\n", "True"), (b"n\n", "False"), (b"maybe\nyes\n", "True")],
)
def test_confirm_reads_the_answer_typed(
    started: list[tuple[Any, int]], typed: bytes, answer: str
) -> None:
    proc, master = _asking(started, "confirm")
    os.write(master, typed)
    shown = _rest(master, proc)
    assert proc.wait(timeout=scaled(30)) == 0, shown
    assert f"answer: {answer}" in shown
    if typed.startswith(b"maybe"):
        assert "Error: invalid input" in shown


def test_ask_reads_the_line_typed(started: list[tuple[Any, int]]) -> None:
    proc, master = _asking(started, "ask")
    os.write(master, b"the left arm\n")
    shown = _rest(master, proc)
    assert proc.wait(timeout=scaled(30)) == 0, shown
    assert "answer: the left arm" in shown


def test_the_end_of_input_at_a_question_aborts(started: list[tuple[Any, int]]) -> None:
    proc, master = _asking(started, "confirm")
    os.write(master, b"\x04")  # Ctrl-D on an empty line: the end of input
    shown = _rest(master, proc)
    assert proc.wait(timeout=scaled(30)) == 1, shown
    assert "error: aborted" in shown and "answer:" not in shown
