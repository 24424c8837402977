"""Offscreen renders of a profile's simulated robot: a still, or a move played frame by frame."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from poppy_core.errors import ConfigError

if TYPE_CHECKING:
    from poppy_core.motion.move import Move
    from poppy_core.robot import RobotConfig

GIF_FPS = 15.0
SETTLE_S = 0.5  # physics time before the first frame: the robot takes its pose


@dataclass(frozen=True)
class RenderProgress:
    """Where a render is: ``done`` frames of ``total`` rendered."""

    done: int
    total: int


def frame_count(move: Move | None, fps: float = GIF_FPS) -> int:
    """Frames a render holds: one still, or the first pose and ``fps`` frames a second of move."""
    return 1 if move is None else int(move.duration_s * fps) + 2


def _motor_map(config: RobotConfig, servers: dict[str, Any]) -> dict[str, tuple[Any, Any]]:
    """Motor name -> (virtual motor, its config entry)."""
    out: dict[str, tuple[Any, Any]] = {}
    for controller, server in servers.items():
        for name in config.motors_of_controller(controller):
            entry = config.motors[name]
            out[name] = (server.bus.motor(entry.id), entry)
    return out


def _command(motors: dict[str, tuple[Any, Any]], goals: dict[str, float]) -> None:
    """Torque on and goal positions (poppy's frame) written into the virtual motors' tables."""
    from poppy_core.robot.frames import to_motor

    for name, (motor, entry) in motors.items():
        with motor.lock:
            motor.table.set("torque_enable", 1)
            if name in goals:
                goal = to_motor(goals[name], entry.orientation, entry.offset)
                motor.table.set_si("goal_position", goal)


def render_frames(
    config: RobotConfig,
    move: Move | None,
    camera: str | None,
    width: int,
    height: int,
    *,
    progress: Callable[[RenderProgress], None] | None = None,
) -> list[Any]:
    """RGB frames of the config's robot: one still (servos on) or ``move`` at ``GIF_FPS``.

    The physics is advanced by hand (no thread, faster than real time); goals go through the
    virtual servos' control tables, so their speed and torque limits apply as on a robot.
    ``progress`` is called after each frame.

    Raises:
        ConfigError: the move drives motors the robot has not; no OpenGL (field ``MUJOCO_GL``).
        ValueError: the model has no such camera (MuJoCo's words).
    """
    from poppy_core.robot.factory import start_emulators, start_simulation

    if move is not None:
        unknown = [m for m in move.motors if m not in config.motors]
        if unknown:
            raise ConfigError(
                f"the move drives motors the robot has not: {', '.join(unknown)}", field="move"
            )
    total = frame_count(move)
    simulation = start_simulation(config)
    servers = start_emulators(config, simulation)
    try:
        motors = _motor_map(config, servers)
        _command(motors, move.position_at(0.0) if move is not None else {})
        simulation.advance(SETTLE_S)
        frames = [simulation.render(camera, width, height)]
        if progress is not None:
            progress(RenderProgress(1, total))
        if move is not None:
            step = 1.0 / GIF_FPS
            for index in range(1, total):
                _command(motors, move.position_at(min(index * step, move.duration_s)))
                simulation.advance(step)
                frames.append(simulation.render(camera, width, height))
                if progress is not None:
                    progress(RenderProgress(index + 1, total))
        return frames
    finally:
        for server in servers.values():
            server.stop()
        simulation.close()
