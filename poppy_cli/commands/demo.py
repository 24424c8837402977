"""`poppy demo`: a virtual Ergo Jr in-process, scanned, read in SI units, then moved."""

from __future__ import annotations

from typing import TYPE_CHECKING

import typer

from poppy_cli.options import sim_option
from poppy_cli.output import console, fmt_value, plain, styled

if TYPE_CHECKING:
    from rich.table import Table

    from poppy_core.robot import Robot

# The choreography: (label, motor name -> degrees, seconds); about 6 s in all.
CHOREOGRAPHY: list[tuple[str, dict[str, float], float]] = [
    ("base turn", {"m1": 45.0}, 1.0),
    ("bow", {"m1": 0.0, "m2": 40.0, "m3": 30.0}, 1.2),
    ("wave up", {"m2": -20.0, "m3": -30.0, "m5": 40.0}, 1.0),
    ("wave", {"m4": 40.0, "m6": -30.0}, 0.6),
    ("wave back", {"m4": -40.0, "m6": 30.0}, 0.6),
    ("back to zero", {f"m{i}": 0.0 for i in range(1, 7)}, 1.4),
]
QUICK_FACTOR = 0.1
# The first-reply floor of the demo's own bus: its motors are an emulator thread of this process,
# which a busy machine runs tens of milliseconds late now and then; it costs nothing while they
# answer (the scan has its own waits).
OWN_EMULATOR_FLOOR_S = 0.5


def demo(
    wire_timing: bool = typer.Option(
        True, "--wire-timing/--no-wire-timing", help="Emulate the wire's timing (1 Mbps)."
    ),
    quick: bool = typer.Option(False, "--quick", help="Play the choreography ten times faster."),
    sim: str | None = sim_option(
        "The dancing robot's servos: --sim (ideal, the default) or --sim mujoco (physics)."
    ),
) -> None:
    """Start a virtual Ergo Jr (six XL-320), scan it, show it, then play a short dance."""
    from rich.table import Table

    from poppy_cli.commands.scan import render_found
    from poppy_core.bus import scan as run_scan
    from poppy_core.bus.dxlbus import DxlBus
    from poppy_core.emulator import ergo_jr_bus, serve_pty
    from poppy_core.models import ServoModel, model_by_name

    virtual = ergo_jr_bus(wire_timing=wire_timing, latency_s=0.001 if wire_timing else 0.0)
    with serve_pty(virtual) as server:
        console.print(
            styled(
                "[bold]Virtual Poppy Ergo Jr[/]: 6 XL-320 on {} (protocol 2, 1 Mbps)", server.url
            )
        )
        with console.status(plain("scanning IDs 0-253 at 1 Mbps, protocol 2…")):
            found = run_scan(server.url, [1_000_000], [2])
        render_found(found)
        table = Table(title="state of the motors found")
        for column in ("id", "position", "temperature", "voltage", "torque", "led"):
            table.add_column(column, justify="right")
        # The motors' other end is a thread of this process: a busy machine runs it late now and
        # then, and a real adapter's 10 ms floor would take a late reply for a missing motor.
        with DxlBus(server.url, 1_000_000, 2, min_timeout_s=OWN_EMULATOR_FLOOR_S) as bus:
            for motor in found:
                if motor.model is None:  # not one of ours: the scan's table shows it
                    continue
                model = model_by_name(motor.model)

                def get(name: str, motor_id: int = motor.id, model: ServoModel = model) -> str:
                    reg = model.register(name)
                    return fmt_value(bus.read_register(motor_id, model, name), reg.unit)

                table.add_row(
                    str(motor.id),
                    get("present_position"),
                    get("present_temperature"),
                    get("present_voltage"),
                    get("torque_enable"),
                    get("led"),
                )
        console.print(table)
    dance(QUICK_FACTOR if quick else 1.0, "mujoco" if sim == "mujoco" else True)
    console.print(
        styled(
            "Next: [bold]poppy emulate --profile ergo-jr[/] serves this robot to other programs; "
            "[bold]poppy scan --port PATH[/] finds its motors; "
            "[bold]poppy robot status --sim --profile ergo-jr[/] shows a virtual robot."
        )
    )


