"""LeRobot 0.4.4's own command lines on Poppy robots through the plugin (issue 38).

`lerobot-teleoperate` and `lerobot-record` with a simulated leader and follower, the episode
loaded by LeRobotDataset and read by poppy as its own; `lerobot-replay` on the emulated robot;
a tiny ACT policy trained for a few steps on CPU from a simulation dataset, run by
`lerobot-record --policy.path` on the simulated robot, then on the emulated one (sim to real).
Short episodes at a low rate: the machine is shared. Commands that need not wait for each
other run side by side (``LeRobot.start``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import pytest

from poppy_core.dataset.layout import DatasetSpec
from poppy_core.robot import dump_config, load_profile
from poppy_core.robot.config import RobotConfig
from tests.helpers.bus import emulate_bus
from tests.helpers.lerobot_venv import run_oracle
from tests.lerobot_plugin.conftest import LeRobot

pytestmark = [pytest.mark.slow, pytest.mark.timeout(1800)]

SIM_FOLLOWER = ["--robot.type=poppy_ergo_jr", "--robot.port=sim", "--robot.id=follower"]
SIM_LEADER = [
    "--teleop.type=poppy_ergo_jr_leader",
    "--teleop.port=sim",
    "--teleop.id=leader",
    "--teleop.primitive=dance",  # a simulated leader has no hand to move it
]
TELEOP_FOLLOWER = ["--robot.type=poppy_ergo_jr", "--robot.port=sim", "--robot.id=teleop-follower"]
TELEOP_LEADER = [
    "--teleop.type=poppy_ergo_jr_leader",
    "--teleop.port=sim",
    "--teleop.id=teleop-leader",
    "--teleop.primitive=dance",
]
CAMERA = ["--robot.robot_cameras=[camera]", "--robot.robot_camera_resolution=[32,24]"]
QUIET = ["--display_data=false", "--play_sounds=false"]
XL320_STEP = 300 / 1024


def dataset_args(root: Path, repo_id: str, episodes: int, seconds: float) -> list[str]:
    return [
        f"--dataset.repo_id={repo_id}",
        f"--dataset.root={root}",
        f"--dataset.num_episodes={episodes}",
        f"--dataset.episode_time_s={seconds}",
        "--dataset.reset_time_s=0",
        "--dataset.fps=5",
        "--dataset.single_task=dance",
        "--dataset.push_to_hub=false",
    ]


def frames(root: Path) -> dict[str, np.ndarray]:
    """The recorded frames' state and action columns."""
    table = pq.read_table(sorted(root.glob("data/*/*.parquet"))[0]).to_pydict()
    return {key: np.asarray(table[key], dtype=float) for key in ("observation.state", "action")}


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


def test_act_policy_from_simulation_runs_in_simulation_and_on_the_robot(
    lerobot: LeRobot, tmp_path: Path
) -> None:
    data = tmp_path / "sim-camera"
    lerobot.run(
        "lerobot_record", *SIM_FOLLOWER, *CAMERA, *SIM_LEADER, *QUIET,
        *dataset_args(data, "poppy/sim-camera", 1, 3),
    )  # fmt: skip
    info = json.loads((data / "meta/info.json").read_text())
    assert info["features"]["observation.images.camera"]["shape"] == [24, 32, 3]

    out = tmp_path / "act"
    lerobot.run(
        "lerobot_train", "--dataset.repo_id=poppy/sim-camera", f"--dataset.root={data}",
        "--policy.type=act", "--policy.device=cpu", "--policy.push_to_hub=false",
        "--policy.pretrained_backbone_weights=null",  # no download: random ResNet weights
        "--policy.dim_model=32", "--policy.n_heads=2", "--policy.dim_feedforward=64",
        "--policy.n_encoder_layers=1", "--policy.n_decoder_layers=1",
        "--policy.n_vae_encoder_layers=1", "--policy.latent_dim=8",
        "--policy.chunk_size=5", "--policy.n_action_steps=5",
        "--batch_size=2", "--steps=2", "--num_workers=0", "--save_freq=2", "--log_freq=1",
        "--eval_freq=0", "--wandb.enable=false", f"--output_dir={out}",
    )  # fmt: skip
    policy = out / "checkpoints" / "last" / "pretrained_model"
    assert (policy / "model.safetensors").is_file()

    # the robot: the emulator on a pty, its camera a dummy one of the same size
    config = load_profile("ergo-jr").to_dict()
    config["sensors"] = {
        "camera": {"type": "DummyCamera", "resolution": [32, 24], "fps": 5.0},
    }
    profile = dump_config(RobotConfig.from_dict(config, source="test"), tmp_path / "robot.yaml")
    on_robot, in_sim = tmp_path / "eval-robot", tmp_path / "eval-sim"
    with (
        emulate_bus("XL-320:1-6", protocol=2, via="pty") as (bus, port),
        lerobot.start(  # in the simulation, beside the robot
            "lerobot_record", *SIM_FOLLOWER, *CAMERA, *QUIET, f"--policy.path={policy}",
            *dataset_args(in_sim, "poppy/eval_sim", 1, 2),
        ) as in_simulation,
    ):  # fmt: skip
        lerobot.run(
            "lerobot_record", "--robot.type=poppy_ergo_jr", f"--robot.port={port}",
            "--robot.id=robot", f"--robot.profile={profile}", "--robot.robot_cameras=[camera]",
            *QUIET, f"--policy.path={policy}", *dataset_args(on_robot, "poppy/eval_robot", 1, 2),
        )  # fmt: skip
        goal_m1 = bus.motor(1).goal_position_deg
        in_simulation.wait()
    ran = frames(in_sim)
    assert len(ran["action"]) >= 3 and np.isfinite(ran["action"]).all()
    acted = frames(on_robot)
    assert len(acted["action"]) >= 3 and np.isfinite(acted["action"]).all()
    # the policy's last action reached the robot (clamped to m1's limits, a tick of the servo)
    assert goal_m1 == pytest.approx(
        np.clip(acted["action"][-1][0], -150, 150 - XL320_STEP), abs=XL320_STEP
    )
