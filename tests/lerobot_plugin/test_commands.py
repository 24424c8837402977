"""LeRobot 0.4.4's own command lines on Poppy robots through the plugin (issue 38): teleoperate,
record and replay.

`lerobot-teleoperate` and `lerobot-record` with a simulated leader and follower, the episode
loaded by LeRobotDataset and read by poppy as its own; `lerobot-replay` on the emulated robot.
Short episodes at a low rate: the machine is shared. Commands that need not wait for each
other run side by side (``LeRobot.start``); the policy's commands are in test_policy_commands.py
(another worker runs them meanwhile).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poppy_core.dataset.layout import DatasetSpec
from tests.helpers.bus import emulate_bus
from tests.helpers.lerobot_venv import run_oracle
from tests.lerobot_plugin.commands import (
    QUIET,
    SIM_FOLLOWER,
    SIM_LEADER,
    TELEOP_FOLLOWER,
    TELEOP_LEADER,
    XL320_STEP,
    dataset_args,
    frames,
)
from tests.lerobot_plugin.conftest import LeRobot

pytestmark = [pytest.mark.slow, pytest.mark.timeout(1800)]


def test_teleoperate_record_and_replay(lerobot: LeRobot, tmp_path: Path) -> None:
    # teleoperated beside the recording (ids of their own: each writes its calibration files)
    with lerobot.start(
        "lerobot_teleoperate", *TELEOP_FOLLOWER, *TELEOP_LEADER, "--fps=5", "--teleop_time_s=2"
    ) as teleoperating:
        root = tmp_path / "sim-dance"
        lerobot.run(
            "lerobot_record", *SIM_FOLLOWER, *SIM_LEADER, *QUIET,
            *dataset_args(root, "poppy/sim-dance", 1, 6),  # the dance's first 3 s go to 0°
        )  # fmt: skip
        shown = teleoperating.wait()
    # both connected on the simulation, the loop ran at its rate, both let go at the end
    for line in (
        "teleop-follower PoppyErgoJr connected on sim",
        "teleop-leader PoppyErgoJrLeader connected",
    ):
        assert line in shown
    assert "Teleop loop time" in shown and "teleop-follower PoppyErgoJr disconnected" in shown

    with emulate_bus("XL-320:1-6", protocol=2, via="pty") as (bus, port):
        with lerobot.start(
            "lerobot_replay", "--robot.type=poppy_ergo_jr", f"--robot.port={port}",
            "--robot.id=robot", "--dataset.repo_id=poppy/sim-dance", f"--dataset.root={root}",
            "--dataset.episode=0", "--dataset.fps=5", "--play_sounds=false",
        ) as replaying:  # fmt: skip
            # LeRobot's loader reads the episode meanwhile
            seen: dict[str, Any] = run_oracle("load", str(root), "poppy/sim-dance", "0")
            replaying.wait()
        goal_m1 = bus.motor(1).goal_position_deg
        torque = [m.torque_enabled for m in bus.motors]
    assert seen["num_episodes"] == 1 and seen["len"] >= 5
    info = json.loads((root / "meta/info.json").read_text())
    # the same features as `poppy dataset record` writes for an Ergo Jr (but poppy's unit)
    spec = DatasetSpec.from_info(info)
    assert spec.motors == ("m1", "m2", "m3", "m4", "m5", "m6")
    for key, feature in spec.features().items():
        feature.pop("unit", None)
        assert info["features"][key] == feature, key
    recorded = frames(root)
    # the dancing leader's positions are the actions; the follower's, the states, followed
    assert np.ptp(recorded["action"], axis=0).max() > 5.0
    assert np.ptp(recorded["observation.state"], axis=0).max() > 1.0

    # the emulated robot was sent the episode's actions, the last one last (m1: direct, no
    # offset, so the motor frame is the dataset's); compliant once LeRobot disconnected
    assert goal_m1 == pytest.approx(recorded["action"][-1][0], abs=XL320_STEP)
    assert torque == [False] * 6
