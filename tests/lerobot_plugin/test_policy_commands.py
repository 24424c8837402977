"""LeRobot 0.4.4's own command lines on Poppy robots through the plugin (issue 38): a policy.

A tiny ACT policy trained for a few steps on CPU from a simulation dataset (`lerobot-record`,
`lerobot-train`), run by `lerobot-record --policy.path` on the simulated robot and, beside it,
on the emulated one (sim to real). Short episodes at a low rate: the machine is shared.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from poppy_core.robot import dump_config, load_profile
from poppy_core.robot.config import RobotConfig
from tests.helpers.bus import emulate_bus
from tests.lerobot_plugin.commands import (
    CAMERA,
    QUIET,
    SIM_FOLLOWER,
    SIM_LEADER,
    XL320_STEP,
    dataset_args,
    frames,
)
from tests.lerobot_plugin.conftest import LeRobot

pytestmark = [pytest.mark.slow, pytest.mark.timeout(1800)]


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
