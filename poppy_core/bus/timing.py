"""Physical timing of bus transactions: wire time, reply deadlines, adapter latency defaults.

A transaction's deadline is built from what happens on the wire, not from one flat timeout:

    instruction bytes on the wire (10 bits per byte at the baud rate)
  + the motor's return delay (factory default 500 µs; poppy sets it to 0)
  + status bytes on the wire
  + the adapter's latency (USB: the FTDI latency timer holds received bytes up to that long)
  + a scheduling margin (the OS may run us late): ``MIN_MARGIN_S`` plus ``MARGIN_FRACTION`` of
    the physical time above.

A reply is awaited until the time its last byte can arrive (adapters hand short packets over in
one USB transfer, so the first byte is no earlier than the last). Once bytes are flowing, a
*grace* extension covers the rest of a long reply, and each reply of a multi-reply instruction
extends the wait by the time the next one needs. An absent motor costs one round trip.

Adapter latency defaults (``default_latency_s``):

* a USB FTDI adapter (USB2Dynamixel, U2D2) on Linux: its latency timer read from sysfs
  (``/sys/bus/usb-serial/devices/ttyUSBx/latency_timer``, in ms; the kernel default is 16 ms);
* any other real serial device (USB2AX, CDC-ACM, on-board UART): ``SERIAL_LATENCY_S`` (2 ms);
* a pty, ``socket://``, ``loop://`` or another URL (the emulator, a network bridge):
  ``VIRTUAL_LATENCY_S`` (1 ms).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

from poppy_core import checks
from poppy_core.bus.ports import read_ftdi_latency_ms
from poppy_core.protocol import DxlProtocol, protocol_for

# A UART frame is 1 start bit, 8 data bits, 1 stop bit (e-manual "Protocol 1.0"/"Protocol 2.0":
# asynchronous serial, 8 bit, 1 stop bit, no parity).
BITS_PER_BYTE = 10

# Latency guesses when nothing better is known (see the module docstring).
SERIAL_LATENCY_S = 0.002
VIRTUAL_LATENCY_S = 0.001

# Scheduling margin: a fixed part for the OS waking us late plus a part growing with the wait.
MIN_MARGIN_S = 0.001
# Shortest wait for the first reply of a transaction with motors known to be there (scans use 0).
MIN_REPLY_TIMEOUT_S = 0.010
# Raises that floor (seconds) for motors whose other end the OS may run late: an emulator or a
# network bridge on a busy machine (the test suite sets it from the machine's load). Unset: the
# real adapter's MIN_REPLY_TIMEOUT_S.
REPLY_FLOOR_ENV = "POPPY_REPLY_FLOOR_S"
# A floor past this is a typo, not a slow bridge.
MAX_REPLY_FLOOR_S = 60.0
MARGIN_FRACTION = 0.1

# Quiet time after a search at one rate, before the next: every reply still coming (a slow
# adapter's) arrives in it and is not taken for an answer at the next rate. This many adapter
# latencies, at least SETTLE_MIN_S (the OS may run the other end late).
SETTLE_LATENCIES = 3.0
SETTLE_MIN_S = 0.01

# Silence that must follow two empty broadcast pings before the bus is taken for empty at that
# rate: the replies of a motor whose other end the OS ran late (an emulator on a busy machine, a
# USB adapter held up) arrive in it. This many adapter latencies,
# at least SILENCE_MIN_S (longer than the stalls seen on a loaded machine, 10-30 ms).
SILENCE_LATENCIES = 10.0
SILENCE_MIN_S = 0.05

# Factory return delay of AX/MX/X servos: 250 x 2 µs (e-manual: "Return Delay Time", address 5
# on protocol 1 models, 9 on X series).
DEFAULT_RETURN_DELAY_S = 0.0005


def reply_floor_s() -> float:
    """The shortest wait for a first reply of motors known to be there: ``$POPPY_REPLY_FLOOR_S``
    when set, else ``MIN_REPLY_TIMEOUT_S`` (read at each call: a bus reads it when it opens).

    A floor below ``MIN_REPLY_TIMEOUT_S`` is taken as given (a fast bridge); scans, which mostly
    wait for absent motors, keep their own floor of 0 whatever it says.

    Raises:
        ConfigError: the variable is not a number of seconds from 0 to ``MAX_REPLY_FLOOR_S``.
    """
    return checks.seconds_from_env(
        REPLY_FLOOR_ENV,
        MIN_REPLY_TIMEOUT_S,
        high=MAX_REPLY_FLOOR_S,
        zero=True,
        what="a reply floor",
        example="0.5",
        unset=f"the adapter's {MIN_REPLY_TIMEOUT_S * 1000:g} ms",
    )


def byte_time_s(baudrate: int) -> float:
    """Time one byte takes on the wire at ``baudrate`` bit/s (8N1)."""
    return BITS_PER_BYTE / baudrate


def instruction_size(protocol: int | DxlProtocol, n_params: int) -> int:
    """Bytes of an instruction packet carrying ``n_params`` parameter bytes (before stuffing)."""
    return protocol_for(protocol).instruction_size(n_params)


def status_size(protocol: int | DxlProtocol, n_params: int) -> int:
    """Bytes of a status packet carrying ``n_params`` parameter bytes (before stuffing)."""
    return protocol_for(protocol).status_size(n_params)


def settle_s(latency_s: float) -> float:
    """How long to listen for late replies on an adapter of ``latency_s`` (see above)."""
    return max(SETTLE_MIN_S, SETTLE_LATENCIES * latency_s)


def silence_s(latency_s: float) -> float:
    """How long an empty bus must stay silent on an adapter of ``latency_s`` (see above)."""
    return max(SILENCE_MIN_S, SILENCE_LATENCIES * latency_s)


def scheduling_margin_s(physical_s: float) -> float:
    """Safety margin added to a physical wait of ``physical_s`` seconds for OS scheduling."""
    return MIN_MARGIN_S + MARGIN_FRACTION * physical_s


@dataclass(frozen=True)
class LinkTiming:
    """Timing parameters of one bus: baud rate, return delay and adapter latency.

    Attributes:
        baudrate: line speed in bit/s.
        return_delay_s: how long a motor waits before answering.
        latency_s: adapter latency (time from a byte on the wire to our ``read``).
    """

    baudrate: int
    return_delay_s: float = DEFAULT_RETURN_DELAY_S
    latency_s: float = VIRTUAL_LATENCY_S

    def wire_s(self, n_bytes: int) -> float:
        """Time ``n_bytes`` take on the wire."""
        return n_bytes * byte_time_s(self.baudrate)

    def _with_margin(self, physical_s: float) -> float:
        return physical_s + scheduling_margin_s(physical_s)

    def reply_timeout_s(self, tx_bytes: int, rx_bytes: int | list[int]) -> float:
        """Worst-case time from writing an instruction to holding every expected reply.

        Args:
            tx_bytes: size of the instruction packet.
            rx_bytes: size of the one expected status packet, or the sizes of several replies
                sent one after the other (sync/bulk read), each after its own return delay.

        Returns:
            The timeout in seconds, margin included.
        """
        sizes = [rx_bytes] if isinstance(rx_bytes, int) else rx_bytes
        physical = (
            self.wire_s(tx_bytes)
            + sum(self.return_delay_s + self.wire_s(n) for n in sizes)
            + self.latency_s
        )
        return self._with_margin(physical)

    def grace_s(self, rx_bytes: int) -> float:
        """Time still allowed once reply bytes flow, for ``rx_bytes`` more bytes to arrive."""
        return self._with_margin(self.wire_s(rx_bytes) + self.latency_s)

    def quiet_gap_s(self, rx_bytes: int) -> float:
        """Silence after which no further reply of ``rx_bytes`` bytes can still be coming."""
        return self._with_margin(self.return_delay_s + self.wire_s(rx_bytes) + self.latency_s)


class Deadline:
    """A point in time on the monotonic clock (like pyserial's ``Timeout``).

    ``Deadline(None)`` never expires; ``Deadline(0)`` is already expired.
    """

    def __init__(self, duration_s: float | None) -> None:
        """Start a deadline ``duration_s`` seconds from now (None: never)."""
        self._end: float | None = None if duration_s is None else time.monotonic() + duration_s

    @property
    def infinite(self) -> bool:
        """True for a deadline that never expires."""
        return self._end is None

    def time_left(self) -> float | None:
        """Seconds left, never negative; None for an infinite deadline."""
        if self._end is None:
            return None
        return max(0.0, self._end - time.monotonic())

    def expired(self) -> bool:
        """True once the deadline has passed."""
        return self._end is not None and time.monotonic() >= self._end

    def extend(self, at_least_s: float) -> None:
        """Push the deadline to at least ``at_least_s`` seconds from now (never earlier)."""
        if self._end is not None:
            self._end = max(self._end, time.monotonic() + at_least_s)


def is_virtual_port(port: str) -> bool:
    """Tell whether ``port`` is a URL (socket://, loop://, ...) or a pseudo-terminal."""
    if "://" in port:
        return True
    real = os.path.realpath(port)
    # Linux/BSD ptys live in /dev/pts/N (Unix98) or /dev/ttyp*, macOS in /dev/ttysNNN.
    base = os.path.basename(real)
    return real.startswith("/dev/pts/") or base.startswith(("ttys", "ttyp", "pty"))


def default_latency_s(port: str, *, sysfs_root: str = "/sys") -> float:
    """Pick the adapter latency to assume for ``port`` (see the module docstring).

    Args:
        port: a device path or a pyserial URL.
        sysfs_root: root of the sysfs tree (tests pass a fake one).

    Returns:
        The latency in seconds.
    """
    if is_virtual_port(port):
        return VIRTUAL_LATENCY_S
    latency_ms = read_ftdi_latency_ms(port, sysfs_root=sysfs_root)
    if latency_ms is not None:
        return latency_ms / 1000.0
    return SERIAL_LATENCY_S
