"""Lines the bus opens: ``SerialLine`` over pyserial, or a registered scheme's (``emu://``).

The ``Line`` contract itself lives in the leaf ``poppy_core.line`` (the emulator implements it
without importing this layer).
"""

from __future__ import annotations

import errno
import logging
import os
import select
import socket
import sys
import time
from typing import Any

import serial

from poppy_core.bus.ports import DIALOUT_ADVICE
from poppy_core.errors import PortError
from poppy_core.line import Line, LineOpener, opener_for, register_scheme, scheme_of

__all__ = [
    "Line",
    "LineOpener",
    "SerialLine",
    "open_line",
    "port_error",
    "register_scheme",
    "scheme_of",
]

logger = logging.getLogger(__name__)

# Without a file descriptor to wait on (loop://, Windows), poll the input buffer this often.
POLL_INTERVAL_S = 0.0002
_READ_CHUNK = 4096


def open_line(port: str, baudrate: int = 1_000_000, *, exclusive: bool = True) -> Line:
    """Open ``port``: a registered scheme's line, else a ``SerialLine``.

    Raises:
        PortError: the port is missing, busy or not accessible.
    """
    opener = opener_for(port)
    if opener is not None:
        return opener(port, baudrate)
    return SerialLine(port, baudrate, exclusive=exclusive)


def port_error(port: str, exc: BaseException) -> PortError:
    """Turn a pyserial/OS error raised while opening ``port`` into a one-line ``PortError``.

    Args:
        port: the device path or URL.
        exc: the exception pyserial raised.

    Returns:
        A ``PortError`` whose message says what to do.
    """
    code = getattr(exc, "errno", None)
    text = str(exc)
    lowered = text.lower()
    if code == errno.ENOENT or "no such file" in lowered or "filenotfounderror" in lowered:
        message = f"no such port {port}: plug the adapter or run `poppy ports`"
    elif code == errno.EBUSY or "busy" in lowered or "exclusively lock" in lowered:
        message = (
            f"{port} is busy: another program (another poppy, Dynamixel Wizard, a serial "
            "monitor) has it open; close it and retry"
        )
    elif code in (errno.EACCES, errno.EPERM) or "permission" in lowered or "denied" in lowered:
        if sys.platform.startswith("linux"):
            message = f"permission denied on {port}: {DIALOUT_ADVICE}"
        elif sys.platform.startswith("win"):
            message = f"{port} is busy or access is denied: close any program using it and retry"
        else:
            message = f"permission denied on {port}: check that your user may open it"
    elif "refused" in lowered or code == errno.ECONNREFUSED:
        message = f"nothing answers at {port}: start the emulator or server, or check host and port"
    else:
        message = f"cannot open {port}: {text}"
    return PortError(message, port=port)


class SerialLine:
    """A ``Line`` over ``serial.serial_for_url``: a device path, a pty, ``socket://``, ``loop://``.

    Reads wait on the port's file descriptor when there is one and poll ``in_waiting`` otherwise.
    """

    def __init__(self, port: str, baudrate: int = 1_000_000, *, exclusive: bool = True) -> None:
        """Open the port.

        Args:
            port: device path or pyserial URL.
            baudrate: line speed in bit/s.
            exclusive: lock a device path against other programs (POSIX ``flock``).

        Raises:
            PortError: the port is missing, busy or not accessible.
        """
        self.port = port
        kwargs: dict[str, Any] = {"baudrate": baudrate, "timeout": 0, "do_not_open": True}
        if exclusive and "://" not in port and os.name == "posix":
            kwargs["exclusive"] = True
        try:
            self._serial = serial.serial_for_url(port, **kwargs)
            self._serial.open()
        except (serial.SerialException, OSError, ValueError) as exc:
            raise port_error(port, exc) from exc
        # socket://: send each small instruction at once (Nagle would hold it until the previous
        # segment is acknowledged, up to the peer's delayed-ACK time of ~40 ms).
        sock = getattr(self._serial, "_socket", None)
        if isinstance(sock, socket.socket):
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._fd: int | None = None
        try:
            self._fd = int(self._serial.fileno())
        except (AttributeError, NotImplementedError, OSError, ValueError, TypeError):
            self._fd = None
        logger.debug("opened %s at %d bps (fd %s)", port, baudrate, self._fd)

    @property
    def baudrate(self) -> int:
        """Current line speed in bit/s."""
        return int(self._serial.baudrate)

    def set_baudrate(self, baudrate: int) -> None:
        """Change the line speed.

        Raises:
            PortError: the OS refused the rate.
        """
        try:
            self._serial.baudrate = baudrate
        except (serial.SerialException, OSError, ValueError) as exc:
            raise PortError(
                f"cannot set {self.port} to {baudrate} bps: {exc}", port=self.port
            ) from exc

    @property
    def is_open(self) -> bool:
        """True until ``close``."""
        return bool(self._serial.is_open)

    def write(self, data: bytes) -> None:
        """Send bytes on the line.

        Raises:
            PortError: the port went away (adapter unplugged, server closed).
        """
        try:
            self._serial.write(data)
        except (serial.SerialException, OSError) as exc:
            raise PortError(f"lost {self.port} while writing: {exc}", port=self.port) from exc

    def read(self, wait_s: float | None) -> bytes:
        """Wait up to ``wait_s`` (None: forever) for bytes and return what is there."""
        try:
            if self._fd is not None:
                ready, _, _ = select.select([self._fd], [], [], wait_s)
                if not ready:
                    return b""
                return bytes(self._serial.read(_READ_CHUNK))
            end = None if wait_s is None else time.monotonic() + wait_s
            while True:
                waiting = int(self._serial.in_waiting)
                if waiting:
                    return bytes(self._serial.read(waiting))
                if end is not None and time.monotonic() >= end:
                    return b""
                time.sleep(POLL_INTERVAL_S)
        except (serial.SerialException, OSError) as exc:
            raise PortError(f"lost {self.port} while reading: {exc}", port=self.port) from exc

    def reset_input(self) -> None:
        """Drop every received byte."""
        try:
            self._serial.reset_input_buffer()
        except (serial.SerialException, OSError) as exc:
            raise PortError(f"lost {self.port}: {exc}", port=self.port) from exc

    def close(self) -> None:
        """Close the port (idempotent)."""
        if self._serial.is_open:
            self._serial.close()
            logger.debug("closed %s", self.port)


class AbsentLine:
    """The line of a port not there yet (a robot waiting for its adapter): closed, every I/O
    raises ``PortError`` with the reason it could not be opened; ``DxlBus.reopen`` replaces it."""

    def __init__(self, port: str, baudrate: int, reason: PortError) -> None:
        self.port = port
        self._baudrate = baudrate
        self.reason = reason

    @property
    def baudrate(self) -> int:
        """The rate the port will be opened at."""
        return self._baudrate

    def set_baudrate(self, baudrate: int) -> None:
        """Remember the rate for when the port opens."""
        self._baudrate = baudrate

    @property
    def is_open(self) -> bool:
        """Never."""
        return False

    def write(self, data: bytes) -> None:
        """Raises PortError: the port is not there."""
        raise PortError(str(self.reason), port=self.port)

    def read(self, wait_s: float | None) -> bytes:
        """Raises PortError: the port is not there."""
        raise PortError(str(self.reason), port=self.port)

    def reset_input(self) -> None:
        """Nothing to drop."""

    def close(self) -> None:
        """Nothing to close."""
