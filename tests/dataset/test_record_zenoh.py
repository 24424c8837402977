"""`poppy dataset record --leader zenoh:NAME`: the actions are the positions a robot served on
Zenoh streams (loopback, explicit endpoints, scouting off)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from tests.helpers.cli import no_user_settings, run_poppy
from tests.helpers.waiting import eventually
from tests.helpers.zenoh_served import TOKEN, Served

pytestmark = pytest.mark.slow
QUICK = ("--fps", "10", "--episode-s", "1.5", "--reset-s", "0", "--no-cameras")


@pytest.fixture(autouse=True)
def settings(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "lerobot"))
    monkeypatch.setenv("POPPY_TOKEN", TOKEN)
    return no_user_settings(tmp_path, monkeypatch, moves=True)


@pytest.fixture
def leader() -> Iterator[Served]:
    served = Served("lead")
    try:
        yield served
    finally:
        served.close()


def test_the_leader_is_a_robot_served_on_zenoh(tmp_path: Path, leader: Served) -> None:
    where = {"m1": 30.0, "m2": -20.0, "m3": 10.0, "m4": 0.0, "m5": 15.0, "m6": -5.0}
    for name, angle in where.items():
        leader.robot.motor(name).compliant = False
        leader.robot.motor(name).goal_position = angle
    assert eventually(
        lambda: (
            [m.present_position for m in leader.robot.motors]
            == pytest.approx(list(where.values()), abs=0.5)
        )
    )
    root = tmp_path / "ds"
    result = run_poppy(
        "dataset",
        "record",
        "me/zenoh",
        "--root",
        str(root),
        "--profile",
        "ergo-jr",
        "--sim",
        "--leader",
        "zenoh:lead",
        "--zenoh-connect",
        leader.endpoint,
        "--task",
        "follow the served arm",
        *QUICK,
        "--json",
    )
    assert result.code == 0, result.stderr
    assert result.json()["frames"] > 5
    data = pq.read_table(root / "data/chunk-000/file-000.parquet").to_pydict()
    wanted = list(where.values())
    for action in data["action"]:
        assert action == pytest.approx(wanted, abs=1.0)
    # the follower ramped to the leader: its last state is where the leader is
    assert data["observation.state"][-1] == pytest.approx(wanted, abs=2.0)


def test_a_zenoh_leader_takes_no_leader_port_and_a_silent_one_is_reported(
    tmp_path: Path, leader: Served
) -> None:
    base = ("dataset", "record", "me/z", "--root", str(tmp_path / "ds"), "--profile", "ergo-jr")
    base = (*base, "--sim", "--task", "t", *QUICK)
    port = run_poppy(*base, "--leader", "zenoh:lead", "--leader-port", "/dev/ttyUSB0")
    assert port.code == 2 and "--leader-port goes with --leader PROFILE" in port.stderr
    connect = run_poppy(*base, "--leader", "ergo-jr", "--zenoh-connect", leader.endpoint)
    assert connect.code == 2 and "--zenoh-connect goes with --leader zenoh:NAME" in connect.stderr
    nobody = run_poppy(*base, "--leader", "zenoh:nobody", "--zenoh-connect", leader.endpoint)
    assert nobody.code != 0 and "zenoh:nobody" in nobody.stderr, nobody.stderr
    assert "Traceback" not in nobody.stderr and not (tmp_path / "ds").exists()
