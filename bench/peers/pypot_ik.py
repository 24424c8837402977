"""pypot's kinematic chains (``IKChain``, on ikpy) as an oracle: forward kinematics and IK timings.

Run it with the peers venv, giving each robot as NAME=CONFIG.json:URDF (the JSON config written
from poppy's profile) and a job on stdin (one JSON document), e.g.::

    bench/.venv-peers/bin/python bench/peers/pypot_ik.py \\
        ergo-jr=/tmp/ergo.json:profiles/ergo-jr/poppy_ergo_jr.urdf < job.json

Jobs:

* ``{"job": "forward", "poses": {"chain_name": [[deg, ...], ...]}}`` -> per chain and pose, the
  4x4 ``forward_kinematics(convert_to_ik_angles(pose))`` (what ``chain.position``,
  ``orientation`` and ``pose`` read for those joint positions);
* ``{"job": "inverse", "chain": "chain", "targets": [[x, y, z], ...], "max_iter": 3 | null}``
  -> per target the joint angles (degrees, user frame) and the solve time, ``inverse_kinematics``
  called as ``IKChain._goto`` calls it (no initial position: ikpy starts at 0 for every joint).

The chains are built as pypot's creatures build them: ``IKChain.from_poppy_creature`` with the
definitions of poppy_ergo_jr.py (``chain``: every motor, tip [0, 0, -0.07]) and poppy_torso.py
(``l_arm_chain`` / ``r_arm_chain``: torso + arm motors, torso passive, tip [0, 0.18, 0],
r_shoulder_x reversed), over a robot built by ``pypot.robot.from_json(..., use_dummy_io=True)``.
The Humanoid gets the Torso's definitions (its torso group has five motors).

ikpy 3.0.1 uses ``numpy.float``, removed in numpy 1.24 (why pypot's REST IK answers 500 on a
current numpy); this script restores the alias at run time so ikpy can run. Nothing in
site-packages is changed.
"""

from __future__ import annotations

import json
import sys
import time
from typing import Any

import numpy

numpy.float = float  # type: ignore[attr-defined]  # ikpy 3.0.1 still uses the removed alias

from pypot.creatures.ik import IKChain  # noqa: E402
from pypot.robot import from_json  # noqa: E402

CHAINS: dict[str, list[tuple[str, list[str], list[str], list[float], list[str]]]] = {
    # name, motor groups, passive groups, tip, reversed motors
    "ergo-jr": [("chain", ["base", "tip"], [], [0.0, 0.0, -0.07], [])],
    "torso": [
        ("l_arm_chain", ["torso", "l_arm"], ["torso"], [0.0, 0.18, 0.0], []),
        ("r_arm_chain", ["torso", "r_arm"], ["torso"], [0.0, 0.18, 0.0], ["r_shoulder_x"]),
    ],
}
CHAINS["humanoid"] = CHAINS["torso"]


def build(kind: str, config: str, urdf: str) -> tuple[Any, dict[str, Any]]:
    """The dummy pypot robot and its chains."""
    robot = from_json(config, use_dummy_io=True)
    robot.urdf_file = urdf
    chains = {}
    for name, groups, passive, tip, reversed_names in CHAINS[kind]:
        motors = [m for g in groups for m in getattr(robot, g)]
        passive_motors = [m for g in passive for m in getattr(robot, g)]
        reversed_motors = [getattr(robot, n) for n in reversed_names]
        chains[name] = IKChain.from_poppy_creature(
            robot, motors=motors, passiv=passive_motors, tip=tip, reversed_motors=reversed_motors
        )
    return robot, chains


def forward(chains: dict[str, Any], poses: dict[str, list[list[float]]]) -> dict[str, Any]:
    """Per chain, the tip pose of each joint pose."""
    out = {}
    for name, listed in poses.items():
        chain = chains[name]
        out[name] = [
            chain.forward_kinematics(chain.convert_to_ik_angles(list(pose))).tolist()
            for pose in listed
        ]
    return out


def inverse(chain: Any, targets: list[list[float]], max_iter: int | None) -> dict[str, Any]:
    """Per target, pypot's answer (degrees, user frame) and the solve time."""
    kwargs = {} if max_iter is None else {"max_iter": max_iter}
    joints, times = [], []
    for target in targets:
        start = time.perf_counter()
        angles = chain.inverse_kinematics(target_position=numpy.array(target), **kwargs)
        times.append(time.perf_counter() - start)
        joints.append([float(v) for v in chain.convert_from_ik_angles(angles)])
    return {"motors": [m.name for m in chain.motors], "joints": joints, "times_s": times}


def main(argv: list[str]) -> int:
    """Build the robots named on the command line and run the job read on stdin."""
    job = json.load(sys.stdin)
    chains: dict[str, Any] = {}
    robots = []
    for arg in argv:
        kind, _, files = arg.partition("=")
        config, _, urdf = files.partition(":")
        robot, built = build(kind, config, urdf)
        robots.append(robot)
        chains.update(built)
    if job["job"] == "forward":
        result: dict[str, Any] = {"poses": forward(chains, job["poses"])}
    else:
        result = inverse(chains[job["chain"]], job["targets"], job.get("max_iter"))
    for robot in robots:
        robot.close()
    sys.stdout.write(json.dumps(result) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
