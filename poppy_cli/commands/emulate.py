"""`poppy emulate`: serve virtual Dynamixel motors on a pty or a TCP port until stopped."""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from poppy_cli.options import MAX_BAUD, MIN_BAUD, checked, finite, profile_option
from poppy_cli.output import EXIT_USAGE, err_console, error_line, printable, styled
from poppy_core import checks
from poppy_core.errors import ArgumentError

if TYPE_CHECKING:
    from poppy_cli.commands.emulate_hand import HandCommands, HandJoint
    from poppy_core.emulator import VirtualBus
    from poppy_core.emulator.control import EmulatorControl


def _delay_ms(value: float) -> float:
    """A reply delay or latency in ms, as the emulator's control accepts (0-10000)."""
    from poppy_core.emulator.control import MAX_REPLY_DELAY_MS

    return checks.in_range(value, 0.0, MAX_REPLY_DELAY_MS, unit="ms")


def parse_hostport(text: str) -> tuple[str, int]:
    """Parse HOST:PORT (PORT 0 picks a free port)."""
    host, sep, port_text = text.rpartition(":")
    try:
        if not sep or not port_text.isdigit():
            raise ValueError(port_text)
        port = checks.count(int(port_text), 0, 65535, "port")  # int() refuses 5000 digits
    except (ValueError, ArgumentError):
        raise typer.BadParameter(
            f"{text!r} is not HOST:PORT with a port in 0-65535, e.g. 127.0.0.1:4000"
        ) from None
    return host or "127.0.0.1", port


