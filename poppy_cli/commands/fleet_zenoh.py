"""`poppy fleet list/status/run/play/stop`: the robots served with `poppy serve --zenoh`, together.

Commands reach the robots on Zenoh (`--zenoh-connect ENDPOINT` as `poppy serve` says it, or
`--connect`; else POPPY_ZENOH_CONNECT, else a router or robot on tcp/127.0.0.1:7447); `run`,
`play` and `stop` go to `--all` robots or `--robots a,b` and carry a shared start time, so the
robots start within a sync period. With `--token` every command is signed, never sent in clear.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli.options import JsonOpt, finite
from poppy_cli.output import EXIT_FAILURE, EXIT_USAGE, console, error_line, print_json
from poppy_core.checks import MAX_DURATION_S

if TYPE_CHECKING:
    from poppy_core.remote.zenoh_fleet import Fleet, Outcome

ConnectOpt = typer.Option(
    None,
    "--zenoh-connect",
    "--connect",
    help="A Zenoh peer or router to connect to, e.g. tcp/192.168.1.10:7447 (repeat it). "
    "Default: POPPY_ZENOH_CONNECT, else tcp/127.0.0.1:7447.",
)
ConfigOpt = typer.Option(
    None,
    "--zenoh-config",
    exists=True,
    dir_okay=False,
    help="Zenoh's own JSON5 configuration (TLS, access control).",
)
ScoutOpt = typer.Option(
    False, "--zenoh-scout", help="Find the robots by multicast scouting on the LAN."
)
AllOpt = typer.Option(False, "--all", help="Every robot of the fleet.")
RobotsOpt = typer.Option(None, "--robots", help="These robots, comma-separated: a,b.")
TokenOpt = typer.Option(
    None, "--token", envvar="POPPY_TOKEN", help="The robots' token (poppy serve --token)."
)
LeadOpt = typer.Option(
    None,
    "--lead",
    min=0.0,
    max=30.0,
    callback=finite,
    help="Seconds between the command and the shared start (default: the slowest robot's "
    "round trip times 3, at least 0.3). A robot the command reaches late starts at once and "
    "says how late.",
)


def _fleet(
    connect: list[str] | None, config: Path | None, scout: bool, token: str | None = None
) -> Fleet:
    from poppy_core.errors import ConfigError
    from poppy_core.remote.zenoh_client import client_settings
    from poppy_core.remote.zenoh_fleet import Fleet

    try:
        return Fleet(client_settings(tuple(connect or ()), config, scout), token=token)
    except ConfigError as exc:
        error_line(str(exc))
        raise typer.Exit(EXIT_USAGE) from None


def fleet_list(
    connect: list[str] | None = ConnectOpt,
    zenoh_config: Path | None = ConfigOpt,
    zenoh_scout: bool = ScoutOpt,
    json_output: bool = JsonOpt,
) -> None:
    """The robots on Zenoh: name, creature, motors, health, host and endpoints."""
    with _fleet(connect, zenoh_config, zenoh_scout) as fleet:
        names = fleet.names()
        described = fleet.describe(names)
    rows = [_row(name, described.get(name)) for name in names]
    if json_output:
        print_json(rows)
        return
    if not rows:
        console.print(
            "no robot on Zenoh (check --zenoh-connect; robots need `poppy serve --zenoh`)"
        )
        return
    from rich.table import Table

    table = Table("name", "creature", "motors", "health", "host", "endpoints")
    for row in rows:
        table.add_row(
            row["name"],
            row["creature"],
            str(row["motors"]),
            row["health"],
            row["host"],
            ", ".join(row["endpoints"]),
        )
    console.print(table)


def _row(name: str, description: dict[str, Any] | None) -> dict[str, Any]:
    if description is None:
        return {
            "name": name,
            "creature": "",
            "motors": 0,
            "health": "no answer",
            "host": "",
            "endpoints": [],
        }
    health = description.get("health", {})
    offline = health.get("offline", [])
    trouble = f"offline: {', '.join(offline)}" if offline else "bus trouble"
    return {
        "name": name,
        "creature": str(description.get("creature", "")),
        "motors": len(description.get("motors", [])),
        "health": "ok" if health.get("ok") else trouble,
        "host": str(description.get("host", "")),
        "endpoints": list(description.get("endpoints", [])),
    }


def fleet_status(
    connect: list[str] | None = ConnectOpt,
    zenoh_config: Path | None = ConfigOpt,
    zenoh_scout: bool = ScoutOpt,
    watch: bool = typer.Option(False, "--watch", "-w", help="Keep refreshing until Ctrl-C."),
) -> None:
    """One table of every robot: health, state rate and each motor's position."""
    from rich.live import Live

    from poppy_core.zenoh_wire import RobotState

    states: dict[str, RobotState] = {}
    health: dict[str, dict[str, Any]] = {}
    present: dict[str, bool] = {}
    came = threading.Event()  # set by each message: the wait below looks again

    def heard(into: dict[str, Any]) -> Callable[[str, Any], None]:
        def put(name: str, value: Any) -> None:
            into[name] = value
            came.set()

        return put

    with _fleet(connect, zenoh_config, zenoh_scout) as fleet:
        fleet.on_presence(heard(present))
        fleet.on_state(heard(states))
        fleet.on_health(heard(health))
        if not watch:
            _await_each(fleet, came, present, lambda: [health, states])
            console.print(_status_table(present, states, health))
            return
        try:
            with Live(_status_table(present, states, health), console=console) as live:
                while True:
                    time.sleep(0.2)
                    live.update(_status_table(present, states, health))
        except KeyboardInterrupt:
            pass


