"""`poppy robot reach X Y Z` and `poppy robot where`: the tips of the robot's kinematic chains.

Added to the `poppy robot` group defined in commands/robot.py.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli.commands.robot import SETTLE_S, app
from poppy_cli.options import (
    ConfigOpt,
    JsonOpt,
    PortOpt,
    ProfileOpt,
    SimOpt,
    duration_option,
)
from poppy_cli.output import console, fmt_deg, print_json
from poppy_cli.robots import build_robot
from poppy_core import checks
from poppy_core.errors import ArgumentError

if TYPE_CHECKING:
    from poppy_core.motion.cartesian import RobotChain
    from poppy_core.robot import Motor, Robot

__all__ = ["app"]

ARRIVED_DEG = 0.5
"""A motor this close to its goal has arrived."""
STILL_S = 0.5
"""A motor short of its goal that has not moved for this long stopped there (held, at a limit)."""
ARRIVAL_LIMIT_S = 30.0
"""The longest wait for the motors to arrive once the move's time is over."""

ChainOpt = typer.Option(None, "--chain", help="The chain to move (default: the robot's first).")


def _numbers(text: str, what: str, count: int = 3) -> list[float]:
    """``count`` finite numbers from words or ``a,b,c``."""
    parts = [p for p in text.replace(",", " ").split() if p]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise typer.BadParameter(
            f"{what} takes {count} numbers, e.g. 0.1,0,0.2; got {text!r}"
        ) from None
    try:
        if len(values) != count:
            raise ArgumentError(what)
        values = [checks.number(v, what) for v in values]  # 1e300 overflowed the solver
    except ArgumentError:
        raise typer.BadParameter(
            f"{what} takes {count} finite numbers within ±{checks.MAX_MAGNITUDE:g}, got {text!r}"
        ) from None
    return values


def _chains(robot: Robot) -> dict[str, RobotChain]:
    from poppy_core.errors import ConfigError
    from poppy_core.motion.chains import robot_chains

    chains = robot_chains(robot)
    if not chains:
        raise ConfigError(
            "this robot has no kinematic chain: add a `kinematics` section (model and chains) "
            "to its config (see docs/kinematics.md)",
            field="kinematics",
        )
    return chains


def _pick(robot: Robot, name: str | None) -> RobotChain:
    from poppy_core.errors import ConfigError

    chains = _chains(robot)
    if name is None:
        return next(iter(chains.values()))
    for chain in chains.values():  # its name (robot.chain) or the name people see (arm)
        if name in (chain.name, chain.label):
            return chain
    known = ", ".join(c.label for c in chains.values())
    raise ConfigError(f"no chain {name!r} (chains: {known})", field=name)


def tip_state(chain: RobotChain) -> dict[str, Any]:
    """Where a chain's tip is: position (m), x axis, roll/pitch/yaw (degrees), its motors."""
    pose = chain.pose
    return {
        "label": chain.label,
        "position": [round(float(v), 5) for v in pose[:3, 3]],
        "orientation": [round(float(v), 5) for v in pose[:3, 0]],
        "rpy_deg": [round(math.degrees(v), 2) for v in chain.rpy],
        "motors": [
            {"name": m.name, "position": round(m.present_position, 2)} for m in chain.motors
        ],
    }


def _wait_for_arrival(motors: list[Motor]) -> None:
    """Wait until the motors are at their goals, or have stopped short of them: the position read
    after a move is where it ended, however late a busy machine runs the motors (a fixed pause
    read a virtual arm 7 mm short at load 20)."""
    time.sleep(SETTLE_S)  # the sync loop reads the motors again
    limit = time.monotonic() + ARRIVAL_LIMIT_S
    last = [m.present_position for m in motors]
    still_since = time.monotonic()
    while time.monotonic() < limit:
        now = [m.present_position for m in motors]
        if all(abs(p - m.goal_position) <= ARRIVED_DEG for p, m in zip(now, motors, strict=True)):
            return
        if any(abs(p - q) > ARRIVED_DEG / 5 for p, q in zip(now, last, strict=True)):
            last, still_since = now, time.monotonic()
        elif time.monotonic() - still_since >= STILL_S:
            return
        time.sleep(0.02)


