"""`--remote` forms of `poppy primitive` and `poppy play`: the same jobs on a served robot."""

from __future__ import annotations

import signal
import time
from typing import Any

import typer

from poppy_cli.output import EXIT_FAILURE, EXIT_INTERRUPTED, console, error_line, print_json

REFRESH_S = 0.1


def _error_text(description: dict[str, Any]) -> str | None:
    error = description.get("error")
    if not error:
        return None
    return f"{error['type']}: {error['message']}" if error.get("message") else str(error["type"])


def list_remote(url: str, json_output: bool) -> None:
    """`poppy primitive list --remote URL`."""
    from rich.table import Table

    from poppy_cli.robots import open_remote

    robot = open_remote(url)
    try:
        described = {p.name: p.describe() for p in robot.primitives}
    finally:
        robot.close()
    if json_output:
        print_json([{"name": name, **record} for name, record in described.items()])
        return
    table = Table(title=f"primitives on {url}")
    for column in ("name", "class", "state", "properties", "error"):
        table.add_column(column)
    for name, d in described.items():
        props = "\n".join(f"{k}={v}" for k, v in d["properties"].items())
        table.add_row(name, d["class"], d["state"], props, _error_text(d) or "")
    console.print(table)


def run_remote(
    url: str,
    name: str,
    duration: float | None,
    pairs: list[tuple[str, str]],
    stiff: bool,
    json_output: bool,
) -> None:
    """`poppy primitive run NAME --remote URL`: start it on the server, follow it, stop it."""
    from poppy_cli.robots import open_remote

    robot = open_remote(url)
    interrupted = False
    try:
        primitive = robot.primitive(name)
        for prop, value in pairs:
            primitive.set_property(prop, value)
        if stiff:
            robot.compliant = False
        primitive.start()
        deadline = None if duration is None else time.monotonic() + duration
        try:
            while primitive.is_alive():
                if deadline is not None and time.monotonic() >= deadline:
                    break
                time.sleep(REFRESH_S)
        except KeyboardInterrupt:
            interrupted = True
        primitive.stop()
        report = {"name": name, "interrupted": interrupted, **primitive.describe()}
    finally:
        robot.close()
    if json_output:
        print_json(report)
    else:
        console.print(f"{name}: {report['state']}  {report['elapsed_s']:.1f} s")
    failure = _error_text(report)
    if failure is not None:
        error_line(f"primitive {name} failed on {url}: {failure}")
        raise typer.Exit(EXIT_FAILURE)


def play_remote(
    url: str, name: str, speed: float, reverse: bool, loops: int, json_output: bool
) -> None:
    """`poppy play NAME --remote URL`: play a move of the server's library, ``loops`` times."""
    from poppy_cli.robots import open_remote

    robot = open_remote(url)
    interrupted = False
    signal.signal(signal.SIGTERM, signal.default_int_handler)  # stops it as Ctrl-C does
    try:
        info = robot.moves.get(name)
        started = time.monotonic()
        try:
            for _ in range(loops):
                robot.moves.play(name, speed=speed, backwards=reverse)
                time.sleep(REFRESH_S)
                while name in robot.moves.status().get("playing", []):
                    time.sleep(REFRESH_S)
        except KeyboardInterrupt:
            interrupted = True
            # the signal may have cut a request short, leaving its connection half used: the stop
            # goes on a connection of its own
            robot.close()
            robot = open_remote(url)
            robot.moves.stop(name)
        elapsed = time.monotonic() - started
    finally:
        robot.close()
    report = {
        **info,
        "name": name,
        "url": url,
        "loops": loops,
        "interrupted": interrupted,
        "elapsed_s": round(elapsed, 3),
    }
    if json_output:
        print_json(report)
    else:
        state = "stopped" if interrupted else "played"
        console.print(f"{name}: {state} on {url} in {elapsed:.1f} s")
    if interrupted:
        raise typer.Exit(EXIT_INTERRUPTED)
