"""CLI test helpers: `poppy` run in this process (fast) or as a subprocess, and what it printed.

``run_poppy`` runs ``poppy_cli.main.main`` in the test process with the streams, arguments and
environment a subprocess would get: starting a Python interpreter and importing the CLI costs
one to two seconds on a loaded machine, and the CLI tests run a few hundred commands. Tests
whose subject is the process itself (Ctrl-C, signals, what an import pulls in, a program
serving until stopped) start ``POPPY`` with ``subprocess`` (``run_poppy_process``).

Typer builds Click's command tree from ``poppy_cli.main.app`` at each call of ``app`` (0.1 s of
CPU: ~400 signatures read); a process calls it once. The tree depends on no argument, variable
or stream, so ``run_poppy`` builds it once a test process (``built_tree``) and reuses it.
"""

from __future__ import annotations

import io
import json
import logging
import os
import signal
import subprocess
import sys
import tempfile
import traceback
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import pytest

from poppy_core.remote.zenoh_fleet import DEFAULT_TIMEOUT_S as FLEET_TIMEOUT_S
from poppy_core.remote.zenoh_fleet import TIMEOUT_ENV as FLEET_TIMEOUT_ENV
from tests.helpers.waiting import reply_floor_env, scaled

POPPY = [sys.executable, "-m", "poppy_cli"]
# What a `poppy` subprocess of the tests sees: a wide terminal, no colours, and a first-reply
# floor for motors that are an emulator on a busy machine (scaled by the load when this module is
# imported; `command_env` measures it again for each command).
WIDTH = 200
ENV = {"COLUMNS": str(WIDTH), "NO_COLOR": "1", **reply_floor_env()}


def command_env(env: Mapping[str, str] | None = None) -> dict[str, str]:
    """``ENV`` with the reply floor and the fleet's time-out (its robots are threads or
    processes of the test, late on a busy machine) scaled by the load measured now, then
    ``env``."""
    fleet = {FLEET_TIMEOUT_ENV: f"{scaled(FLEET_TIMEOUT_S):.3f}"}
    return {**ENV, **reply_floor_env(), **fleet, **(env or {})}


@dataclass
class Result:
    """What a `poppy` run printed and returned."""

    code: int
    stdout: str
    stderr: str

    def json(self) -> Any:
        return json.loads(self.stdout)


def keyed(records: list[dict[str, Any]], key: str = "name") -> dict[Any, dict[str, Any]]:
    """A `--json` list of records (docs/cli.md: JSON output) by their ``key``, for lookups."""
    return {record[key]: record for record in records}


def run_poppy_process(
    *args: str, timeout: float = 60, input: str | None = None, env: Mapping[str, str] | None = None
) -> Result:
    """Run `poppy ARGS...` as a subprocess (``env``: added to its environment)."""
    full = dict(os.environ, **command_env(env))
    proc = subprocess.run(
        [*POPPY, *args],
        capture_output=True,
        text=True,
        timeout=scaled(timeout),
        env=full,
        input=input,
    )
    return Result(proc.returncode, proc.stdout, proc.stderr)


def run_poppy(
    *args: str,
    timeout: float = 60,
    input: str | io.TextIOBase | None = None,
    env: Mapping[str, str] | None = None,
) -> Result:
    """Run `poppy ARGS...` in this process (``env``: added to its environment; ``input``: the
    text of stdin, or a stream whose reads the test drives, e.g. to act between prompts).

    ``timeout`` is kept for the callers' sake: pytest-timeout stops a command that hangs.
    """
    del timeout
    from poppy_cli.main import main

    stdout, stderr = _stream(), _stream()
    with _as_a_process(args, stdout, stderr, input, command_env(env)):
        try:
            main()
            code = 0
        except SystemExit as exc:
            code = _exit_code(exc.code, stderr)
        except Exception:  # what Python prints for an uncaught exception (`--debug`)
            traceback.print_exc(file=stderr)
            code = 1
    return Result(code, stdout.getvalue(), stderr.getvalue())


