"""What the LeRobot command-line tests share: the robots' and teleoperators' arguments, a
dataset's arguments, the recorded frames (tests/lerobot_plugin/test_commands.py and
test_policy_commands.py, two modules so that two workers run them side by side)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

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
