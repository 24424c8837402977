"""Hostile numbers on the command line: each is one usage line (exit 2) before anything is
allocated, opened or started; none is an "unexpected" error, a crash or a command that runs."""

from __future__ import annotations

import tracemalloc
from typing import Any

import pytest
import typer

from poppy_cli.options import parse_ids
from tests.helpers.cli import run_poppy

HUGE = "99999999999999999999"
ROBOT = ("--sim", "--profile", "ergo-jr")


def _one_usage_line(result: Any, words: str) -> None:
    lines = result.stderr.strip().splitlines()
    assert result.code == 2, result.stderr
    assert len(lines) == 1 and lines[0].startswith("error:"), result.stderr
    assert words in lines[0], lines[0]
    assert "unexpected" not in lines[0]


# (arguments, words of the one line); "URL" is the emulated bus.
TABLE: list[tuple[tuple[str, ...], str]] = [
    (("scan", "--port", "URL", "--ids", f"0-{HUGE}"), f"ID {HUGE} is out of range"),
    (("scan", "--port", "URL", "--ids", "-3"), "is not an ID or a range"),
    (("motor", "get", f"0-{HUGE}", "present_position", "--port", "URL"), "out of range"),
    (("motor", "set-baudrate", "1", HUGE, "--port", "URL"), "'BPS'"),
    (("motor", "set-return-delay", "1", "nan", "--port", "URL"), "'DELAY_US'"),
    (("motor", "set-return-delay", "1", "1e309", "--port", "URL"), "'DELAY_US'"),
    (("motor", "angle-limits", "1", "--port", "URL", "nan", "90"), "'MIN_DEG'"),
    (("motor", "reset", HUGE, "1", "--port", "URL"), "'MOTOR_ID'"),
    (("motor", "reset", "1", "2", "--target-baud", HUGE, "--port", "URL"), "--target-baud"),
    (("robot", "goto", *ROBOT, "--duration", "nan", "m1=10"), "--duration"),
    (("robot", "goto", *ROBOT, "--duration", "1e309", "m1=10"), "--duration"),
    (("robot", "goto", *ROBOT, "m1=1e300"), "finite number of degrees"),
    (("robot", "reach", *ROBOT, "--duration", "1e309", "0.1", "0", "0.1"), "--duration"),
    (("robot", "reach", *ROBOT, "--duration", "nan", "0.1", "0", "0.1"), "--duration"),
    (("robot", "reach", *ROBOT, "1e300", "0", "0.1"), "X Y Z takes 3 finite numbers within"),
    (("robot", "reach", *ROBOT, "0.1", "0", "0.1", "--rpy", "1e20,0,0"), "--rpy takes 3"),
    (("calibrate", *ROBOT, "--check", "--tolerance", "inf"), "--tolerance"),
    (("calibrate", *ROBOT, "--check", "--tolerance", "nan"), "--tolerance"),
    (("teleop", "--rate", "nan"), "--rate"),
    (("teleop", "--ramp", "nan"), "--ramp"),
    (("teleop", "--duration", "1e309"), "--duration"),
    (("serve", "--ws-rate", "nan"), "--ws-rate"),
    (("camera", "snapshot", "-o", "x.png", "--resolution", f"{HUGE}x480"), "the width"),
    (("emulate", "--motors", "XL-320:1", "--delay-ms", "1e309"), "--delay-ms"),
    (("emulate", "--motors", "XL-320:1", "--delay-ms", "nan"), "--delay-ms"),
    (("emulate", "--motors", "XL-320:1", "--latency-ms", "1e309"), "--latency-ms"),
    (("emulate", "--motors", "XL-320:1", "--corrupt", "nan"), "--corrupt"),
    (("emulate", "--motors", "XL-320:1", "--drop", "nan"), "--drop"),
    (("emulate", "--motors", "XL-320:1", "--tcp", "127.0.0.1:" + "9" * 5000), "is not HOST:PORT"),
    (("emulate", "--motors", "XL-320:1", "--tcp", "127.0.0.1:65536"), "is not HOST:PORT"),
]


@pytest.mark.parametrize(("args", "words"), TABLE, ids=[" ".join(a)[:90] for a, _ in TABLE])
def test_a_hostile_number_is_one_usage_line(args: tuple[str, ...], words: str) -> None:
    # Before the fix some of these served forever (emulate, serve) or crashed: pytest-timeout
    # turns a command that runs into a failure, as a subprocess's timeout did (each started
    # Python and the CLI for a refusal, 0.5-1 s of CPU), and a crash is "unexpected" or exit 1.
    url = "socket://127.0.0.1:9"  # never opened: every refusal comes first
    result = run_poppy(*(url if a == "URL" else a for a in args), timeout=60)
    _one_usage_line(result, words)


def test_a_goto_of_1e_300_seconds_is_refused_in_one_line(poppy: Any) -> None:
    result = poppy("robot", "goto", *ROBOT, "--duration", "1e-300", "m1=10", "--json")
    assert result.code != 0  # was "unexpected ZeroDivisionError"
    assert "at least 0.001 s" in result.stderr and "Traceback" not in result.stderr


def test_an_id_range_is_checked_before_it_is_expanded() -> None:
    tracemalloc.start()
    try:
        with pytest.raises(typer.BadParameter, match="ID 2000000 is out of range"):
            parse_ids("0-2000000")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 1 << 20  # expanding it first held two million IDs (over 100 MB)
    assert parse_ids("1-3,11,0-1") == [0, 1, 2, 3, 11]
    with pytest.raises(typer.BadParameter, match="goes backwards"):
        parse_ids("5-1")
