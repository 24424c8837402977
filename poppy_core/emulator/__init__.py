"""Virtual Dynamixel motors that answer like real ones: in process, on a pty or a TCP socket.

Typical use::

    from poppy_core.emulator import build_bus_from_spec, serve_link, serve_pty

    bus = build_bus_from_spec("MX-28:11-15,AX-12A:36-37")
    with serve_link(bus) as server:  # emu://N: a DxlBus in this process
        ...
    with serve_pty(bus) as server:  # /dev/pts/N: any program (pypot, the Dynamixel SDK)
        ...  # open server.url with pyserial / DxlBus
"""

from poppy_core.emulator.bus import ADAPTERS, Adapter, Reply, VirtualBus
from poppy_core.emulator.bus_servers import (
    EmulatorServer,
    Endpoint,
    PtyServer,
    TcpServer,
    serve_pty,
    serve_tcp,
)
from poppy_core.emulator.bus_spec import (
    EmulatorConfig,
    build_bus_from_spec,
    ergo_jr_bus,
    parse_spec,
)
from poppy_core.emulator.faults import FaultInjector, fault_bits
from poppy_core.emulator.hand import Hand
from poppy_core.emulator.linespeed import BAUD_TOLERANCE, baud_matches, read_pty_baudrate
from poppy_core.emulator.link import LinkServer, VirtualLine, serve_link
from poppy_core.emulator.motor import VirtualMotor
from poppy_core.emulator.plant import IdealPlant, Plant
from poppy_core.emulator.wire_timing import byte_time_s, sleep_until, transfer_time_s

__all__ = [
    "ADAPTERS",
    "BAUD_TOLERANCE",
    "Adapter",
    "EmulatorConfig",
    "EmulatorServer",
    "Endpoint",
    "FaultInjector",
    "Hand",
    "IdealPlant",
    "LinkServer",
    "Plant",
    "PtyServer",
    "Reply",
    "TcpServer",
    "VirtualBus",
    "VirtualLine",
    "VirtualMotor",
    "baud_matches",
    "build_bus_from_spec",
    "byte_time_s",
    "ergo_jr_bus",
    "fault_bits",
    "parse_spec",
    "read_pty_baudrate",
    "serve_link",
    "serve_pty",
    "serve_tcp",
    "sleep_until",
    "transfer_time_s",
]
