"""Bus layer: transports, ``DxlBus`` transactions, port listing, scanning and motor setup."""

from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.dxlio import Dxl320IO, DxlIO, get_available_ports
from poppy_core.bus.ports import (
    KNOWN_ADAPTERS,
    PortInfo,
    describe_ports,
    latency_advice,
    list_ports,
    port_info,
    read_ftdi_latency_ms,
    recognise_adapter,
)
from poppy_core.bus.replies import is_alarm_only
from poppy_core.bus.results import BusStats, FoundMotor, PingResult, ScanProgress, SetupResult
from poppy_core.bus.scan import find_bus, find_port, scan
from poppy_core.bus.serial_line import Line, LineOpener, SerialLine, open_line, register_scheme
from poppy_core.bus.setup import (
    change_baudrate,
    change_id,
    identify,
    locate,
    reboot,
    set_angle_limits,
    set_return_delay,
    wait_for_answer,
)
from poppy_core.bus.setup_reset import factory_reset, reset_motor
from poppy_core.bus.timing import Deadline, LinkTiming, default_latency_s, is_virtual_port
from poppy_core.bus.transport import Transport, port_error
from poppy_core.models.xl320 import XL320LEDColors  # pypot.dynamixel.conversion's name

__all__ = [
    "KNOWN_ADAPTERS",
    "BusStats",
    "Deadline",
    "Dxl320IO",
    "DxlBus",
    "DxlIO",
    "FoundMotor",
    "Line",
    "LineOpener",
    "LinkTiming",
    "PingResult",
    "PortInfo",
    "ScanProgress",
    "SerialLine",
    "SetupResult",
    "Transport",
    "XL320LEDColors",
    "change_baudrate",
    "change_id",
    "default_latency_s",
    "describe_ports",
    "factory_reset",
    "find_bus",
    "find_port",
    "get_available_ports",
    "identify",
    "is_alarm_only",
    "is_virtual_port",
    "latency_advice",
    "list_ports",
    "locate",
    "open_line",
    "port_error",
    "port_info",
    "read_ftdi_latency_ms",
    "reboot",
    "recognise_adapter",
    "register_scheme",
    "reset_motor",
    "scan",
    "set_angle_limits",
    "set_return_delay",
    "wait_for_answer",
]
