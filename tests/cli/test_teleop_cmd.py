"""`poppy teleop` as a subprocess against emulators served from the test (moved by a test hand)."""

from __future__ import annotations

import math
import os
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from poppy_core.emulator import EmulatorServer, VirtualBus, serve_pty
from poppy_core.motion import read_move
from poppy_core.robot import load_profile
from poppy_core.robot.factory import virtual_buses
from tests.helpers.cli import POPPY, Result, command_env, no_user_settings
from tests.helpers.processes import start
from tests.helpers.waiting import scaled


@pytest.fixture(autouse=True)
def settings(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty move library, no user settings or default robot."""
    return no_user_settings(tmp_path, monkeypatch, moves=True)


def ergo_jr_bus() -> Iterator[tuple[VirtualBus, EmulatorServer]]:
    bus = virtual_buses(load_profile("ergo-jr"))["my_dxl_controller"]
    server = serve_pty(bus)
    try:
        yield bus, server
    finally:
        server.stop()


@pytest.fixture
def leader_bus() -> Iterator[tuple[VirtualBus, EmulatorServer]]:
    """A virtual Ergo Jr bus served on a pty by this process (the test's hand moves it)."""
    yield from ergo_jr_bus()


@pytest.fixture
def follower_bus() -> Iterator[tuple[VirtualBus, EmulatorServer]]:
    """Another one, to follow."""
    yield from ergo_jr_bus()


def run_with_hand(args: list[str], hand: VirtualBus, timeout_s: float = 60.0) -> Result:
    """Run `poppy ARGS`, waving the leader's joints (motor frame) until it exits."""
    env = dict(os.environ, **command_env())
    proc = start([*POPPY, *args], env, stdin=subprocess.DEVNULL)
    began = time.monotonic()
    while proc.poll() is None and time.monotonic() - began < timeout_s:
        t = time.monotonic() - began
        for k, motor in enumerate(hand.motors):
            motor.move_by_hand(20.0 + 25.0 * math.sin(2.0 * t + k))
        time.sleep(0.01)
    stdout, stderr = proc.communicate(timeout=scaled(20))
    return Result(proc.returncode, stdout, stderr)


def test_a_follower_copies_the_leader_and_the_run_is_recorded(
    leader_bus: Any, follower_bus: Any, settings: Path
) -> None:
    (hand, leader), (follow, follower) = leader_bus, follower_bus
    begun = time.monotonic()
    result = run_with_hand(
        [
            "teleop",
            "--leader",
            "ergo-jr",
            "--leader-port",
            leader.url,
            "--follower",
            "ergo-jr",
            "--follower-port",
            follower.url,
            "--duration",
            "2.5",
            "--record",
            "copied",
            "--json",
        ],
        hand,
    )
    assert result.code == 0, result.stderr
    summary = result.json()
    assert summary["map"] == "m1=m1, m2=m2, m3=m3, m4=m4, m5=m5, m6=m6"
    # it ticked (125 times in 2.5 s at 50 Hz when the machine keeps up: how often is the
    # teleop bench's; a loaded machine ticked 27 times) and never held
    assert summary["ticks"] > 1 and summary["holds"] == 0
    assert summary["record_path"] == str(settings / "copied.move")
    move = read_move(settings / "copied.move")
    assert move.motors == tuple(f"m{i}" for i in range(1, 7))
    # the following after the start-up ramp, within the run (about 2 s when the machine keeps
    # up; 0.82 s once at load 20, where the ramp took longer)
    assert 0 < move.duration_s <= time.monotonic() - begun
    spread = move.positions.max(axis=0) - move.positions.min(axis=0)
    assert (spread > 10.0).all()  # the follower moved with the hand
    assert "ramping" in result.stderr and "following" in result.stderr
    # stopped: the follower's servos hold, stiff
    assert all(m.torque_enabled for m in follow.motors)


def test_a_simulated_follower_with_a_map(leader_bus: Any) -> None:
    hand, leader = leader_bus
    result = run_with_hand(
        [
            "teleop",
            "--leader",
            "ergo-jr",
            "--leader-port",
            leader.url,
            "--follower",
            "torso",
            "--follower-sim",
            "ideal",
            "--map",
            "r_shoulder_y=m2, r_elbow_y=-m3+30",
            "--rate",
            "50",
            "--duration",
            "1.5",
            "--json",
        ],
        hand,
    )
    assert result.code == 0, result.stderr
    assert result.json()["map"] == "r_shoulder_y=m2, r_elbow_y=-m3+30"


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["--follower", "ergo-jr", "--map", "m1=="], 1, "is not a joint link"),
        (["--follower", "ergo-jr", "--map", "m1=m9"], 1, "the leader has no motor m9"),
        (["--follower", "ergo-jr", "--follower-sim", "physics"], 2, "use ideal or mujoco"),
        (["--follower", "self", "--follower-port", "/dev/null"], 2, "--follower self"),
        (["--follower", "self"], 2, "needs a --map of other joints"),
        (["--follower", "self", "--map", "m1=m2,m2=m1"], 1, "cannot lead and follow"),
        (["--follower", "http://127.0.0.1:9", "--follower-sim", "ideal"], 2, "served follower"),
        (["--follower", "nope"], 1, "unknown profile"),
        (["--follower", "ergo-jr", "--follower-port", "PORT"], 2, "cannot share PORT"),
        (["--follower", "ergo-jr", "--map", "a=b", "--map-file", "x.yaml"], 2, "not both"),
        (["--follower", "http://127.0.0.1:9"], 1, "cannot reach"),
    ],
)
def test_bad_input_is_one_line(poppy: Any, args: list[str], code: int, message: str) -> None:
    leader = ["--leader", "ergo-jr", "--leader-port", "PORT"]
    result = poppy("teleop", *leader, *args, "--duration", "1")
    assert result.code == code, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr
    if code == 1:
        assert len(result.stderr.strip().splitlines()) == 1


def test_an_existing_record_needs_force(poppy: Any, settings: Path) -> None:
    settings.mkdir(parents=True)
    (settings / "taken.move").write_bytes(b"")
    result = poppy(
        "teleop",
        "--leader",
        "ergo-jr",
        "--leader-port",
        "A",
        "--follower",
        "ergo-jr",
        "--follower-port",
        "B",
        "--record",
        "taken",
    )
    assert result.code == 1 and "pass --force" in result.stderr  # a refused file: 1
