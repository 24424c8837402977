"""Streaming decoder: bytes in any split -> packets, skipping garbage and resyncing after errors."""

from __future__ import annotations

import logging
from typing import Literal

from poppy_core.errors import ProtocolError
from poppy_core.protocol.base import NEED_MORE, DxlProtocol
from poppy_core.protocol.constants import KINDS
from poppy_core.protocol.packets import InstructionPacket, StatusPacket
from poppy_core.protocol.versions import protocol_for

logger = logging.getLogger(__name__)

Packet = InstructionPacket | StatusPacket
Kind = Literal["instruction", "status"]

_NEED_MORE = NEED_MORE


class PacketDecoder:
    """Turn a byte stream into packets of one protocol and one kind.

    The framing itself is the protocol object's (``DxlProtocol.read_frame``); this class keeps
    the buffer and the counters. Bytes are accepted as they arrive, in any split. Bytes before a
    header are skipped. A packet with a bad checksum/CRC or an impossible length counts as
    corrupt, and the search for the next header restarts one byte after the failed header, so a
    valid packet hidden in garbage is still found. For protocol 2, packets of the other kind
    (e.g. the echo of our own instruction on a half-duplex bus, recognised by its instruction
    byte being or not being 0x55) are dropped and counted in ``ignored_packets``. For protocol 1
    the kind alone decides whether the byte after LEN is an instruction or an error. ``feed``
    never raises.

    Attributes:
        protocol: 1 or 2.
        proto: the protocol object.
        kind: ``"instruction"`` or ``"status"``.
        corrupt_packets: packets dropped for a bad checksum/CRC, length or shape.
        skipped_bytes: bytes discarded outside any well-formed packet.
        ignored_packets: well-formed protocol 2 packets of the other kind.
    """

    def __init__(self, protocol: int | DxlProtocol, kind: Kind) -> None:
        """Create a decoder.

        Args:
            protocol: 1 or 2 (or its protocol object).
            kind: ``"instruction"`` (a device reading the host) or ``"status"`` (the host).

        Raises:
            ProtocolError: unknown protocol or kind.
        """
        proto = protocol_for(protocol)
        if kind not in KINDS:
            raise ProtocolError(f"unknown packet kind {kind!r} (expected one of {KINDS})")
        self.proto = proto
        self.protocol = proto.version
        self.kind: Kind = kind
        self._status = kind == "status"
        self._buf = bytearray()
        self._stop_at = 0
        self.corrupt_packets = 0
        self.skipped_bytes = 0
        self.ignored_packets = 0

    @property
    def pending(self) -> int:
        """Number of bytes held, waiting for the rest of a packet."""
        return len(self._buf)

    def reset(self) -> None:
        """Drop any partial packet (counters are kept)."""
        self._buf.clear()

    def feed(self, data: bytes | bytearray | memoryview) -> list[InstructionPacket | StatusPacket]:
        """Add received bytes and return the packets they complete, in order.

        Args:
            data: the bytes just received (possibly empty).

        Returns:
            The complete packets found; partial data is kept for the next call.
        """
        buf = self._buf
        buf += data
        out: list[Packet] = []
        pos = 0
        step = self.proto.read_frame
        while True:
            consumed = step(self, pos, out)
            if consumed == _NEED_MORE:
                pos = self._stop_at
                break
            pos = consumed
        if pos:
            del buf[:pos]
        return out

    def _skip_to_header(self, pos: int, header: bytes) -> int:
        """Index of the next header at or after ``pos``; skips the bytes before it.

        When no header is there, everything is skipped except a tail that may be the start of
        one, and ``_NEED_MORE`` is returned.
        """
        buf = self._buf
        idx = buf.find(header, pos)
        if idx >= 0:
            self.skipped_bytes += idx - pos
            return idx
        end = len(buf)
        keep = 0
        for size in range(len(header) - 1, 0, -1):
            if end - pos >= size and buf.endswith(header[:size]):
                keep = size
                break
        self.skipped_bytes += end - keep - pos
        return self._wait(end - keep)

    def _corrupt(self, start: int, reason: str) -> int:
        """Count a corrupt packet at ``start`` and resume the search one byte later."""
        self.corrupt_packets += 1
        self.skipped_bytes += 1
        if logger.isEnabledFor(logging.DEBUG):
            logger.debug("protocol %d: corrupt packet dropped (%s)", self.protocol, reason)
        return start + 1

    def _wait(self, keep_from: int) -> int:
        """Stop this feed: bytes from ``keep_from`` stay buffered for the next call."""
        self._stop_at = keep_from
        return _NEED_MORE
