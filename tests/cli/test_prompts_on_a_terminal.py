"""Questions on a terminal: Ctrl-C and SIGTERM end them at once, a yes does what it says.

`poppy emulate --profile ergo-jr` serves the XL-320's factory return delay (500 µs), so a
command building that robot on a terminal asks whether to set it to 0 µs.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.terminal import CTRL_C, Terminal

QUESTION = "Set their return delay to 0 µs (EEPROM)? [Y/n]"


@pytest.fixture
def emulated(emulator_factory: Any) -> str:
    """The port of an emulated Ergo Jr whose motors come as from the factory."""
    url: str = emulator_factory("--profile", "ergo-jr").url
    return url


@pytest.fixture
def terminals() -> Iterator[list[Terminal]]:
    opened: list[Terminal] = []
    yield opened
    for terminal in opened:
        terminal.close()


# A loaded machine may starve the emulator process: a start-up ping unanswered is no verdict
# (the reads and writes after it wait for late replies: poppy_core.robot.startup).
LATE = ("missing motors",)


def _late(shown: str) -> bool:
    return any(sign in shown for sign in LATE)


ATTEMPTS = 3


def _run(terminals: list[Terminal], *args: str, env: dict[str, str] | None = None) -> Terminal:
    terminal = Terminal(*args, env=env)
    terminals.append(terminal)
    return terminal


def _asked(terminals: list[Terminal], *args: str, env: dict[str, str] | None = None) -> Terminal:
    """`poppy ARGS` on a terminal, once it asks the question (started again while the
    emulator answered too late to be found)."""
    for _ in range(ATTEMPTS):
        terminal = _run(terminals, *args, env=env)
        shown = terminal.read_until(QUESTION)
        if QUESTION in shown or not _late(shown):
            break
    assert QUESTION in terminal.text, terminal.text[-2000:]
    return terminal


def _ended(terminals: list[Terminal], *args: str) -> tuple[int, Terminal]:
    """`poppy ARGS` on a terminal, run to its end (started again as in ``_asked``)."""
    for _ in range(ATTEMPTS):
        terminal = _run(terminals, *args)
        code = terminal.wait()
        if not _late(terminal.text):
            break
    return code, terminal


def _teleop(port: str) -> tuple[str, ...]:
    return (
        "teleop",
        "--leader",
        "ergo-jr",
        "--leader-port",
        port,
        "--follower",
        "ergo-jr",
        "--follower-sim",
        "ideal",
    )


@pytest.mark.parametrize(
    ("stop", "code", "line"),
    [
        ("ctrl-c", 130, "interrupted"),
        ("sigint", 130, "interrupted"),
        ("sigterm", 143, "terminated"),
    ],
)
def test_teleop_question_ends_on_ctrl_c_and_sigterm(
    emulated: str, terminals: list[Terminal], stop: str, code: int, line: str
) -> None:
    terminal = _asked(terminals, *_teleop(emulated))
    if stop == "ctrl-c":
        terminal.type(CTRL_C)
    else:
        terminal.signal(signal.SIGINT if stop == "sigint" else signal.SIGTERM)
    assert terminal.wait() == code, terminal.text[-2000:]
    tail = terminal.text.split(QUESTION, 1)[1]
    assert f"error: {line}" in tail and "Traceback" not in tail
    assert "teleoperating" not in tail  # nothing started


def test_record_ctrl_c_at_the_question_saves_nothing(
    emulated: str, terminals: list[Terminal], tmp_path: Path
) -> None:
    library = tmp_path / "moves"
    terminal = _asked(
        terminals,
        "record",
        "wave",
        "--profile",
        "ergo-jr",
        "--port",
        emulated,
        "--duration",
        "5",
        env={"POPPY_MOVES_DIR": str(library)},
    )
    terminal.type(CTRL_C)
    assert terminal.wait() == 130, terminal.text[-2000:]
    assert "recorded" not in terminal.text and "Traceback" not in terminal.text
    assert list(tmp_path.rglob("*.move")) == []


def test_yes_on_stiff_motors_sets_the_delay_for_good(
    emulated: str, terminals: list[Terminal], poppy: Any
) -> None:
    port = ("--port", emulated)
    assert poppy("motor", "torque", "1-6", "on", *port).code == 0  # EEPROM locked
    terminal = _asked(terminals, "robot", "status", "--profile", "ergo-jr", *port)
    terminal.type(b"y\n")
    assert terminal.wait() == 0, terminal.text[-2000:]
    answered = terminal.text.split(QUESTION, 1)[1]
    assert "could not" not in answered and "warning" not in answered, answered
    delays = poppy("motor", "get", "1-6", "return_delay_time", "torque_enable", "--json", *port)
    assert [row["return_delay_time"] for row in delays.json()] == [0] * 6
    assert [row["torque_enable"] for row in delays.json()] == [True] * 6  # still stiff
    code, again = _ended(terminals, "robot", "status", "--profile", "ergo-jr", *port)
    assert code == 0, again.text[-2000:]
    assert "return delay" not in again.text and "warning" not in again.text
