"""`poppy serve --http` shows its warnings on its terminal (stderr), not only on the web page.

The page keeps the server's log lines in memory; that handler used to silence Python's last
resort, so a lost bus was reported nowhere a person at the server would see it.
"""

from __future__ import annotations

import logging
import os
import queue
import signal
import sys
import threading
from collections.abc import Iterator

import pytest

from poppy_core.emulator import Endpoint, serve_tcp
from poppy_core.robot import load_profile
from poppy_core.robot.factory import virtual_buses
from poppy_core.server.web.logs import LogBuffer, StderrWarnings, printable
from tests.helpers.cli import command_env
from tests.helpers.processes import reap, start

POPPY = [sys.executable, "-m", "poppy_cli"]
WAIT_S = 60.0


def lines_of(stream: object) -> queue.Queue[str]:
    """The lines of a subprocess's stream, read in a thread as they come."""
    found: queue.Queue[str] = queue.Queue()

    def read() -> None:
        for line in stream:  # type: ignore[attr-defined]
            found.put(line)

    threading.Thread(target=read, daemon=True).start()
    return found


def wait_for_line(lines: queue.Queue[str], text: str, seen: list[str]) -> str:
    """The first line holding ``text`` (every line read goes to ``seen``)."""
    while True:
        try:
            line = lines.get(timeout=WAIT_S)
        except queue.Empty:
            pytest.fail(f"no line with {text!r} within {WAIT_S} s; stderr so far: {seen}")
        seen.append(line)
        if text in line:
            return line


@pytest.fixture
def served_bus() -> Iterator[Endpoint]:
    """An Ergo Jr's bus served on TCP by this process (so that it can be taken away)."""
    (bus,) = virtual_buses(load_profile("ergo-jr")).values()
    server = serve_tcp(bus)
    yield server
    server.stop()


def test_a_lost_bus_is_a_warning_on_the_servers_stderr(served_bus: Endpoint) -> None:
    env = dict(os.environ, **command_env())
    proc = start(
        [
            *POPPY,
            "serve",
            "--http",
            "--http-port",
            "0",
            "--profile",
            "ergo-jr",
            "--port",
            served_bus.url,
            "--no-sensors",
        ],
        env,
    )
    try:
        assert proc.stdout is not None and proc.stderr is not None
        assert proc.stdout.readline().startswith("http://127.0.0.1:")  # serving
        errors = lines_of(proc.stderr)
        seen: list[str] = []
        served_bus.lose(3.0)
        lost = wait_for_line(errors, "lost", seen)
        # the CLI's stderr handler (poppy_cli.output.log_to_stderr): the message, escaped
        assert ": lost socket://" in lost and "offline" in lost, lost
        wait_for_line(errors, "is back", seen)
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=WAIT_S) == 0
        wait_for_line(errors, "stopped", seen)
        assert sum("lost" in line for line in seen) == 1  # once, not once per handler
    finally:
        reap(proc)


def test_configured_logging_takes_the_warnings_and_two_pages_print_them_once(
    capsys: pytest.CaptureFixture[str],
) -> None:
    root = logging.getLogger()
    saved = root.handlers[:]
    root.handlers = []  # as in `poppy serve` without --verbose (pytest's own handlers removed)
    first, second = LogBuffer(), LogBuffer()
    try:
        first.attach()
        second.attach()
        logging.getLogger("poppy_core.robot.sync").warning("bus \x1b]0;title\x07 lost")
        logging.getLogger("poppy_core.robot.sync").info("not shown")
        assert capsys.readouterr().err == (
            "WARNING poppy_core.robot.sync: bus \\x1b]0;title\\x07 lost\n"
        )
        assert [line["message"] for line in first.lines()][-1] == "bus \x1b]0;title\x07 lost"
        configured = logging.StreamHandler(sys.stdout)
        root.addHandler(configured)  # `--verbose`: the configured handler shows it instead
        logging.getLogger("poppy_core.robot.sync").warning("again")
        captured = capsys.readouterr()
        assert captured.err == "" and "again" in captured.out
    finally:
        first.detach()
        second.detach()
        root.handlers = saved
    assert printable("a\x9bb\nc") == "a\\x9bb\nc"
    assert isinstance(first._stderr, StderrWarnings)
