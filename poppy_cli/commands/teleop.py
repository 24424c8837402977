"""`poppy teleop`: a follower robot copies a leader moved by hand (local, simulated or served).

The work is ``poppy_core.motion.teleop.teleoperate``; this module builds the two robots from the
options, shows the teleoperation live and prints a summary.
"""

from __future__ import annotations

import os
import sys
import threading
from contextlib import ExitStack
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli import complete
from poppy_cli.options import SIM_ENGINES, JsonSummaryOpt, StopAfterOpt, finite
from poppy_cli.output import (
    EXIT_FAILURE,
    EXIT_USAGE,
    console,
    err_console,
    error_line,
    fmt_deg,
    print_json,
    styled,
)

if TYPE_CHECKING:
    from rich.table import Table

    from poppy_core.motion.teleop.joint_map import JointMap
    from poppy_core.motion.teleop.leader import Leader
    from poppy_core.motion.teleop.session import Teleoperation
    from poppy_core.remote.zenoh_teleop import ZenohLeader
    from poppy_core.robot import Robot, RobotConfig

REFRESH_S = 0.1
SELF = "self"


def _is_url(text: str) -> bool:
    return text.startswith(("http://", "https://", "ws://"))


def _config(spec: str, port: str | None, role: str) -> RobotConfig:
    """A profile name or a config file, with ``port`` on its one bus."""
    from poppy_core.errors import ConfigError
    from poppy_core.robot import load_config, load_profile, with_ports

    path = Path(spec).expanduser()
    config = load_config(path) if path.is_file() else load_profile(spec)
    if port is None:
        return config
    try:
        return with_ports(config, port, source="command line")
    except ConfigError as exc:
        raise ConfigError(f"--{role}-port: {exc}", field=exc.field) from None


def _joint_map(text: str | None, file: Path | None) -> JointMap | None:
    from poppy_core.motion.teleop.joint_map import JointMap

    if text is not None and file is not None:
        raise typer.BadParameter("give --map or --map-file, not both", param_hint="--map")
    if file is not None:
        return JointMap.load(file)
    return JointMap.parse(text) if text is not None else None


def _ports_of(config: RobotConfig) -> set[str]:
    return {c.port for c in config.controllers.values() if c.port != "auto"}