def _xyz(values: list[float]) -> str:
    """A point for people, in millimetres (as the TUI and the web page show it; JSON and the
    arguments of `robot reach` are metres)."""
    return "(" + ", ".join(f"{v * 1000:.0f}" for v in values) + ") mm"


@app.command("where")
def where(
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Show where the tip of each kinematic chain is (millimetres, in the chain's base frame;
    --json: metres)."""
    with build_robot(profile, config_file, port, sim) as robot:
        time.sleep(SETTLE_S)
        states = {name: tip_state(chain) for name, chain in _chains(robot).items()}
    if json_output:
        print_json([{"name": name, **state} for name, state in states.items()])
        return
    from rich.table import Table

    table = Table(title="chain tips")
    for column in ("chain", "x (mm)", "y (mm)", "z (mm)", "x axis", "roll/pitch/yaw"):
        table.add_column(column, justify="left" if column == "chain" else "right")
    for state in states.values():
        x, y, z = state["position"]
        axis = ", ".join(f"{round(v, 2) + 0.0:.2f}" for v in state["orientation"])
        rpy = " / ".join(f"{v:.0f}°" for v in state["rpy_deg"])
        table.add_row(
            state["label"], f"{x * 1000:.0f}", f"{y * 1000:.0f}", f"{z * 1000:.0f}", axis, rpy
        )
    console.print(table)


@app.command("reach", context_settings={"ignore_unknown_options": True})
def reach(
    coordinates: list[str] = typer.Argument(
        ..., help="Target X Y Z in metres (chain's base frame)."
    ),
    chain_name: str | None = ChainOpt,
    orientation: str | None = typer.Option(
        None, "--orientation", help="The tip's x axis as X,Y,Z (pypot's orientation vector)."
    ),
    rpy: str | None = typer.Option(
        None, "--rpy", help="The tip's whole orientation as roll,pitch,yaw in degrees."
    ),
    duration: float = duration_option(2.0, "Seconds to move."),
    linear: bool = typer.Option(False, "--linear", help="Move the tip along a straight line."),
    wait: bool = typer.Option(False, "--wait", help="Wait until the motors arrived."),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Move a chain's tip to X Y Z (metres): the motors move together, within their limits.

    An unreachable target is refused (nothing moves) with the nearest point the tip can reach.
    The command waits for the move when it streams it (--linear, minimum-jerk robots such as
    the Torso) and with --sim (the virtual robot ends with the command).
    """
    from poppy_core.kinematics import rotation_degrees

    target = _numbers(" ".join(coordinates), "X Y Z")
    if orientation is not None and rpy is not None:
        raise typer.BadParameter("give --orientation or --rpy, not both")
    goal: Any = None
    if orientation is not None:
        goal = _numbers(orientation, "--orientation")
    elif rpy is not None:
        goal = rotation_degrees(_numbers(rpy, "--rpy"))
    with build_robot(profile, config_file, port, sim) as robot:
        chain = _pick(robot, chain_name)
        angles = chain.solve(target, goal)
        # this process streams straight and minjerk moves, and a --sim robot ends with it
        wait = wait or bool(sim) or linear or chain.control == "minjerk"
        for motor in chain.active_motors:
            motor.compliant = False
        if linear:
            chain.goto_linear(target, goal, duration=max(duration, 0.05), wait=wait)
        else:
            chain.goto(target, goal, duration=duration, wait=wait)
        if wait:
            _wait_for_arrival(chain.active_motors)
        reached = [float(v) for v in chain.position] if wait else None
    result: dict[str, Any] = {
        "chain": chain.name,
        "label": chain.label,
        "target": target,
        "motors": [{"name": name, "goal": angle} for name, angle in angles.items()],
        "waited": wait,
        "position": reached,
    }
    if reached is not None:
        result["error_m"] = math.dist(reached, target)
    if json_output:
        print_json(result)
        return
    motors = ", ".join(f"{n}={fmt_deg(a)}" for n, a in angles.items())
    if reached is None:
        console.print(f"{chain.label}: moving to {_xyz(target)} in {duration:g} s ({motors})")
    else:
        console.print(
            f"{chain.label}: at {_xyz(reached)}, {result['error_m'] * 1000:.1f} mm from "
            f"{_xyz(target)} ({motors})"
        )