def positions_table(robot: Robot, step: str) -> Table:
    """The motors' positions and goals during the dance."""
    from rich.table import Table

    table = Table(title=f"virtual Ergo Jr dancing: {step}")
    for column in ("motor", "position", "goal"):
        table.add_column(column, justify="left" if column == "motor" else "right")
    for motor in robot.motors:
        table.add_row(
            motor.name,
            fmt_value(round(motor.present_position, 1), "°"),
            fmt_value(round(motor.goal_position, 1), "°"),
        )
    return table


def dance(time_factor: float, sim: bool | str = True) -> None:
    """Build the virtual Ergo Jr robot and play the choreography, showing the positions live.

    Args:
        time_factor: durations are multiplied by it (0.1 plays ten times faster).
        sim: the robot's servos: True (ideal) or ``"mujoco"`` (physics).
    """
    import time

    from rich.live import Live

    from poppy_core import from_profile

    with from_profile("ergo-jr", sim=sim, sensors=False) as robot:  # the dance needs no camera
        robot.compliant = False
        with Live(positions_table(robot, "ready"), console=console, refresh_per_second=10) as live:
            for label, goals, duration_s in CHOREOGRAPHY:
                handle = robot.goto_position(goals, duration_s * time_factor)
                end = time.monotonic() + duration_s * time_factor
                while time.monotonic() < end:
                    live.update(positions_table(robot, label))
                    time.sleep(0.05)
                handle.wait()
            time.sleep(0.1)
            live.update(positions_table(robot, "done"))
        record_and_replay(robot, time_factor)
    console.print()


def record_and_replay(robot: Robot, time_factor: float) -> None:
    """Record the arm moved "by hand" (through the emulator), then replay it and compare."""
    import math
    import time

    from rich.live import Live

    from poppy_core.motion import MovePlayer, MoveRecorder, PlayProgress

    arm = ["m2", "m3", "m5"]
    virtual = next(iter(robot.emulators.values())).bus
    duration_s = max(0.6, 3.0 * time_factor)
    for name in arm:
        robot.motor(name).compliant = True
    time.sleep(0.1)
    console.print(
        styled(
            "[bold]Recording[/] {} for {} s, moved by hand…", ", ".join(arm), f"{duration_s:.1f}"
        )
    )
    with MoveRecorder(robot, 50, arm) as recorder:
        start = time.monotonic()
        while (elapsed := time.monotonic() - start) < duration_s:
            phase = 2 * math.pi * elapsed / duration_s
            for k, name in enumerate(arm):
                hand = 35.0 * math.sin(phase + k * math.pi / 3)
                virtual.motor(robot.motor(name).id).move_by_hand(robot.motor(name).to_motor(hand))
            time.sleep(0.01)
    move = recorder.move
    console.print(f"recorded {len(move.times())} frames at {move.framerate:g} Hz")
    for name in arm:
        robot.motor(name).compliant = False
    gaps: list[float] = []

    def compare(progress: PlayProgress) -> None:
        # past the ramp and the first frames: goals reach the motors one write cycle later
        if progress.phase == "play" and 0.2 < progress.move_t_s < move.duration_s - 0.1:
            at = move.positions_at(progress.move_t_s - 0.04)
            expected = dict(zip(move.motors, at, strict=True))
            gaps.append(max(abs(robot.motor(m).present_position - expected[m]) for m in arm))

    player = MovePlayer(robot, move, on_progress=compare)
    with Live(positions_table(robot, "replay"), console=console, refresh_per_second=10) as live:
        player.start()
        while player.playing:
            live.update(positions_table(robot, "replay"))
            time.sleep(0.02)
        player.wait()
        live.update(positions_table(robot, "replayed"))
    worst = sorted(gaps)[int(0.95 * (len(gaps) - 1))] if gaps else 0.0
    console.print(f"replayed {len(gaps)} frames; 95 % within {worst:.1f}° of the recorded path")
