"""`poppy robot reach` and `poppy robot where` on virtual robots."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.cli import keyed, no_user_settings


@pytest.fixture(autouse=True)
def xdg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty user config folder and no POPPY_* variables."""
    return no_user_settings(tmp_path, monkeypatch)


def test_where_json_lists_every_chain(poppy: Any) -> None:
    result = poppy("robot", "where", "--sim", "--profile", "torso", "--json")
    assert result.code == 0, result.stderr
    data = keyed(result.json())
    assert sorted(data) == ["l_arm_chain", "r_arm_chain"]
    left = data["l_arm_chain"]
    assert len(left["position"]) == 3 and len(left["orientation"]) == 3
    assert {"l_elbow_y", "abs_z"} <= set(keyed(left["motors"]))


def test_where_table(poppy: Any) -> None:
    result = poppy("robot", "where", "--sim", "--profile", "ergo-jr")
    assert result.code == 0, result.stderr
    assert "z (mm)" in result.stdout and "│    156 │" in result.stdout  # the tip's z at rest, in mm


def test_reach_with_negative_coordinates(poppy: Any) -> None:
    result = poppy(
        "robot",
        "reach",
        "--sim",
        "--profile",
        "ergo-jr",
        "0.1",
        "-0.1",
        "0.12",
        "--duration",
        "0.5",
        "--json",
    )
    assert result.code == 0, result.stderr
    data = result.json()
    assert data["chain"] == "chain" and data["waited"] is True
    assert data["error_m"] < 0.003
    assert math.dist(data["position"], [0.1, -0.1, 0.12]) < 0.003
    assert set(keyed(data["motors"])) == {f"m{i}" for i in range(1, 7)}


def test_reach_linear_with_orientation(poppy: Any) -> None:
    result = poppy(
        "robot",
        "reach",
        "--sim",
        "--profile",
        "ergo-jr",
        "0.05,-0.15,0.1",
        "--orientation",
        "0,0,1",
        "--linear",
        "--duration",
        "0.5",
    )
    assert result.code == 0, result.stderr
    assert "arm: at (" in result.stdout and "mm from" in result.stdout


def test_reach_out_of_reach_is_one_line(poppy: Any) -> None:
    result = poppy("robot", "reach", "--sim", "--profile", "ergo-jr", "0", "0", "0.6")
    assert result.code == 1
    assert "nearest point it reaches" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["0.1", "0.1"], "X Y Z takes 3"),
        (["0.1", "x", "0.1"], "X Y Z takes 3 numbers"),
        (["0.1", "0", "0.1", "--orientation", "1,2"], "--orientation takes 3"),
        (["0.1", "0", "0.1", "--orientation", "0,0,1", "--rpy", "0,0,0"], "not both"),
    ],
)
def test_reach_usage_errors(poppy: Any, args: list[str], message: str) -> None:
    result = poppy("robot", "reach", "--sim", "--profile", "ergo-jr", *args)
    assert result.code == 2
    assert message in result.stderr


def test_unknown_chain_names_the_chains(poppy: Any) -> None:
    result = poppy(
        "robot", "reach", "--sim", "--profile", "ergo-jr", "--chain", "leg", "0.1", "0", "0.1"
    )
    assert result.code == 1
    assert "no chain 'leg' (chains: arm)" in result.stderr


def test_robot_without_chains_says_how_to_add_them(poppy: Any, tmp_path: Path) -> None:
    from poppy_core.robot import RobotConfig, dump_config, load_profile

    config = load_profile("ergo-jr").to_dict()
    config["profile"] = {"name": "my-arm", "kind": "my-arm"}
    config.pop("kinematics")
    path = tmp_path / "my-arm.yaml"
    dump_config(RobotConfig.from_dict(config), path)
    result = poppy("robot", "where", "--sim", "--config", str(path))
    assert result.code == 1
    assert "no kinematic chain" in result.stderr and "kinematics" in result.stderr


def test_the_ergo_jr_chain_is_shown_as_arm_and_keeps_its_pypot_name(poppy: Any) -> None:
    table = poppy("robot", "where", "--sim", "--profile", "ergo-jr")
    assert table.code == 0, table.stderr
    row = next(line for line in table.stdout.splitlines() if "156" in line)
    assert row.split("│")[1].strip() == "arm"
    [tip] = poppy("robot", "where", "--sim", "--profile", "ergo-jr", "--json").json()
    assert tip["name"] == "chain" and tip["label"] == "arm"  # robot.chain, as pypot names it
    for name in ("arm", "chain"):
        moved = poppy(
            "robot",
            "reach",
            "--sim",
            "--profile",
            "ergo-jr",
            "--chain",
            name,
            "0.1",
            "0",
            "0.12",
            "--duration",
            "0.2",
        )
        assert moved.code == 0, moved.stderr
        assert moved.stdout.startswith("arm: at (100, ")
    unknown = poppy(
        "robot", "reach", "--sim", "--profile", "ergo-jr", "--chain", "leg", "0.1", "0", "0.1"
    )
    assert unknown.code == 1 and "(chains: arm)" in unknown.stderr
    far = poppy("robot", "reach", "--sim", "--profile", "ergo-jr", "1", "0", "0.1")
    assert far.code == 1 and "chain 'arm' cannot reach" in far.stderr, far.stderr


def test_a_chain_label_must_be_a_name() -> None:
    from pydantic import ValidationError

    from poppy_core.motion.chains import kinematics_spec
    from poppy_core.robot.config_sections import KinematicsSection

    section: dict[str, Any] = {
        "model": "x.urdf",
        "chains": {"chain": {"motors": ["m1"], "label": "my arm"}},
    }
    with pytest.raises(ValidationError, match="must be a name such as arm"):
        KinematicsSection.model_validate(section)
    section["chains"]["chain"]["label"] = "arm"
    spec = kinematics_spec(KinematicsSection.model_validate(section))
    assert spec.chains[0].shown == "arm"


class _LateMotor:
    """A motor that reaches its goal ``late_s`` after it was made, or stops ``short`` of it."""

    def __init__(self, goal: float, late_s: float, short: float = 0.0) -> None:
        self.goal_position = goal
        self._start = time.monotonic()
        self._late_s = late_s
        self._short = short

    @property
    def present_position(self) -> float:
        done = min(1.0, (time.monotonic() - self._start) / self._late_s)
        return (self.goal_position - self._short) * done


def test_reach_reads_the_arm_once_late_motors_arrived() -> None:
    # a busy machine runs the motors late: the arm is read where the move ended, not on the way
    from poppy_cli.commands.reach import ARRIVED_DEG, _wait_for_arrival

    motors = [_LateMotor(30.0, late_s=1.0), _LateMotor(-20.0, late_s=0.5)]
    _wait_for_arrival(motors)  # type: ignore[arg-type]
    assert all(abs(m.present_position - m.goal_position) <= ARRIVED_DEG for m in motors)


def test_reach_stops_waiting_for_a_motor_that_stopped_short() -> None:
    from poppy_cli.commands.reach import ARRIVAL_LIMIT_S, _wait_for_arrival

    held = _LateMotor(30.0, late_s=0.3, short=5.0)  # held 5° before its goal
    started = time.monotonic()
    _wait_for_arrival([held])  # type: ignore[list-item]
    assert time.monotonic() - started < ARRIVAL_LIMIT_S
    assert held.present_position == pytest.approx(25.0)