@cache
def built_tree() -> Any:
    """`poppy`'s Click command tree as ``app`` builds it at each call; built once, never changed
    (``tests.helpers.cli_tree.root`` builds one of its own to change)."""
    import typer.main

    import poppy_cli.main as cli_main

    app = cli_main.app
    return typer.main.get_command(app.app if isinstance(app, _Prebuilt) else app)


class _Prebuilt:
    """Stands for ``poppy_cli.main.app`` during ``run_poppy``: calls ``built_tree`` as ``app``
    calls the tree it builds (Typer's exception hook and notes only print uncaught exceptions
    prettily, which `poppy` turns off)."""

    def __init__(self, app: Any) -> None:
        self.app = app

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return built_tree()(*args, **kwargs)


def _stream() -> io.TextIOWrapper:
    """A text stream like a pipe's (with a ``buffer``), readable after the command."""
    return _Captured(io.BytesIO(), encoding="utf-8", newline="", write_through=True)


class _Captured(io.TextIOWrapper):
    def getvalue(self) -> str:
        self.flush()
        buffer = self.buffer
        assert isinstance(buffer, io.BytesIO)
        return buffer.getvalue().decode("utf-8")


def _exit_code(code: object, stderr: io.TextIOBase) -> int:
    """The exit status Python gives ``sys.exit(code)``."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=stderr)
    return 1


@contextmanager
def _as_a_process(
    args: tuple[str, ...],
    stdout: io.TextIOBase,
    stderr: io.TextIOBase,
    input: str | io.TextIOBase | None,
    env: Mapping[str, str],
) -> Iterator[None]:
    """Give the command what a fresh `poppy` process would have, and take it back after."""
    import typer

    import poppy_cli.main as cli_main
    from poppy_cli import state
    from poppy_cli.output import console, err_console

    saved_streams = sys.stdin, sys.stdout, sys.stderr
    saved_argv = sys.argv
    saved_env = {name: os.environ.get(name) for name in env}
    root = logging.getLogger()
    saved_logging = root.handlers[:], root.level
    handlers = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    consoles = [(c, c._width, c._color_system, c.quiet) for c in (console, err_console)]
    saved_app = cli_main.app
    if isinstance(saved_app, typer.Typer):  # not a stand-in of the test's
        cli_main.app = _Prebuilt(saved_app)  # type: ignore[assignment]
    saved_tempdir = tempfile.tempdir
    tempfile.tempdir = None  # found again from TMPDIR, as a new process does
    sys.stdin = input if isinstance(input, io.TextIOBase) else io.StringIO(input or "")
    sys.stdout, sys.stderr = stdout, stderr  # type: ignore[assignment]
    sys.argv = ["poppy", *args]
    os.environ.update(env)
    root.handlers = []  # `--debug` / `-v` configure logging as in a new process
    for c, _, _, _ in consoles:
        c.width = WIDTH
        c._color_system = None
    try:
        yield
    finally:
        cli_main.app = saved_app
        tempfile.tempdir = saved_tempdir
        for c, width, colors, quiet in consoles:
            c._width, c._color_system, c.quiet = width, colors, quiet
        root.handlers, _ = saved_logging
        root.setLevel(saved_logging[1])
        for name, value in saved_env.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
        sys.argv = saved_argv
        sys.stdin, sys.stdout, sys.stderr = saved_streams
        for signum, handler in handlers.items():
            signal.signal(signum, handler)
        state.debug = False


def no_user_settings(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, *, moves: bool = False
) -> Path:
    """Keep the user's settings out of a test's runs: an empty config folder (platformdirs reads
    ``XDG_CONFIG_HOME``: ``tmp_path/xdg``), no ``POPPY_PROFILE``/``POPPY_PORT``; with ``moves``,
    an empty move library too (``POPPY_MOVES_DIR``: ``tmp_path/moves``).

    Returns:
        The move library with ``moves``, else the config folder.
    """
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "xdg"))
    monkeypatch.delenv("POPPY_PROFILE", raising=False)
    monkeypatch.delenv("POPPY_PORT", raising=False)
    if moves:
        monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "moves"))
        return tmp_path / "moves"
    return tmp_path / "xdg"
