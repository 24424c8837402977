"""Wire timing: how long bytes take on a UART line, and a precise sleep for physical replies."""

from __future__ import annotations

import time

# A UART frame is 1 start bit, 8 data bits, 1 stop bit (Dynamixel: 8N1, e-manual "Protocol").
BITS_PER_BYTE = 10
# Sleep until this close to a deadline, then spin: time.sleep overshoots by ~50-100 µs on Linux.
SPIN_WINDOW_S = 200e-6


def byte_time_s(baudrate_bps: int) -> float:
    """Time one byte takes on the wire at ``baudrate_bps`` (8N1 framing)."""
    return BITS_PER_BYTE / baudrate_bps


def transfer_time_s(n_bytes: int, baudrate_bps: int) -> float:
    """Time ``n_bytes`` take on the wire at ``baudrate_bps``."""
    return n_bytes * byte_time_s(baudrate_bps)


def sleep_until(deadline: float) -> None:
    """Block until ``time.perf_counter()`` reaches ``deadline``, with ~µs precision.

    Sleeps with the OS timer until ``SPIN_WINDOW_S`` before the deadline, then spins.

    Args:
        deadline: target time on the ``time.perf_counter`` clock.
    """
    remaining = deadline - time.perf_counter()
    if remaining > SPIN_WINDOW_S:
        time.sleep(remaining - SPIN_WINDOW_S)
    while time.perf_counter() < deadline:
        pass


class LineClock:
    """Tracks when instruction bytes finish arriving on a half-duplex line.

    Bytes handed to the emulator at time ``t`` were, on a real line, still being
    transmitted: each takes ``10 / baud`` seconds, and the line carries one byte at a time.
    """

    def __init__(self) -> None:
        self._busy_until = 0.0

    def receive(self, n_bytes: int, received_at: float, baudrate_bps: int) -> float:
        """Account for ``n_bytes`` received at ``received_at``; return when the last one is in."""
        start = max(self._busy_until, received_at)
        self._busy_until = start + transfer_time_s(n_bytes, baudrate_bps)
        return self._busy_until

    def occupy_until(self, t: float) -> None:
        """Mark the line busy (replies being sent) until ``t``."""
        self._busy_until = max(self._busy_until, t)

    def reset(self) -> None:
        """Forget the line history (a new client connected)."""
        self._busy_until = 0.0
