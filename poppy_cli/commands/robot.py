"""`poppy robot ...`: build a robot from a profile or config file, show it, move it."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli import complete
from poppy_cli.options import (
    ConfigOpt,
    JsonOpt,
    PortOpt,
    ProfileOpt,
    RemoteOpt,
    SimOpt,
    duration_option,
)
from poppy_cli.output import EXIT_INTERRUPTED, console, fmt_value, print_json, styled
from poppy_cli.robots import build_robot, open_remote, robot_config, start_robot
from poppy_cli.targets import TargetSyntaxError, parse_targets
from poppy_core.errors import ArgumentError
from poppy_core.trajectory import control_name

if TYPE_CHECKING:
    from rich.table import Table

    from poppy_core.remote import RemoteMotor, RemoteRobot
    from poppy_core.robot import Motor, Robot

app = typer.Typer(
    help="Drive a whole robot: status, goto, compliance (a profile, a config file or --sim).",
    no_args_is_help=True,
)

SETTLE_S = 0.1
"""Time for the sync loop to read the motors again after a command."""


def motor_state(motor: Motor | RemoteMotor) -> dict[str, Any]:
    """One motor's state as plain values (degrees, deg/s, %, °C, V)."""
    return {
        "id": motor.id,
        "model": motor.model.name,
        "position": motor.present_position,
        "goal": motor.goal_position,
        "speed": motor.present_speed,
        "load": motor.present_load,
        "temperature": motor.present_temperature,
        "voltage": motor.present_voltage,
        "compliant": motor.compliant,
        "online": motor.online,
        "errors": motor.errors,
    }


def robot_state(robot: Robot | RemoteRobot) -> dict[str, dict[str, Any]]:
    """Motor name -> its state."""
    return {motor.name: motor_state(motor) for motor in robot.motors}


