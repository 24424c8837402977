"""`poppy robot ...` and the user settings: virtual (--sim) robots and an emulated bus."""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.cli import keyed, no_user_settings


@pytest.fixture(autouse=True)
def xdg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty user config folder (platformdirs reads XDG_CONFIG_HOME) and no POPPY_* vars."""
    return no_user_settings(tmp_path, monkeypatch)


def write_settings(xdg: Path, text: str) -> Path:
    file = xdg / "poppy" / "config.yaml"
    file.parent.mkdir(parents=True, exist_ok=True)
    file.write_text(text)
    return file


def test_status_sim_json(poppy: Any) -> None:
    result = poppy("robot", "status", "--sim", "--profile", "ergo-jr", "--json")
    assert result.code == 0, result.stderr
    data = keyed(result.json()["motors"])
    assert sorted(data) == [f"m{i}" for i in range(1, 7)]
    for name, state in data.items():
        assert abs(state["position"]) < 2, name
        assert state["online"] is True
        assert state["model"] == "XL-320"
    assert data["m3"]["id"] == 3


def test_status_table(poppy: Any) -> None:
    result = poppy("robot", "status", "--sim", "--profile", "ergo-jr")
    assert result.code == 0, result.stderr
    assert "m6" in result.stdout and "online" in result.stdout
    # why a robot's angle is not the one `poppy motor` shows (m3 at +30 after `motor set -30`)
    note = " ".join(result.stdout.split())
    assert "robot frame: m2 m3 m5 m6 sign flipped (`poppy motor` shows the motor's own)" in note


def test_goto_sim_reaches_target(poppy: Any) -> None:
    result = poppy(
        "robot",
        "goto",
        "--sim",
        "--profile",
        "ergo-jr",
        "m1=30",
        "m2=-10",
        "--duration",
        "0.5",
        "--wait",
        "--json",
    )
    assert result.code == 0, result.stderr
    reached = {m["name"]: m["position"] for m in result.json()["motors"]}
    assert abs(reached["m1"] - 30) <= 2
    assert abs(reached["m2"] + 10) <= 2


def test_goto_unknown_motor_is_one_line(poppy: Any) -> None:
    result = poppy("robot", "goto", "--sim", "--profile", "ergo-jr", "m9=30")
    assert result.code == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1
    assert "m9" in lines[0] and "m1, m2, m3, m4, m5, m6" in lines[0]


def test_goto_bad_number_is_usage_error(poppy: Any) -> None:
    result = poppy("robot", "goto", "--sim", "--profile", "ergo-jr", "m1=abc")
    assert result.code == 2
    assert "not a number" in result.stderr


def test_no_robot_given(poppy: Any) -> None:
    result = poppy("robot", "status", "--sim")
    assert result.code == 2
    assert "--profile" in result.stderr


def test_compliant_off_then_status(poppy: Any, ergo_jr: Any) -> None:
    common = ("--profile", "ergo-jr", "--port", ergo_jr.url)
    before = keyed(poppy("robot", "status", *common, "--json").json()["motors"])
    assert all(state["compliant"] for state in before.values())
    off = poppy("robot", "compliant", "off", "base", *common, "--json")
    assert off.code == 0, off.stderr
    assert off.json() == [{"name": f"m{i}", "compliant": False} for i in (1, 2, 3)]
    after = keyed(poppy("robot", "status", *common, "--json").json()["motors"])
    assert [after[f"m{i}"]["compliant"] for i in range(1, 7)] == [False] * 3 + [True] * 3


def test_compliant_unknown_group(poppy: Any) -> None:
    result = poppy("robot", "compliant", "off", "arm", "--sim", "--profile", "ergo-jr")
    assert result.code == 1
    assert "groups: base, tip" in result.stderr


def test_settings_file_then_env_override(
    poppy: Any, xdg: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    write_settings(xdg, "profile: torso\n")
    from_file = poppy("robot", "status", "--sim", "--json")
    assert from_file.code == 0, from_file.stderr
    assert len(from_file.json()["motors"]) == 13
    monkeypatch.setenv("POPPY_PROFILE", "ergo-jr")
    from_env = poppy("robot", "status", "--sim", "--json")
    assert sorted(keyed(from_env.json()["motors"])) == [f"m{i}" for i in range(1, 7)]
    from_option = poppy("robot", "status", "--sim", "--json", "--profile", "torso")
    assert len(from_option.json()["motors"]) == 13


def test_settings_port_used_for_the_bus(poppy: Any, xdg: Path, ergo_jr: Any) -> None:
    write_settings(xdg, f"profile: ergo-jr\nport: {ergo_jr.url}\n")
    result = poppy("robot", "status", "--json")
    assert result.code == 0, result.stderr
    assert len(result.json()["motors"]) == 6


def test_malformed_settings_file(poppy: Any, xdg: Path) -> None:
    file = write_settings(xdg, "profile: [unclosed\n")
    result = poppy("robot", "status", "--sim")
    assert result.code == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and str(file) in lines[0]
    write_settings(xdg, "colour: blue\n")
    unknown = poppy("robot", "status", "--sim")
    assert unknown.code == 1 and "unknown key 'colour'" in unknown.stderr


def test_slow_return_delay_is_reported_without_a_terminal(poppy: Any, ergo_jr: Any) -> None:
    # `poppy emulate` motors keep the factory return delay (500 µs); no tty: report, don't write.
    result = poppy("robot", "status", "--profile", "ergo-jr", "--port", ergo_jr.url, "--json")
    assert result.code == 0, result.stderr
    assert "return delay" in result.stderr and "set-return-delay" in result.stderr
    delays = poppy(
        "motor",
        "get",
        "1",
        "return_delay_time",
        "--port",
        ergo_jr.url,
        "--baud",
        "1000000",
        "--protocol",
        "2",
    )
    assert delays.stdout.strip() == "500 µs"


def test_return_delay_advice_is_a_command_that_works(poppy: Any, ergo_jr: Any) -> None:
    robot = ("robot", "status", "--profile", "ergo-jr", "--port", ergo_jr.url, "--json")
    warned = poppy(*robot)
    assert warned.code == 0, warned.stderr
    advice = [line for line in warned.stderr.splitlines() if "return delay" in line]
    assert len(advice) == 1 and "fix_return_delay" not in advice[0]  # a Python argument
    command = advice[0].split("`")[1]
    assert command == f"poppy motor set-return-delay 1-6 0 --port {ergo_jr.url}"
    fixed = poppy(*shlex.split(command)[1:])  # an ID list, as `motor get 1-6` takes
    assert fixed.code == 0, fixed.stderr
    again = poppy(*robot)
    assert again.code == 0 and again.stderr == ""
