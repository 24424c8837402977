"""`poppy primitive list|run` on a virtual Ergo Jr."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.helpers.cli import keyed, no_user_settings

SIM = ("--sim", "--profile", "ergo-jr")


@pytest.fixture(autouse=True)
def xdg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """No user settings or POPPY_* variables leak into the runs."""
    no_user_settings(tmp_path, monkeypatch)


def test_list_json(poppy: Any) -> None:
    result = poppy("primitive", "list", *SIM, "--json")
    assert result.code == 0, result.stderr
    data = keyed(result.json())
    assert {"sinus", "cosinus", "square", "position_watcher", "simple_posture"} <= set(data)
    sinus = data["sinus"]
    assert sinus["class"] == "Sinus" and sinus["state"] == "idle" and sinus["error"] is None
    assert sinus["properties"]["motor_list"] == [f"m{i}" for i in range(1, 7)]
    assert {"amplitude", "frequency", "offset", "phase"} <= set(sinus["properties"])
    assert "duty" in data["square"]["properties"]


def test_list_table(poppy: Any) -> None:
    result = poppy("primitive", "list", *SIM)
    assert result.code == 0, result.stderr
    assert "position_watcher" in result.stdout and "SimplePosture" in result.stdout


def test_run_for_a_duration(poppy: Any) -> None:
    result = poppy(
        "primitive",
        "run",
        "sinus",
        *SIM,
        "--duration",
        "0.5",
        "--set",
        "amplitude=20",
        "--set",
        "motor_list=m1,m2",
        "--json",
    )
    assert result.code == 0, result.stderr
    report = result.json()
    assert report["name"] == "sinus" and report["state"] == "stopped"
    assert report["alive"] is False and report["error"] is None
    assert 0.4 <= report["elapsed_s"] < 3.0
    assert report["properties"]["amplitude"] == 20.0


def test_run_human_output(poppy: Any) -> None:
    result = poppy("primitive", "run", "Cosinus", *SIM, "--duration", "0.3")
    assert result.code == 0, result.stderr
    assert "cosinus: stopped" in result.stdout


def test_an_unknown_motor_is_refused_before_the_primitive_starts(poppy: Any) -> None:
    result = poppy("primitive", "run", "sinus", *SIM, "--set", "motor_list=m9", "--duration", "2")
    assert result.code == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr  # one line, no traceback
    assert "no motor or group 'm9'" in lines[0] and "motors: m1, m2" in lines[0]


def test_an_unknown_motor_is_refused_before_the_primitive_starts_json(poppy: Any) -> None:
    result = poppy(
        "primitive", "run", "square", *SIM, "--set", "motor_list=nope", "--duration", "2", "--json"
    )
    assert result.code == 1
    assert result.stdout == ""
    assert "no motor or group 'nope'" in result.stderr


def test_bad_property_value_is_one_line(poppy: Any) -> None:
    result = poppy("primitive", "run", "sinus", *SIM, "--set", "amplitude=loud")
    assert result.code == 1
    assert "amplitude" in result.stderr and "not a number" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_unknown_primitive(poppy: Any) -> None:
    result = poppy("primitive", "run", "moonwalk", *SIM)
    assert result.code == 1
    assert "no primitive 'moonwalk'" in result.stderr and "sinus" in result.stderr