def records(by_name: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """``{NAME: {...}}`` as the CLI's JSON gives a collection: a list of records, each with its
    ``name`` first (docs/cli.md, JSON output)."""
    return [{"name": name, **record} for name, record in by_name.items()]


def status_table(robot: Robot | RemoteRobot, title: str = "robot status") -> Table:
    """A Rich table of every motor's state."""
    from rich.table import Table

    table = Table(title=title)
    columns = ("motor", "id", "position", "goal", "speed", "load", "temp", "voltage")
    for column in columns:
        table.add_column(column, justify="left" if column == "motor" else "right")
    table.add_column("compliant")
    table.add_column("link")
    for name, state in robot_state(robot).items():
        errors = f" ({state['errors']} errors)" if state["errors"] else ""
        link = styled("online{}" if state["online"] else "[red]offline[/]{}", errors)
        table.add_row(
            name,
            str(state["id"]),
            fmt_value(round(state["position"], 1), "°"),
            fmt_value(round(state["goal"], 1), "°"),
            fmt_value(round(state["speed"], 1), "°/s"),
            fmt_value(round(state["load"], 1), "%"),
            fmt_value(state["temperature"], "°C"),
            fmt_value(state["voltage"], "V"),
            "yes" if state["compliant"] else "no",
            link,
        )
    table.caption = frame_note(robot)
    return table


def frame_note(robot: Robot | RemoteRobot) -> str | None:
    """Why a robot's angle differs from the motor's own (`poppy motor` speaks the motor's):
    the motors mounted indirect (sign flipped) or with an offset; None when none is."""
    flipped = [m.name for m in robot.motors if getattr(m, "orientation", "") == "indirect"]
    shifted = [
        f"{m.name} {float(getattr(m, 'offset', 0.0)):+g}°"
        for m in robot.motors
        if float(getattr(m, "offset", 0.0))
    ]
    parts = ([" ".join(flipped) + " sign flipped"] if flipped else []) + (
        ["offset " + " ".join(shifted)] if shifted else []
    )
    if not parts:
        return None
    return f"robot frame: {'; '.join(parts)} (`poppy motor` shows the motor's own)"


def robot_health(robot: Robot | RemoteRobot) -> dict[str, dict[str, Any]]:
    """Controller name -> its bus's health as plain values (``Robot.health``)."""
    return {
        name: health if isinstance(health, dict) else health.as_dict()
        for name, health in robot.health().items()
    }


def health_table(health: dict[str, dict[str, Any]]) -> Table:
    """A Rich table of each bus: link, loop rates, error counters, offline motors."""
    from rich.table import Table
    from rich.text import Text

    table = Table(title="buses")
    for column in ("bus", "port", "link", "loops (Hz)", "timeouts", "retries", "corrupt"):
        table.add_column(
            column, justify="right" if column in ("timeouts", "retries", "corrupt") else "left"
        )
    table.add_column("offline")
    for name, bus in health.items():
        if bus["connected"]:
            link = Text("connected" if bus["running"] else "stopped")
        else:
            link = Text(f"LOST {bus['down_s']:.1f} s (reopening)", style="red")
        loops = ", ".join(
            f"{loop} {hz:.0f}/{bus['target_hz'][loop]:g}" for loop, hz in bus["loop_hz"].items()
        )
        offline = Text(", ".join(bus["offline"]) or "none", style="red" if bus["offline"] else "")
        table.add_row(
            Text(str(bus.get("label", name))),
            Text(bus["port"]),
            link,
            loops,
            str(bus["timeouts"]),
            str(bus["retries"]),
            str(bus["corrupt_packets"]),
            offline,
        )
    return table


@app.command("status")
def status(
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    watch: bool = typer.Option(False, "--watch", "-w", help="Refresh at 10 Hz until Ctrl-C."),
    json_output: bool = JsonOpt,
    remote: str | None = RemoteOpt,
) -> None:
    """Show every motor (position, goal, speed, load, temperature, voltage, compliance, link)
    and each bus's health (link, loop rates, errors, offline motors).

    --json prints {"motors": [{name, id, position, ...}], "buses": [{name, port, ...}]}.
    """
    opened = open_remote(remote) if remote else build_robot(profile, config_file, port, sim)
    with opened as robot:
        if not remote:
            time.sleep(SETTLE_S)  # a few loop runs, so that the loop rates are measured
        if json_output:
            print_json(
                {"motors": records(robot_state(robot)), "buses": records(robot_health(robot))}
            )
            return
        if not watch:
            console.print(status_table(robot))
            console.print(health_table(robot_health(robot)))
            return
        from rich.console import Group
        from rich.live import Live

        def view(title: str) -> Group:
            return Group(status_table(robot, title), health_table(robot_health(robot)))

        try:
            with Live(view("robot status"), console=console, refresh_per_second=10) as live:
                while True:
                    time.sleep(0.1)
                    live.update(view("robot status (Ctrl-C to stop)"))
        except KeyboardInterrupt:  # the way to stop watching, yet an interruption (130)
            raise typer.Exit(EXIT_INTERRUPTED) from None


def _goals(
    targets: list[str],
    known: list[str],
    limits: dict[str, tuple[float, float] | None] | None = None,
) -> dict[str, float]:
    """The targets of `robot goto`; a word that is not NAME=DEGREES is a usage error."""
    try:
        return parse_targets(targets, known, limits)
    except TargetSyntaxError as exc:
        raise typer.BadParameter(str(exc)) from None


@app.command("goto")
def goto(
    targets: list[str] = typer.Argument(..., help="Targets as NAME=DEGREES, e.g. m1=30 m2=-10."),
    duration: float = duration_option(1.0, "Seconds to move."),
    wait: bool = typer.Option(False, "--wait", help="Wait until the motors arrived."),
    control: str = typer.Option("minjerk", "--trajectory", help="minjerk or dummy."),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonOpt,
    remote: str | None = RemoteOpt,
) -> None:
    """Move motors so they arrive together (torque is turned on for the motors moved).

    A minjerk trajectory is streamed by this command, so it runs until the motion ends; a dummy
    move is one goal and speed per motor, which the motors finish on their own unless --wait.
    A --sim robot lives only within the command, so --sim always waits; a --remote robot
    (served by `poppy serve`) moves on its own, so the command waits only with --wait.
    """
    try:
        control = control_name(control)
    except ArgumentError as exc:
        raise typer.BadParameter(str(exc), param_hint="--trajectory") from None
    robot: Robot | RemoteRobot
    if remote:
        robot = open_remote(remote)
        goals = _goals(targets, [m.name for m in robot.motors])
    else:
        config = robot_config(profile, config_file, port)
        limits = {
            name: None if motor.wheel_mode else motor.user_angle_limit
            for name, motor in config.motors.items()
        }
        goals = _goals(targets, list(config.motors), limits)
        robot = start_robot(config, sim)
        wait = wait or bool(sim) or control == "minjerk"
    with robot:
        for name in goals:
            robot.motor(name).compliant = False
        robot.goto_position(goals, duration, control=control, wait=wait)
        if wait:
            time.sleep(SETTLE_S)
        reached = {name: robot.motor(name).present_position for name in goals}
    if json_output:
        motors = [{"name": n, "goal": g, "position": reached[n]} for n, g in goals.items()]
        print_json({"motors": motors, "waited": wait})
        return
    for name, goal in goals.items():
        if wait:
            console.print(f"{name}: {fmt_value(round(reached[name], 1), '°')} (goal {goal:g}°)")
        else:
            console.print(f"{name}: moving to {goal:g}° in {duration:g} s")


@app.command("compliant")
def compliant(
    state: str = typer.Argument(
        ...,
        help="on (free to move by hand) or off (holds position).",
        autocompletion=complete.on_off,
    ),
    names: list[str] | None = typer.Argument(None, help="Motors or groups (default: all)."),
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    port: str | None = PortOpt,
    sim: str | None = SimOpt,
    json_output: bool = JsonOpt,
    remote: str | None = RemoteOpt,
) -> None:
    """Make motors compliant (on) or stiff (off); every motor when none is named."""
    from poppy_core.errors import ConfigError

    lowered = state.strip().lower()
    if lowered not in ("on", "off"):
        raise typer.BadParameter(f"state takes on or off, not {state!r}")
    value = lowered == "on"
    robot: Robot | RemoteRobot
    if remote:
        robot = open_remote(remote)
        motors = [m.name for m in robot.motors]
        members = {g: [m.name for m in ms] for g, ms in robot.motorgroups.items()}
    else:
        config = robot_config(profile, config_file, port)
        motors = list(config.motors)
        members = {g: config.resolve_group(g) for g in config.motorgroups}
    chosen: list[str] = []
    for name in names or motors:
        if name not in motors and name not in members:
            groups = ", ".join(members) or "none"
            raise ConfigError(
                f"no motor or group {name!r} (motors: {', '.join(motors)}; groups: {groups})",
                field=name,
            )
        chosen.extend(n for n in members.get(name, [name]) if n not in chosen)
    if not remote:
        robot = start_robot(config, sim)
    with robot:
        for name in chosen:
            robot.motor(name).compliant = value
        result = {name: robot.motor(name).compliant for name in chosen}
    if json_output:
        print_json([{"name": name, "compliant": flag} for name, flag in result.items()])
        return
    for name, is_compliant in result.items():
        console.print(f"{name}: compliant {'on' if is_compliant else 'off'}")
