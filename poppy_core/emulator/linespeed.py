"""Line speed: read the baud rate a client set on a pty, and match it like a UART would."""

from __future__ import annotations

import fcntl
import logging
import struct
import sys
import termios

logger = logging.getLogger(__name__)

# A UART samples each bit in its middle: it still decodes bytes whose rate is a few percent off.
# Dynamixel e-manuals allow a baud rate error below 3 % between controller and servo.
BAUD_TOLERANCE = 0.03

# Linux asm-generic ioctl TCGETS2 = _IOR('T', 0x2A, struct termios2); struct termios2 is
# 4 x tcflag_t, c_line, c_cc[19], c_ispeed, c_ospeed = 44 bytes on x86/arm (asm-generic).
_TCGETS2 = 0x802C542A
_TERMIOS2_FORMAT = "4IB19sII"
_BOTHER = 0o010000
_CBAUD = 0o010017


def _speed_constants() -> dict[int, int]:
    """Map termios ``Bxxx`` constants to rates in bit/s."""
    table: dict[int, int] = {}
    for name in dir(termios):
        if name.startswith("B") and name[1:].isdigit():
            table[int(getattr(termios, name))] = int(name[1:])
    return table


_SPEEDS = _speed_constants()


def baud_matches(line_bps: int, motor_bps: int, tolerance: float = BAUD_TOLERANCE) -> bool:
    """Tell whether a UART at ``motor_bps`` decodes bytes sent at ``line_bps``.

    Args:
        line_bps: rate the bytes are sent at.
        motor_bps: rate the receiver is set to.
        tolerance: largest relative difference still decoded.

    Returns:
        True when the two rates differ by at most ``tolerance`` (relative to the motor's rate).
    """
    if motor_bps <= 0 or line_bps <= 0:
        return False
    return abs(line_bps - motor_bps) <= tolerance * motor_bps


def read_pty_baudrate(fd: int) -> int | None:
    """Read the output baud rate currently set on a terminal (e.g. a pty slave).

    Tries the Linux ``TCGETS2`` ioctl first (it reports any rate, including custom
    ``BOTHER`` ones such as 1 000 000 set through ``TCSETS2``), then falls back on
    ``termios.tcgetattr`` and the standard ``Bxxx`` constants.

    Args:
        fd: an open file descriptor of the terminal.

    Returns:
        The rate in bit/s, or None when it cannot be read.
    """
    if sys.platform.startswith("linux"):
        try:
            raw = fcntl.ioctl(fd, _TCGETS2, bytes(struct.calcsize(_TERMIOS2_FORMAT)))
            fields = struct.unpack(_TERMIOS2_FORMAT, raw)
            cflag, ospeed = int(fields[2]), int(fields[7])
            # The kernel fills c_ospeed for standard Bxxx rates too; BOTHER rates only live there.
            if ospeed:
                return ospeed
            if cflag & _CBAUD != _BOTHER and cflag & _CBAUD in _SPEEDS:
                return _SPEEDS[cflag & _CBAUD]
        except OSError as exc:
            logger.debug("TCGETS2 failed on fd %d: %s", fd, exc)
    try:
        attrs = termios.tcgetattr(fd)
    except termios.error as exc:
        logger.debug("tcgetattr failed on fd %d: %s", fd, exc)
        return None
    ospeed_code = int(attrs[5])
    return _SPEEDS.get(ospeed_code)
