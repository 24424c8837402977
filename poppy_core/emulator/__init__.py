"""Virtual Dynamixel motors that answer like real ones, served on a pty or a TCP socket.

Typical use::

    from poppy_core.emulator import build_bus_from_spec, serve_pty

    bus = build_bus_from_spec("MX-28:11-15,AX-12A:36-37")
    with serve_pty(bus) as server:
        ...  # open server.url with pyserial / DxlBus
"""

from poppy_core.emulator.bus import ADAPTERS, Adapter, Reply, VirtualBus
from poppy_core.emulator.faults import FaultInjector, fault_bits
from poppy_core.emulator.linespeed import BAUD_TOLERANCE, baud_matches, read_pty_baudrate
from poppy_core.emulator.motor import VirtualMotor
from poppy_core.emulator.plant import IdealPlant, Plant
from poppy_core.emulator.server import EmulatorServer, PtyServer, TcpServer, serve_pty, serve_tcp
from poppy_core.emulator.spec import EmulatorConfig, build_bus_from_spec, ergo_jr_bus, parse_spec
from poppy_core.emulator.timing import byte_time_s, sleep_until, transfer_time_s

__all__ = [
    "ADAPTERS",
    "BAUD_TOLERANCE",
    "Adapter",
    "EmulatorConfig",
    "EmulatorServer",
    "FaultInjector",
    "IdealPlant",
    "Plant",
    "PtyServer",
    "Reply",
    "TcpServer",
    "VirtualBus",
    "VirtualMotor",
    "baud_matches",
    "build_bus_from_spec",
    "byte_time_s",
    "ergo_jr_bus",
    "fault_bits",
    "parse_spec",
    "read_pty_baudrate",
    "serve_pty",
    "serve_tcp",
    "sleep_until",
    "transfer_time_s",
]
