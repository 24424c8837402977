"""Byte transport over pyserial (device, pty, socket://, loop://) reading whole status packets."""

from __future__ import annotations

import errno
import logging
import os
import select
import socket
import sys
import time
from collections import deque
from collections.abc import Callable
from typing import Any

import serial

from poppy_core.bus.ports import DIALOUT_ADVICE
from poppy_core.bus.timing import Deadline
from poppy_core.errors import PortError
from poppy_core.protocol import PacketDecoder, StatusPacket

logger = logging.getLogger(__name__)

# Without a file descriptor to wait on (loop://, Windows), poll the input buffer this often.
POLL_INTERVAL_S = 0.0002
_READ_CHUNK = 4096


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


class Transport:
    """A serial line that writes instruction bytes and reads decoded status packets.

    Opens ``serial.serial_for_url(port, baudrate)``, so it works with a device path
    (``/dev/ttyUSB0``, ``COM3``), a pty path, ``socket://host:port`` or ``loop://``. Reads never
    block past the given deadline: it waits on the port's file descriptor when there is one and
    polls ``in_waiting`` otherwise.

    Attributes:
        port: the device path or URL.
    """

    def __init__(
        self, port: str, baudrate: int = 1_000_000, protocol: int = 1, *, exclusive: bool = True
    ) -> None:
        """Open the port.

        Args:
            port: device path or pyserial URL.
            baudrate: line speed in bit/s.
            protocol: Dynamixel protocol of the status packets to decode (1 or 2).
            exclusive: lock a device path against other programs (POSIX ``flock``).

        Raises:
            PortError: the port is missing, busy or not accessible.
        """
        self.port = port
        self._decoder = PacketDecoder(protocol, "status")
        self._packets: deque[StatusPacket] = deque()
        self.bytes_received = 0
        """Bytes read from the line since the port was opened."""
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

    # -- configuration ------------------------------------------------------------------------

    @property
    def baudrate(self) -> int:
        """Current line speed in bit/s."""
        return int(self._serial.baudrate)

    def set_baudrate(self, baudrate: int) -> None:
        """Change the line speed and drop any received bytes.

        Raises:
            PortError: the OS refused the rate.
        """
        try:
            self._serial.baudrate = baudrate
        except (serial.SerialException, OSError, ValueError) as exc:
            raise PortError(
                f"cannot set {self.port} to {baudrate} bps: {exc}", port=self.port
            ) from exc
        self.reset_input_buffer()

    @property
    def protocol(self) -> int:
        """Protocol of the status packets being decoded."""
        return self._decoder.protocol

    @protocol.setter
    def protocol(self, protocol: int) -> None:
        if protocol != self._decoder.protocol:
            self._decoder = PacketDecoder(protocol, "status")
            self._packets.clear()

    @property
    def corrupt_packets(self) -> int:
        """Corrupt status packets seen since the decoder was created."""
        return self._decoder.corrupt_packets

    @property
    def skipped_bytes(self) -> int:
        """Bytes discarded outside any well-formed status packet."""
        return self._decoder.skipped_bytes

    @property
    def is_open(self) -> bool:
        """True until ``close``."""
        return bool(self._serial.is_open)

    # -- I/O --------------------------------------------------------------------------------------

    def write(self, data: bytes) -> None:
        """Send bytes on the line.

        Raises:
            PortError: the port went away (adapter unplugged, server closed).
        """
        try:
            self._serial.write(data)
        except (serial.SerialException, OSError) as exc:
            raise PortError(f"lost {self.port} while writing: {exc}", port=self.port) from exc

    def _read_available(self, wait_s: float | None) -> bytes:
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

    def read_packet(
        self,
        deadline: Deadline,
        *,
        grace_s: float = 0.0,
        give_up: Callable[[], bool] | None = None,
    ) -> StatusPacket | None:
        """Return the next complete status packet, or None when the deadline passes first.

        Args:
            deadline: when to give up.
            grace_s: once bytes arrive without completing a packet, the deadline is pushed to
                at least this long after their arrival (a reply that has started is not cut).
            give_up: checked after bytes arrive without a packet; True stops waiting now (the
                reply came but was garbled: no point waiting out the deadline).

        Raises:
            PortError: the port went away.
        """
        while True:
            if self._packets:
                return self._packets.popleft()
            data = self._read_available(deadline.time_left())
            if data:
                self._feed(data)
                if not self._packets:
                    if give_up is not None and give_up():
                        return None
                    if grace_s > 0:
                        deadline.extend(grace_s)
                continue
            if deadline.expired():
                return None

    def _feed(self, data: bytes) -> None:
        self.bytes_received += len(data)
        for packet in self._decoder.feed(data):
            if isinstance(packet, StatusPacket):
                self._packets.append(packet)

    def drain(self) -> list[StatusPacket]:
        """Decode whatever is already received (without waiting) and start a clean reply.

        Returns:
            Complete status packets that were waiting (late replies), oldest first.
        """
        data = self._read_available(0.0)
        while data:
            self._feed(data)
            data = self._read_available(0.0)
        late = list(self._packets)
        self._packets.clear()
        self._decoder.reset()
        return late

    def reset_input_buffer(self) -> None:
        """Drop every received byte and partial packet."""
        try:
            self._serial.reset_input_buffer()
        except (serial.SerialException, OSError) as exc:
            raise PortError(f"lost {self.port}: {exc}", port=self.port) from exc
        self._packets.clear()
        self._decoder.reset()

    def close(self) -> None:
        """Close the port (idempotent)."""
        if self._serial.is_open:
            self._serial.close()
            logger.debug("closed %s", self.port)

    def __enter__(self) -> Transport:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()
