"""Find who a corrupt instruction packet was meant for, so that motor answers a checksum error."""

from __future__ import annotations

from poppy_core.protocol import DxlProtocol, protocol_for

# Enough history to hold any instruction a test or a robot sends in one go.
_WINDOW = 4096


class CorruptSniffer:
    """Keeps the recent instruction bytes and finds complete frames that fail their check.

    The streaming ``PacketDecoder`` drops corrupt packets and only counts them; a real motor
    still reads the header of such a packet and, if the id is its own, answers with the
    checksum (protocol 1) or CRC (protocol 2) error. This class looks at the same bytes the
    decoder saw to recover ``(id, instruction)`` of those frames.

    Args:
        protocol: 1 or 2 (or its protocol object).
    """

    def __init__(self, protocol: int | DxlProtocol) -> None:
        self.proto = protocol_for(protocol)
        self._buf = bytearray()
        self._base = 0  # stream offset of _buf[0]
        self._reported: set[int] = set()

    def feed(self, data: bytes) -> None:
        """Record bytes just given to the decoder."""
        self._buf += data
        excess = len(self._buf) - _WINDOW
        if excess > 0:
            del self._buf[:excess]
            self._base += excess
            self._reported = {offset for offset in self._reported if offset >= self._base}

    def reset(self) -> None:
        """Forget the history (the decoder was reset)."""
        self._base += len(self._buf)
        self._buf.clear()
        self._reported.clear()

    def corrupt_frames(self, limit: int) -> list[tuple[int, int]]:
        """The newest ``limit`` complete corrupt frames not reported yet, oldest first.

        Returns:
            ``(id, instruction)`` per frame.
        """
        found: list[tuple[int, int, int]] = []
        header = self.proto.header
        buf = self._buf
        start = buf.find(header)
        while start >= 0:
            frame = self._check(start)
            if frame is not None and start + self._base not in self._reported:
                found.append((start + self._base, *frame))
            start = buf.find(header, start + 1)
        chosen = found[-limit:] if limit > 0 else []
        for offset, _, _ in chosen:
            self._reported.add(offset)
        return [(packet_id, instruction) for _, packet_id, instruction in chosen]

    def _check(self, start: int) -> tuple[int, int] | None:
        """``(id, instruction)`` when a complete frame at ``start`` fails its check."""
        return self.proto.corrupt_frame_at(self._buf, start)
