"""Transport: whole status packets read off any ``Line`` (pyserial, the in-process link)."""

from __future__ import annotations

import logging
import time
from collections import deque
from collections.abc import Callable, Iterator, Sequence

from poppy_core.bus.serial_line import Line, open_line, port_error
from poppy_core.bus.timing import Deadline
from poppy_core.errors import PortError
from poppy_core.protocol import PacketDecoder, StatusPacket

__all__ = ["Transport", "port_error"]


class Transport:
    """A serial line that writes instruction bytes and reads decoded status packets.

    The bytes travel on a :class:`~poppy_core.line.Line` opened from ``port``: a device
    path (``/dev/ttyUSB0``, ``COM3``), a pty path, ``socket://host:port``, ``loop://`` (pyserial)
    or a registered scheme such as the emulator's in-process ``emu://NAME``. Reads never block
    past the given deadline, whatever the line.

    Attributes:
        port: the device path or URL.
    """

    def __init__(
        self,
        port: str,
        baudrate: int = 1_000_000,
        protocol: int = 1,
        *,
        exclusive: bool = True,
        line: Line | None = None,
    ) -> None:
        """Open the port.

        Args:
            port: device path or URL.
            baudrate: line speed in bit/s.
            protocol: Dynamixel protocol of the status packets to decode (1 or 2).
            exclusive: lock a device path against other programs (POSIX ``flock``).
            line: an open line to use instead of opening ``port`` (closed with the transport).

        Raises:
            PortError: the port is missing, busy or not accessible.
        """
        self.port = port
        self._decoder = PacketDecoder(protocol, "status")
        self._packets: deque[StatusPacket] = deque()
        self.bytes_received = 0
        """Bytes read from the line since the port was opened."""
        self.written_at = float("-inf")
        """``time.monotonic()`` when bytes were last written (-inf: never)."""
        self._line = line if line is not None else open_line(port, baudrate, exclusive=exclusive)

    # -- configuration ------------------------------------------------------------------------

    @property
    def baudrate(self) -> int:
        """Current line speed in bit/s."""
        return self._line.baudrate

    def set_baudrate(self, baudrate: int) -> None:
        """Change the line speed and drop any received bytes.

        Raises:
            PortError: the OS refused the rate.
        """
        self._line.set_baudrate(baudrate)
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
        return self._line.is_open

    # -- I/O --------------------------------------------------------------------------------------

    @property
    def line(self) -> Line:
        """The byte line under this transport."""
        return self._line

    def write(self, data: bytes) -> None:
        """Send bytes on the line.

        Raises:
            PortError: the port went away (adapter unplugged, server closed).
        """
        self._line.write(data)
        self.written_at = time.monotonic()

    def since_written_s(self) -> float:
        """Seconds since bytes were last written (infinite before the first write)."""
        return time.monotonic() - self.written_at

    def _read_available(self, wait_s: float | None) -> bytes:
        """Wait up to ``wait_s`` (None: forever) for bytes and return what is there."""
        return self._line.read(wait_s)

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
        self._line.reset_input()
        self._packets.clear()
        self._decoder.reset()

    def close(self) -> None:
        """Close the port (idempotent)."""
        self._line.close()

    def __enter__(self) -> Transport:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def open_each(
    ports: Sequence[str], unopened: list[PortError] | None = None
) -> Iterator[tuple[str, Transport]]:
    """Each port of ``ports`` opened in turn, with its transport (the caller closes or keeps it).

    A port that cannot be opened is logged and skipped (its error added to ``unopened``), unless
    it is the only one.

    Raises:
        PortError: the only port given cannot be opened.
    """
    for port in ports:
        try:
            transport = Transport(port)
        except PortError as exc:
            if len(ports) == 1:
                raise
            logging.getLogger(__name__).warning("skipping %s: %s", port, exc)
            if unopened is not None:
                unopened.append(exc)
            continue
        yield port, transport