def _await_each(
    fleet: Fleet,
    came: threading.Event,
    present: dict[str, bool],
    seen: Callable[[], list[dict[str, Any]]],
) -> None:
    """Wait until each robot here (``fleet.names()`` and those ``present`` says came) has
    sent its health and a state (``seen``): as soon as they came, or after a health period
    and the fleet's measured answer time (``Fleet.answer_limit_s``), whichever is first: a
    robot still silent shows ``?``, and a network with no robot is waited for that long."""
    from poppy_core.server.zenoh.robot_node import HEALTH_PERIOD_S

    names = set(fleet.names())
    end = time.monotonic() + HEALTH_PERIOD_S + fleet.answer_limit_s(sorted(names))
    while True:
        wanted = names | {name for name, alive in dict(present).items() if alive}
        if wanted and all(name in got for name in wanted for got in seen()):
            return
        left = end - time.monotonic()
        if left <= 0:
            return
        came.wait(left)
        came.clear()


def _status_table(
    present: dict[str, bool], states: dict[str, Any], health: dict[str, dict[str, Any]]
) -> Any:
    from rich.table import Table

    from poppy_cli.output import fmt_deg

    table = Table("robot", "health", "state Hz", "age", "motors (°)")
    now = time.time()
    for name in sorted(n for n, alive in present.items() if alive):
        state = states.get(name)
        data = health.get(name, {})
        ok = data.get("ok")
        verdict = "?" if ok is None else "ok" if ok else "offline: " + ", ".join(data["offline"])
        if state is None:
            table.add_row(name, verdict, "", "", "")
            continue
        motors = " ".join(
            f"{m}:{fmt_deg(v['present_position'], 1.0, '')}{'' if v['online'] else '!'}"
            if v["present_position"] is not None
            else f"{m}:-"
            for m, v in state.motors.items()
        )
        age = f"{max(0.0, now - state.stamp) * 1000:.0f} ms"
        table.add_row(name, verdict, str(data.get("state_hz", "")), age, motors)
    return table


def _wanted(all_robots: bool, robots: str | None) -> list[str] | None:
    """The robots of ``--robots a,b`` (None for ``--all``), checked before connecting: a usage
    error when neither or both are given, or a name is no robot name (``checks.robot_name``:
    ``Poppy`` is ``poppy``)."""
    from poppy_core.checks import robot_name
    from poppy_core.errors import ArgumentError

    if all_robots == bool(robots):
        error_line("name the robots: --all, or --robots a,b")
        raise typer.Exit(EXIT_USAGE)
    if all_robots:
        return None
    try:
        names = [robot_name(n, "--robots") for n in (robots or "").split(",") if n.strip()]
    except ArgumentError as exc:
        error_line(str(exc))
        raise typer.Exit(EXIT_USAGE) from None
    if not names:
        error_line("name the robots: --all, or --robots a,b")
        raise typer.Exit(EXIT_USAGE)
    return names


def _targets(fleet: Fleet, wanted: list[str] | None) -> list[str]:
    """``wanted``, or every robot on Zenoh for ``--all`` (an error when there is none)."""
    if wanted is not None:
        return wanted
    names = fleet.names()
    if not names:
        error_line("no robot on Zenoh (check --zenoh-connect; robots need `poppy serve --zenoh`)")
        raise typer.Exit(EXIT_FAILURE)
    return names