def emulate(
    profile: str | None = profile_option(
        "Robot profile: ergo-jr (6 XL-320, ids 1-6), torso, humanoid."
    ),
    motors: str | None = typer.Option(
        None, "--motors", "-m", help="Models and IDs, e.g. MX-28:11-15,AX-12A:36-37."
    ),
    protocol: int | None = typer.Option(
        None, "--protocol", min=1, max=2, help="Protocol (default: the models')."
    ),
    baud: int | None = typer.Option(
        None, "--baud", "-b", help="Baud rate (default 1000000).", min=MIN_BAUD, max=MAX_BAUD
    ),
    pty: bool = typer.Option(False, "--pty", help="Serve on a pseudo-terminal (the default)."),
    tcp: str | None = typer.Option(
        None, "--tcp", help="Serve on TCP HOST:PORT instead (port 0: any free port)."
    ),
    wire_timing: bool = typer.Option(
        False, "--wire-timing", help="Delay replies as a real wire does (10 bits/byte)."
    ),
    latency_ms: float = typer.Option(
        0.0,
        "--latency-ms",
        min=0.0,
        callback=checked(_delay_ms),
        help="Adapter (USB) latency added to replies, in ms.",
    ),
    usb2ax: bool = typer.Option(
        False, "--usb2ax", help="Act as a USB2AX adapter (answers protocol 1 SYNC_READ 0x84)."
    ),
    link: list[Path] | None = typer.Option(
        None,
        "--link",
        help="Keep this symlink pointing at the pty (one per bus, in order); it survives `lose`.",
    ),
    corrupt: float = typer.Option(
        0.0,
        "--corrupt",
        min=0.0,
        max=1.0,
        callback=finite,
        help="Fault: probability that a reply byte is flipped.",
    ),
    drop: float = typer.Option(
        0.0,
        "--drop",
        min=0.0,
        max=1.0,
        callback=finite,
        help="Fault: probability that a reply is lost.",
    ),
    delay_ms: float = typer.Option(
        0.0,
        "--delay-ms",
        min=0.0,
        callback=checked(_delay_ms),
        help="Fault: extra delay added to every reply, in ms.",
    ),
    unplug: list[str] | None = typer.Option(
        None,
        "--unplug",
        metavar="ID@T[+D]",
        help="Fault: unplug motor ID T seconds after start (for D seconds). Repeatable.",
    ),
    control: bool = typer.Option(
        False,
        "--control",
        help="Read fault and hand commands from stdin, one per line (`help` lists them; see docs).",
    ),
    seed: int = typer.Option(0, "--seed", help="Seed of the fault injection's random numbers."),
) -> None:
    """Serve virtual motors: print the pty path (or socket:// URL), then serve until Ctrl-C."""
    from poppy_cli.commands.emulate_hand import HandCommands, joints_of
    from poppy_core.emulator import Hand, build_bus_from_spec, serve_pty, serve_tcp
    from poppy_core.emulator.control import ControlError, EmulatorControl, ScheduledUnplug

    if (profile is None) == (motors is None):
        error_line("give either --profile NAME or --motors MODEL:IDS (e.g. --motors XL-320:1-6)")
        raise typer.Exit(EXIT_USAGE)
    if pty and tcp:
        error_line("give either --pty or --tcp, not both")
        raise typer.Exit(EXIT_USAGE)
    try:
        scheduled = [ScheduledUnplug.parse(text) for text in unplug or []]
    except ControlError as exc:
        error_line(f"--unplug: {exc}")
        raise typer.Exit(EXIT_USAGE) from None
    if link and tcp:
        error_line("--link names a pty: it cannot be used with --tcp")
        raise typer.Exit(EXIT_USAGE)
    options: dict[str, object] = {
        "wire_timing": wire_timing,
        "latency_s": latency_ms / 1000.0,
        "seed": seed,
    }
    buses: list[tuple[str, VirtualBus]]
    joints: dict[str, HandJoint] = {}
    if profile is not None:
        from poppy_core.robot.factory import virtual_buses
        from poppy_core.robot.profiles import load_profile

        config = load_profile(profile)
        joints = joints_of(config)
        # motors as they come from the factory (return delay 500 µs), as on a new robot
        found = virtual_buses(
            config, baudrate=baud, set_up=False, adapter="usb2ax" if usb2ax else None, **options
        )
        buses = list(found.items())
        if protocol is not None and any(b.protocol != protocol for _, b in buses):
            error_line(f"profile {profile} speaks protocol {buses[0][1].protocol}, not {protocol}")
            raise typer.Exit(EXIT_USAGE)
    else:
        assert motors is not None
        adapter = "usb2ax" if usb2ax else "u2d2"
        bus = build_bus_from_spec(
            motors, protocol=protocol, baudrate=baud or 1_000_000, adapter=adapter, **options
        )
        buses = [("bus", bus)]
    links = list(link or [])
    if links and len(links) != len(buses):
        error_line(f"give one --link per bus: this robot has {len(buses)} ({len(links)} given)")
        raise typer.Exit(EXIT_USAGE)
    for _, bus in buses:
        bus.corrupt_rate, bus.drop_rate, bus.extra_delay_s = corrupt, drop, delay_ms / 1000.0
    hostport = parse_hostport(tcp) if tcp else None
    # Handlers go in before the URL is printed: a client may stop us as soon as it reads it.
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    servers = []
    faults = None
    hand = Hand(*(bus for _, bus in buses))
    try:
        for index, (_name, bus) in enumerate(buses):
            if hostport is None:
                servers.append(serve_pty(bus, links[index] if links else None))
            else:
                host, port = hostport
                servers.append(serve_tcp(bus, host, port + index if port else 0))
        faults = EmulatorControl({name: s for (name, _), s in zip(buses, servers, strict=True)})
        try:
            faults.schedule(scheduled)
        except ControlError as exc:
            error_line(f"--unplug: {exc}")
            raise typer.Exit(EXIT_USAGE) from None
        for index, server in enumerate(servers):
            sys.stdout.write(f"{printable(str(links[index]) if links else server.url)}\n")
        sys.stdout.flush()
        for (name, bus), server in zip(buses, servers, strict=True):
            ids = ", ".join(str(m.id) for m in bus.motors)
            err_console.print(
                styled(
                    "[green]serving[/] {}",
                    f"{name}: {len(bus.motors)} {bus.motors[0].model.name}"
                    f"{'…' if len({m.model.name for m in bus.motors}) > 1 else ''} "
                    f"(ids {ids}) protocol {bus.protocol} at {bus.baudrate} bps on {server.url}"
                    " — Ctrl-C to stop",
                )
            )
        if control:
            _read_commands(faults, HandCommands(hand, joints), stop)
        while not stop.wait(0.5):
            pass
    finally:
        hand.close()
        if faults is not None:
            faults.close()
        for server in servers:
            server.stop()


def _read_commands(faults: EmulatorControl, hand: HandCommands, stop: threading.Event) -> None:
    """Run fault and hand commands read from stdin, one per line, in a thread (answers on
    stderr)."""
    from poppy_cli.commands import emulate_hand
    from poppy_core.emulator.control import ControlError

    if sys.stdin.isatty():
        err_console.print(
            "commands: type `help` (unplug 3 · lose 2 · drop 0.01 · move 3 30 --over 2 · where …)"
        )

    def execute(line: str) -> str:
        words = line.split()
        if words and words[0].lower() in emulate_hand.WORDS:
            return hand.execute(words[0].lower(), words[1:])
        answer = faults.execute(line)
        return f"{answer}\n{emulate_hand.HELP}" if words and words[0].lower() == "help" else answer

    def run() -> None:
        for line in sys.stdin:
            if stop.is_set():
                return
            try:
                answer = execute(line)
            except ControlError as exc:
                error_line(str(exc))
                continue
            if answer:
                err_console.print(answer, markup=False, highlight=False)

    threading.Thread(target=run, name="emulator commands", daemon=True).start()
