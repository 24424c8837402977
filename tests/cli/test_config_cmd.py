"""`poppy config ...`: validate, convert, show, list, generate (subprocess runs)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.cli import no_user_settings

DATA = Path(__file__).resolve().parents[1] / "robot" / "data"
ERGO_JSON = DATA / "poppy_ergo_jr.json"


@pytest.fixture(autouse=True)
def _isolated_settings(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    no_user_settings(tmp_path, monkeypatch)


def test_validate_ok(poppy: Any) -> None:
    result = poppy("config", "validate", str(ERGO_JSON))
    assert result.code == 0, result.stderr
    assert "ok" in result.stdout
    assert "6 motors" in result.stdout and "1 controller," in result.stdout
    assert "2 groups" in result.stdout


def test_validate_duplicate_id_is_one_line_naming_the_field(poppy: Any, tmp_path: Path) -> None:
    data = json.loads(ERGO_JSON.read_text())
    data["motors"]["m2"]["id"] = data["motors"]["m1"]["id"]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    result = poppy("config", "validate", str(bad))
    assert result.code == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1
    assert "motors.m" in lines[0] and ".id" in lines[0]
    assert "Traceback" not in result.stderr


def test_convert_round_trip(poppy: Any, tmp_path: Path) -> None:
    yaml_file = tmp_path / "robot.yaml"
    json_file = tmp_path / "back.json"
    assert poppy("config", "convert", str(ERGO_JSON), str(yaml_file)).code == 0
    assert not yaml_file.read_text().lstrip().startswith("{")
    assert poppy("config", "convert", str(yaml_file), str(json_file)).code == 0
    original = poppy("config", "show", str(ERGO_JSON), "--json").json()
    back = poppy("config", "show", str(json_file), "--json").json()
    assert back == original
    assert (
        json.loads(json_file.read_text())["motors"] == json.loads(ERGO_JSON.read_text())["motors"]
    )


def test_convert_refuses_unknown_extension(poppy: Any, tmp_path: Path) -> None:
    result = poppy("config", "convert", str(ERGO_JSON), str(tmp_path / "robot.txt"))
    assert result.code == 2
    assert "extension" in result.stderr


def test_show_json_profile(poppy: Any) -> None:
    result = poppy("config", "show", "ergo-jr", "--json")
    assert result.code == 0, result.stderr
    data = result.json()
    assert sorted(data["motors"]) == [f"m{i}" for i in range(1, 7)]
    assert data["motorgroups"]["base"] == ["m1", "m2", "m3"]


def test_show_table_and_yaml(poppy: Any) -> None:
    table = poppy("config", "show", "ergo-jr")
    assert table.code == 0
    assert "XL-320" in table.stdout and "indirect" in table.stdout
    assert "group base: m1, m2, m3" in table.stdout
    yaml_text = poppy("config", "show", "ergo-jr", "--yaml").stdout
    assert "motors:" in yaml_text and "m6:" in yaml_text


def test_show_unknown_profile_is_one_line(poppy: Any) -> None:
    result = poppy("config", "show", "no-such-robot")
    assert result.code == 1
    assert len(result.stderr.strip().splitlines()) == 1


def test_list_marks_user_profiles(poppy: Any, tmp_path: Path) -> None:
    user_dir = tmp_path / "xdg" / "poppy" / "profiles" / "my-arm"
    user_dir.mkdir(parents=True)
    (user_dir / "profile.yaml").write_text("profile:\n  name: my-arm\n  description: mine\n")
    data = poppy("config", "list", "--json").json()
    by_name = {p["name"]: p for p in data}
    assert by_name["ergo-jr"]["user"] is False
    assert by_name["my-arm"]["user"] is True
    table = poppy("config", "list").stdout
    assert "user" in table and "installed" in table


def test_generate_from_emulator_then_validate(poppy: Any, ergo_jr: Any, tmp_path: Path) -> None:
    out = tmp_path / "found.yaml"
    args = ("config", "generate", "--port", ergo_jr.url, "--baud", "1000000")
    result = poppy(*args, "--protocol", "2", "--prefix", "joint", "-o", str(out))
    assert result.code == 0, result.stderr
    validated = poppy("config", "validate", str(out))
    assert validated.code == 0, validated.stderr
    assert "6 motors, 1 controller," in validated.stdout
    data = poppy("config", "show", str(out), "--json").json()
    assert sorted(data["motors"]) == [f"joint{i}" for i in range(1, 7)]
    assert data["motors"]["joint1"]["type"] == "XL-320"
    low, high = data["motors"]["joint1"]["angle_limit"]
    assert low < high
    controller = next(iter(data["controllers"].values()))
    assert controller["port"] == ergo_jr.url and controller["protocol"] == 2
    again = poppy(*args, "--protocol", "2", "-o", str(out))
    assert again.code == 1
    assert "--force" in again.stderr


def _validate_refused(poppy: Any, tmp_path: Path, data: Any) -> tuple[Path, list[str]]:
    """``poppy config validate`` of ``data`` saved as bad.json: refused in three lines, no trace."""
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    result = poppy("config", "validate", str(bad))
    assert result.code == 1
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 3, result.stderr
    return bad, lines


def test_validate_lists_every_problem_one_line_each(poppy: Any, tmp_path: Path) -> None:
    data = json.loads(ERGO_JSON.read_text())
    data["motors"]["m2"]["id"] = data["motors"]["m1"]["id"]
    data["motors"]["m3"]["angle_limit"] = [90, -90]
    data["motors"]["m4"]["type"] = "XL-3200"
    bad, lines = _validate_refused(poppy, tmp_path, data)
    assert all(line.startswith(f"error: {bad}: motors.m") for line in lines)
    assert any("motors.m2.id = 1: duplicate ID" in line for line in lines)
    assert any("motors.m3.angle_limit = [90, -90]: min must be below max" in line for line in lines)
    assert any("motors.m4.type" in line for line in lines)


def test_validate_lists_chains_and_sensors_problems_one_line_each(
    poppy: Any, tmp_path: Path
) -> None:
    data = json.loads(ERGO_JSON.read_text())
    data["kinematics"] = {"model": "", "chains": {"arm": {"motors": ["m1"]}}}
    data["sensors"] = {
        "camera": {"type": "OpenCVCamera", "resolution": [640]},
        "imu": {"type": "ForceSensor"},
    }
    bad, lines = _validate_refused(poppy, tmp_path, data)
    assert any("sensors.camera.resolution = [640]: must be [width, " in line for line in lines)
    assert any("sensors.imu.type" in line and "not supported yet" in line for line in lines)
    assert any('kinematics.model = "": must not be empty' in line for line in lines)
    assert all(line.startswith(f"error: {bad}: ") for line in lines)
