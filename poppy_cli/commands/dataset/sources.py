"""The source of an episode's actions: a move, a primitive, a hand, a leader (local or Zenoh)."""

from __future__ import annotations

import os
from contextlib import ExitStack
from typing import TYPE_CHECKING, Any

from poppy_cli.commands.dataset.checks import core, usage

if TYPE_CHECKING:
    from poppy_core.motion.episodes import ActionSource
    from poppy_core.robot import Robot, RobotConfig

ZENOH = "zenoh:"


def load_move(name: str, config: RobotConfig) -> Any:
    """The move ``--play`` names, refused when the robot lacks one of its motors."""
    from poppy_core.errors import ConfigError
    from poppy_core.motion import load_move as load
    from poppy_core.motion import move_path

    move = load(move_path(name))
    missing = [m for m in move.motors if m not in config.motors]
    if missing:
        raise ConfigError(f"the robot lacks the move's motors {', '.join(missing)}", field="motors")
    return move


def open_leader(
    stack: ExitStack, leader: str, leader_port: str | None, connect: list[str] | None
) -> Any:
    """The leader robot: ``zenoh:NAME`` (a robot served with ``poppy serve --zenoh``, its state
    stream read), else a profile or config file built here; closed with ``stack``."""
    if leader.startswith(ZENOH):
        from poppy_core.remote.zenoh_client import client_settings, robot_name
        from poppy_core.remote.zenoh_teleop import ZenohLeader

        name = core(lambda: robot_name(leader), "--leader")
        token = os.environ.get("POPPY_TOKEN") or None
        zenoh_leader = ZenohLeader(str(name), token, settings=client_settings(tuple(connect or ())))
        stack.callback(zenoh_leader.close)
        return zenoh_leader
    from poppy_cli.commands.teleop import _build, _config

    return stack.enter_context(_build(_config(leader, leader_port, "leader"), None))


def action_source(
    robot: Robot,
    motors: list[str],
    source: str,
    move: Any,
    primitive: str | None,
    leader: Any,
) -> ActionSource:
    """The actions of ``source`` (a flag of ``checks.SOURCES``) for ``motors`` of ``robot``."""
    from poppy_core.motion import episodes

    if source == "--by-hand":
        return episodes.ByHand(robot, motors)
    if source == "--play":
        from poppy_core.motion import MovePlayer

        players: list[Any] = []

        def start_move() -> None:
            players.append(MovePlayer(robot, move))
            players[-1].start()

        def stop_move() -> None:
            if players:
                players.pop().stop()

        return episodes.Goals(robot, motors, start_move, stop_move)
    if source == "--primitive":
        from poppy_cli.commands.primitive import _find, robot_primitives

        _, found = core(lambda: _find(robot_primitives(robot), str(primitive)), "--primitive")
        return episodes.Goals(robot, motors, found.start, found.stop)
    return _teleoperated(robot, motors, leader)


def _teleoperated(robot: Robot, motors: list[str], leader: Any) -> ActionSource:
    from poppy_core.motion import episodes
    from poppy_core.motion.teleop.session import Teleoperation

    missing = [m for m in motors if m not in [x.name for x in leader.motors]]
    if missing:
        raise usage(f"the leader lacks {', '.join(missing)}: a leader of the same kind", "--leader")
    runs: list[Any] = []

    def start_teleop() -> None:
        runs.append(Teleoperation(leader, robot))
        runs[-1].start()

    def stop_teleop() -> None:
        if runs:
            runs.pop().stop()

    return episodes.Teleoperated(leader, motors, start_teleop, stop_teleop)