def _report(outcomes: list[Outcome], what: str, json_output: bool) -> None:
    if json_output:
        print_json(
            [
                {
                    "name": o.name,
                    "ok": o.ok,
                    "status": o.status,
                    "message": o.message,
                    "late_s": o.late_s,
                }
                for o in outcomes
            ]
        )
    else:
        for outcome in outcomes:
            if outcome.ok and outcome.late_s > 0:
                console.print(
                    f"{outcome.name}: {what}, {outcome.late_s:.2f} s late (the command came "
                    "after the shared start: it started at once; --lead S gives more time)"
                )
            elif outcome.ok:
                console.print(f"{outcome.name}: {what}")
            else:
                error_line(f"{outcome.name}: {outcome.message}")
    if not all(o.ok for o in outcomes):
        raise typer.Exit(EXIT_FAILURE)


def fleet_run(
    primitive: str = typer.Argument(..., help="The primitive to start (e.g. dance)."),
    all_robots: bool = AllOpt,
    robots: str | None = RobotsOpt,
    connect: list[str] | None = ConnectOpt,
    zenoh_config: Path | None = ConfigOpt,
    zenoh_scout: bool = ScoutOpt,
    token: str | None = TokenOpt,
    lead: float | None = LeadOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Start a primitive on the robots, all at the same time."""
    wanted = _wanted(all_robots, robots)
    with _fleet(connect, zenoh_config, zenoh_scout, token) as fleet:
        names = _targets(fleet, wanted)
        path = f"/api/v1/primitives/{_quoted(primitive)}/start"
        outcomes = fleet.command(names, "POST", path, lead_s=lead)
    _report(outcomes, f"{primitive} started", json_output)


def fleet_play(
    move: str = typer.Argument(..., help="The move to play (from each robot's library)."),
    all_robots: bool = AllOpt,
    robots: str | None = RobotsOpt,
    connect: list[str] | None = ConnectOpt,
    zenoh_config: Path | None = ConfigOpt,
    zenoh_scout: bool = ScoutOpt,
    token: str | None = TokenOpt,
    ramp: float | None = typer.Option(
        None,
        "--ramp",
        min=0.0,
        max=MAX_DURATION_S,
        callback=finite,
        help="Seconds to reach the first frame, the same on every robot: they play in phase "
        "wherever each one is (default: each its own, from its distance).",
    ),
    lead: float | None = LeadOpt,
    json_output: bool = JsonOpt,
) -> None:
    """Play a move on the robots, all starting at the same time."""
    wanted = _wanted(all_robots, robots)
    body: dict[str, Any] = {"speed": 1.0, "backwards": False}
    if ramp is not None:
        body["ramp_s"] = ramp
    with _fleet(connect, zenoh_config, zenoh_scout, token) as fleet:
        names = _targets(fleet, wanted)
        path = f"/api/v1/moves/{_quoted(move)}/play"
        outcomes = fleet.command(names, "POST", path, body, lead_s=lead)
    _report(outcomes, f"playing {move}", json_output)


def fleet_stop(
    all_robots: bool = AllOpt,
    robots: str | None = RobotsOpt,
    connect: list[str] | None = ConnectOpt,
    zenoh_config: Path | None = ConfigOpt,
    zenoh_scout: bool = ScoutOpt,
    token: str | None = TokenOpt,
    json_output: bool = JsonOpt,
) -> None:
    """The Stop button of every robot named: primitives and moves stopped, motors held."""
    wanted = _wanted(all_robots, robots)
    with _fleet(connect, zenoh_config, zenoh_scout, token) as fleet:
        names = _targets(fleet, wanted)
        outcomes = fleet.command(
            names, "POST", "/api/v1/web/stop", {"then": "hold"}, together=False
        )
    _report(outcomes, "stopped, motors held", json_output)


def _quoted(name: str) -> str:
    from urllib.parse import quote

    return quote(name, safe="")


def register(app: typer.Typer) -> None:
    """Add list, status, run, play and stop to the `poppy fleet` group."""
    app.command("list")(fleet_list)
    app.command("status")(fleet_status)
    app.command("run")(fleet_run)
    app.command("play")(fleet_play)
    app.command("stop")(fleet_stop)