def teleop(
    leader: str | None = typer.Option(
        None,
        "--leader",
        help="Leader: a profile name, a config file, or zenoh:NAME (a robot served with "
        "`poppy serve --zenoh`). [default: user settings]",
        autocompletion=complete.profiles,
    ),
    leader_port: str | None = typer.Option(
        None,
        "--leader-port",
        help="Serial port of the leader's bus. [env: POPPY_PORT]",
        autocompletion=complete.ports,
    ),
    follower: str = typer.Option(
        ...,
        "--follower",
        help="Follower: a profile name, a config file, http://HOST:PORT of `poppy serve "
        "--http`, zenoh:NAME of `poppy serve --zenoh`, or 'self' (the leader copies its own "
        "joints, e.g. one arm to the other).",
        autocompletion=complete.profiles,
    ),
    follower_port: str | None = typer.Option(
        None,
        "--follower-port",
        help="Serial port of the follower's bus.",
        autocompletion=complete.ports,
    ),
    follower_sim: str | None = typer.Option(
        None,
        "--follower-sim",
        metavar="[mujoco]",
        help="Simulate the follower: --follower-sim (ideal servos) or --follower-sim mujoco.",
        autocompletion=complete.engines,
    ),
    joint_map: str | None = typer.Option(
        None,
        "--map",
        help="Joint map FOLLOWER=[-][SCALE*]LEADER[+OFFSET],... (default: same motor names).",
    ),
    map_file: Path | None = typer.Option(None, "--map-file", help="Joint map file (YAML)."),
    rate: float = typer.Option(
        100.0, "--rate", min=1.0, max=1000.0, callback=finite, help="Ticks per second."
    ),
    ramp: float | None = typer.Option(
        None,
        "--ramp",
        min=0.0,
        max=30.0,
        callback=finite,
        help="Start/resume ramp in s (default: by distance).",
    ),
    duration: float | None = StopAfterOpt,
    record: str | None = typer.Option(
        None, "--record", help="Save the follower's trajectory as a move of this name (or path)."
    ),
    force: bool = typer.Option(
        False, "--force", "-f", help="Replace an existing move of that name."
    ),
    json_output: bool = JsonSummaryOpt,
    connect: list[str] | None = typer.Option(
        None,
        "--zenoh-connect",
        "--connect",
        help="For zenoh:NAME robots: a Zenoh peer or router to connect to (repeat it). "
        "Default: POPPY_ZENOH_CONNECT, else tcp/127.0.0.1:7447.",
    ),
) -> None:
    """Teleoperate: the leader turns compliant, move it by hand; the follower copies it.

    The follower ramps from where it is to the leader, then follows at --rate; it holds where it
    is when the leader (or the network to a served follower) is lost and ramps again when it
    comes back. Enter, Ctrl-C or --duration stops: the follower holds where it is, stiff; the
    leader stays compliant. Angles are compared in each robot's calibrated frame (`poppy
    calibrate`), so two calibrated robots of one kind agree; other pairs need --map.
    """
    from poppy_cli.commands.record import _install_stop
    from poppy_cli.robots import robot_config
    from poppy_core.motion import move_path

    if follower_sim is not None and follower_sim not in SIM_ENGINES:
        raise typer.BadParameter(
            f"{follower_sim!r}: use ideal or mujoco", param_hint="--follower-sim"
        )
    zenoh_leader = leader is not None and leader.startswith("zenoh:")
    zenoh_follower = follower.startswith("zenoh:")
    remote = _is_url(follower) or zenoh_follower
    if zenoh_leader and (leader_port or follower == SELF):
        raise typer.BadParameter("a zenoh: leader takes no --leader-port and no --follower self")
    if remote and (follower_port or follower_sim):
        raise typer.BadParameter("a served follower takes no --follower-port or --follower-sim")
    if follower == SELF and (follower_port or follower_sim):
        raise typer.BadParameter("--follower self is the leader: no --follower-port/--follower-sim")
    mapping = _joint_map(joint_map, map_file)
    path = move_path(record, must_exist=False) if record is not None else None
    if path is not None and path.exists() and not force:
        error_line(f"{path} exists: pick another name or pass --force")
        raise typer.Exit(EXIT_FAILURE)  # a refused file: 1, as everywhere
    if path is not None:
        from poppy_core.files import probe_folder
        from poppy_core.motion.move_library import is_path

        probe_folder(path.parent, make_folder=not is_path(record or ""))  # before anything moves
    leader_file = Path(leader).expanduser() if leader is not None else None
    leader_config: RobotConfig | None = None
    if zenoh_leader:
        pass
    elif leader_file is not None and leader_file.is_file():  # the port: option, env, settings
        leader_config = robot_config(None, leader_file, leader_port)
    else:
        leader_config = robot_config(leader, None, leader_port)
    follower_config = (
        None if remote or follower == SELF else _config(follower, follower_port, "follower")
    )
    if leader_config is not None and follower_config is not None and follower_sim is None:
        shared = _ports_of(leader_config) & _ports_of(follower_config)
        if shared:
            error_line(
                f"the leader and the follower cannot share {', '.join(sorted(shared))}: "
                "give each its own port (or --follower self for one robot)"
            )
            raise typer.Exit(EXIT_USAGE)
    with ExitStack() as stack:
        # Everything that can be refused is, before a robot is built (nothing turns compliant).
        follow: Any = None
        zenoh_lead: ZenohLeader | None = None
        settings = _zenoh_settings(connect) if zenoh_leader or zenoh_follower else None
        if zenoh_follower:
            follow = _zenoh_follower(follower, settings)
            stack.callback(follow.close)
            follower_motors = follow.motor_names
        elif remote:
            follow = _remote(follower, rate)
            stack.callback(follow.close)
            follower_motors = follow.motor_names
        else:
            follower_motors = list((follower_config or leader_config).motors)  # type: ignore[union-attr]
        if leader_config is None:
            zenoh_lead = _zenoh_leader(str(leader), settings)
            stack.callback(zenoh_lead.close)
            leader_motors = [m.name for m in zenoh_lead.motors]
        else:
            leader_motors = list(leader_config.motors)
        _check_map(mapping, leader_motors, follower_motors, follower == SELF)
        lead: Leader
        if zenoh_lead is not None:
            lead = zenoh_lead
        else:
            assert leader_config is not None
            lead = stack.enter_context(_build(leader_config, None))
        if follow is None:
            follow = (
                lead
                if follower_config is None
                else stack.enter_context(_build(follower_config, follower_sim))
            )
        # Only now do Ctrl-C and Enter stop a teleoperation: before, a question asked at
        # start-up (return delays) is answered, or Ctrl-C there ends the command.
        stop = threading.Event()
        _install_stop(stop)
        leader_name = (
            leader_config.profile.name
            if leader_config is not None and leader_config.profile is not None
            else leader or "leader"
        )
        teleop_run = _start(
            lead, follow, mapping, rate, ramp, duration, path, leader_name, follower
        )
        _watch(teleop_run, stop, show=not json_output)
        report = teleop_run.report()
        if teleop_run.error is not None:
            raise teleop_run.error
    summary = {
        "leader": leader or "settings",
        "follower": follower,
        "map": str(teleop_run.joint_map),
        **report.as_dict(),
    }
    if json_output:
        print_json(summary)
        return
    console.print(
        f"teleoperated {report.duration_s:.1f} s at {report.measured_hz:.1f} Hz "
        f"(asked {rate:g}); holds: {report.holds}"
        + (f"; recorded {report.recorded_frames} frames to {report.record_path}" if path else "")
    )


