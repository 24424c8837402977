"""`poppy config set/get/unset/path`: the user's defaults, written atomically, used by commands."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.helpers.cli import run_poppy


@pytest.fixture
def home(tmp_path: Path) -> dict[str, str]:
    """An environment whose user config folder is ``tmp_path`` (no POPPY_PORT/PROFILE)."""
    return {"XDG_CONFIG_HOME": str(tmp_path), "POPPY_PORT": "", "POPPY_PROFILE": ""}


def test_set_get_unset_round_trip(home: dict[str, str], tmp_path: Path) -> None:
    assert run_poppy("config", "set", "profile", "Ergo_Jr", env=home).code == 0
    assert run_poppy("config", "set", "port", "/dev/ttyUSB7", env=home).code == 0
    assert run_poppy("config", "get", "profile", env=home).stdout == "ergo-jr\n"
    assert run_poppy("config", "get", env=home).stdout == "profile=ergo-jr\nport=/dev/ttyUSB7\n"
    assert run_poppy("config", "get", "--json", env=home).json() == {
        "profile": "ergo-jr",
        "port": "/dev/ttyUSB7",
    }
    file = tmp_path / "poppy" / "config.yaml"
    assert file.read_text() == "profile: ergo-jr\nport: /dev/ttyUSB7\n"
    assert run_poppy("config", "unset", "port", env=home).code == 0
    assert file.read_text() == "profile: ergo-jr\n"
    unset = run_poppy("config", "get", "port", env=home)
    assert unset.code == 1 and unset.stdout == ""
    assert "port is not set" in unset.stderr


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (("set", "colour", "red"), "unknown setting 'colour' (settings: profile, port)"),
        (("get", "colour"), "unknown setting 'colour'"),
        (("set", "profile", "ergo-jx"), "unknown profile"),
        (("set", "port", "  "), "port: give a value"),
    ],
)
def test_bad_keys_and_values_are_one_line_and_nothing_written(
    home: dict[str, str], tmp_path: Path, args: tuple[str, ...], said: str
) -> None:
    result = run_poppy("config", *args, env=home)
    assert result.code == 1
    assert said in result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "poppy" / "config.yaml").exists()


def test_path_tells_where_settings_and_profiles_live(home: dict[str, str], tmp_path: Path) -> None:
    shown = run_poppy("config", "path", "--json", env=home).json()
    assert shown["settings"] == str(tmp_path / "poppy" / "config.yaml")
    assert shown["user_profiles"] == str(tmp_path / "poppy" / "profiles")
    installed = run_poppy("config", "path", "ergo_jr", env=home).stdout.strip()
    assert installed.endswith("ergo-jr/profile.yaml")
    # a user profile of the same name hides the installed one: path says which file wins
    mine = tmp_path / "poppy" / "profiles" / "ergo-jr" / "profile.yaml"
    mine.parent.mkdir(parents=True)
    mine.write_text(Path(installed).read_text())
    assert run_poppy("config", "path", "ergo-jr", env=home).stdout.strip() == str(mine)


def test_the_stored_port_is_used_by_bus_commands_and_the_env_wins(home: dict[str, str]) -> None:
    assert run_poppy("config", "set", "port", "/nonexistent/ttyStored", env=home).code == 0
    stored = run_poppy("motor", "get", "1", "present_position", env=home)
    assert stored.code == 1 and "/nonexistent/ttyStored" in stored.stderr
    env = dict(home, POPPY_PORT="/nonexistent/ttyEnv")
    from_env = run_poppy("motor", "get", "1", "present_position", env=env)
    assert "/nonexistent/ttyEnv" in from_env.stderr
    flag = run_poppy(
        "motor", "get", "1", "present_position", "--port", "/nonexistent/ttyFlag", env=env
    )
    assert "/nonexistent/ttyFlag" in flag.stderr


def test_the_stored_profile_is_the_default_robot(home: dict[str, str]) -> None:
    assert run_poppy("config", "set", "profile", "ergo-jr", env=home).code == 0
    shown = run_poppy("robot", "status", "--sim", "--json", env=home)
    assert shown.code == 0, shown.stderr
    assert "m6" in shown.stdout