def _check_map(
    mapping: JointMap | None, leader: list[str], follower: list[str], same_robot: bool
) -> None:
    from poppy_core.motion.teleop.joint_map import JointMap

    if same_robot and mapping is None:
        raise typer.BadParameter(
            "--follower self needs a --map of other joints, e.g. r_elbow_y=l_elbow_y",
            param_hint="--map",
        )
    chosen = mapping or JointMap.same_names(leader, follower)
    chosen.check(leader, follower)
    both = sorted(set(chosen.leaders) & set(chosen.followers)) if same_robot else []
    if both:
        from poppy_core.errors import ConfigError

        raise ConfigError(
            f"{', '.join(both)} cannot lead and follow at once: map other joints",
            field="map",
            value=both,
        )


def _build(config: RobotConfig, sim: str | None) -> Robot:
    from poppy_cli.robots import start_robot

    return start_robot(config, sim)


def _remote(url: str, rate: float) -> Any:
    from poppy_core.remote import RemoteFollower

    if url.startswith("https://"):
        raise typer.BadParameter("poppy serve speaks http:// (put a TLS proxy in front of it)")
    return RemoteFollower(url, token=os.environ.get("POPPY_TOKEN") or None, rate_hz=rate)


def _zenoh_settings(connect: list[str] | None) -> Any:
    from poppy_core.remote.zenoh_client import client_settings

    return client_settings(tuple(connect or ()))


def _zenoh_leader(spec: str, settings: Any) -> ZenohLeader:
    from poppy_core.remote.zenoh_client import robot_name
    from poppy_core.remote.zenoh_teleop import ZenohLeader

    token = os.environ.get("POPPY_TOKEN") or None
    return ZenohLeader(str(robot_name(spec)), token, settings=settings)


def _zenoh_follower(spec: str, settings: Any) -> Any:
    from poppy_core.remote.zenoh_client import robot_name
    from poppy_core.remote.zenoh_teleop import ZenohFollower

    token = os.environ.get("POPPY_TOKEN") or None
    return ZenohFollower(str(robot_name(spec)), token, settings=settings)


def _start(
    leader: Leader,
    follower: Any,
    mapping: JointMap | None,
    rate: float,
    ramp: float | None,
    duration: float | None,
    path: Path | None,
    name: str,
    follower_spec: str,
) -> Teleoperation:
    from poppy_core.motion.teleop.session import Teleoperation

    metadata = {"description": f"teleoperated: {name} → {follower_spec}"}
    if getattr(follower, "config", None) is not None and follower.config.profile is not None:
        metadata["robot"] = follower.config.profile.name
    teleop_run = Teleoperation(
        leader,
        follower,
        mapping,
        rate_hz=rate,
        ramp_s=ramp,
        duration_s=duration,
        record=path,
        record_metadata=metadata,
        on_change=lambda state, reason: err_console.print(styled("[dim]{}: {}[/]", state, reason)),
    )
    err_console.print(
        f"teleoperating {follower_spec} from the leader at {rate:g} Hz "
        f"({teleop_run.joint_map}) — move the leader by hand; Enter or Ctrl-C stops",
        soft_wrap=True,
    )
    sys.stderr.flush()
    return teleop_run.start()


def _watch(teleop_run: Teleoperation, stop: threading.Event, *, show: bool) -> None:
    if not (show and err_console.is_terminal):
        while teleop_run.running:
            if stop.wait(REFRESH_S):
                teleop_run.stop()
        return
    from rich.live import Live

    with Live(_table(teleop_run), console=err_console, transient=True) as live:
        while teleop_run.running:
            if stop.wait(REFRESH_S):
                teleop_run.stop()
            live.update(_table(teleop_run))


def _table(teleop_run: Teleoperation) -> Table:
    from rich.table import Table

    status = teleop_run.status()
    table = Table(
        title=f"{status.state} — {status.elapsed_s:.1f} s at {status.measured_hz:.0f} Hz, "
        f"holds {status.holds} — Enter or Ctrl-C stops"
    )
    for column in ("follower joint", "leader", "target", "follower"):
        table.add_column(column, justify="left" if column == "follower joint" else "right")
    for link in teleop_run.joint_map.links:
        leader = status.leader.get(link.leader)
        target = status.targets.get(link.follower)
        now = status.follower.get(link.follower)
        table.add_row(
            f"{link.follower} ← {link.leader}",
            "-" if leader is None else fmt_deg(leader),
            "-" if target is None else fmt_deg(target),
            "-" if now is None else fmt_deg(now),
        )
    return table
