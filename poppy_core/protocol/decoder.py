"""Streaming decoder: bytes in any split -> packets, skipping garbage and resyncing after errors."""

from __future__ import annotations

import logging
from typing import Literal

from poppy_core.errors import ProtocolError
from poppy_core.protocol.constants import (
    BROADCAST_ID,
    KINDS,
    V1_HEADER,
    V2_HEADER,
    V2_MAX_LENGTH,
    Instruction,
)
from poppy_core.protocol.encoding import check_protocol
from poppy_core.protocol.packets import InstructionPacket, StatusPacket
from poppy_core.protocol.v2 import crc16, unstuff

logger = logging.getLogger(__name__)

Packet = InstructionPacket | StatusPacket
Kind = Literal["instruction", "status"]

_STATUS = int(Instruction.STATUS)
_NEED_MORE = -1
_PATTERN = b"\xff\xff\xfd"


class PacketDecoder:
    """Turn a byte stream into packets of one protocol and one kind.

    Bytes are accepted as they arrive, in any split. Bytes before a header are skipped. A packet
    with a bad checksum/CRC or an impossible length counts as corrupt, and the search for the
    next header restarts one byte after the failed header, so a valid packet hidden in garbage is
    still found. For protocol 2, packets of the other kind (e.g. the echo of our own instruction
    on a half-duplex bus, recognised by its instruction byte being or not being 0x55) are dropped
    and counted in ``ignored_packets``. For protocol 1 the kind alone decides whether the byte
    after LEN is an instruction or an error. ``feed`` never raises.

    Attributes:
        protocol: 1 or 2.
        kind: ``"instruction"`` or ``"status"``.
        corrupt_packets: packets dropped for a bad checksum/CRC, length or shape.
        skipped_bytes: bytes discarded outside any well-formed packet.
        ignored_packets: well-formed protocol 2 packets of the other kind.
    """

    def __init__(self, protocol: int, kind: Kind) -> None:
        """Create a decoder.

        Args:
            protocol: 1 or 2.
            kind: ``"instruction"`` (a device reading the host) or ``"status"`` (the host).

        Raises:
            ProtocolError: unknown protocol or kind.
        """
        check_protocol(protocol)
        if kind not in KINDS:
            raise ProtocolError(f"unknown packet kind {kind!r} (expected one of {KINDS})")
        self.protocol = protocol
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
        step = self._step_v1 if self.protocol == 1 else self._step_v2
        while True:
            consumed = step(pos, out)
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

    def _step_v1(self, pos: int, out: list[Packet]) -> int:
        buf = self._buf
        start = self._skip_to_header(pos, V1_HEADER)
        if start == _NEED_MORE:
            return _NEED_MORE
        if len(buf) < start + 4:
            return self._wait(start)
        packet_id = buf[start + 2]
        if packet_id == 0xFF:
            # FF FF FF: the real header starts one byte later.
            self.skipped_bytes += 1
            return start + 1
        length = buf[start + 3]
        if length < 2:
            return self._corrupt(start, f"LEN {length} < 2")
        end = start + 4 + length
        if len(buf) < end:
            return self._wait(start)
        if ~sum(buf[start + 2 : end - 1]) & 0xFF != buf[end - 1]:
            return self._corrupt(start, "bad checksum")
        code = buf[start + 4]
        params = bytes(buf[start + 5 : end - 1])
        if self._status:
            out.append(StatusPacket(packet_id, code, params))
        else:
            out.append(InstructionPacket(packet_id, code, params))
        return end

    def _step_v2(self, pos: int, out: list[Packet]) -> int:
        buf = self._buf
        start = self._skip_to_header(pos, V2_HEADER)
        if start == _NEED_MORE:
            return _NEED_MORE
        if len(buf) < start + 7:
            return self._wait(start)
        packet_id = buf[start + 4]
        length = buf[start + 5] | (buf[start + 6] << 8)
        if packet_id == 0xFF:
            return self._corrupt(start, "ID 0xFF")
        if length < 3 or length > V2_MAX_LENGTH:
            return self._corrupt(start, f"LEN {length} out of 3..{V2_MAX_LENGTH}")
        end = start + 7 + length
        if self._bad_stuffing(start, end, packet_id):
            return self._corrupt(start, "unstuffed FF FF FD inside the payload")
        if len(buf) < end:
            return self._wait(start)
        crc = buf[end - 2] | (buf[end - 1] << 8)
        if crc16(memoryview(buf)[start : end - 2]) != crc:
            return self._corrupt(start, "bad CRC")
        instruction = buf[start + 7]
        if (instruction == _STATUS) != self._status:
            self.ignored_packets += 1
            return end
        # Stuffing covers INS and everything after it up to the CRC. A status from the broadcast
        # ID is a fast-read reply, positional and never stuffed (see encode_status).
        region = bytes(buf[start + 7 : end - 2])
        if not (self._status and packet_id == BROADCAST_ID):
            region = unstuff(region)
        if not self._status:
            out.append(InstructionPacket(packet_id, instruction, region[1:]))
            return end
        if len(region) < 2:
            self.corrupt_packets += 1
            logger.debug("protocol 2: status packet without an error byte dropped")
            return end
        out.append(StatusPacket(packet_id, region[1], region[2:]))
        return end

    def _bad_stuffing(self, start: int, end: int, packet_id: int) -> bool:
        """True when the payload seen so far holds an FF FF FD not followed by the stuffed FD.

        A genuine stuffed payload never does, so such a header is garbage (often a real header
        sits right there); rejecting it early avoids waiting for bytes of a length that was
        never sent. Fast-read replies (status from the broadcast ID) are not stuffed: skipped.
        """
        buf = self._buf
        region_end = min(end - 2, len(buf))
        first = start + 7
        if packet_id == BROADCAST_ID and (first >= len(buf) or buf[first] == _STATUS):
            return False
        idx = buf.find(_PATTERN, first, region_end)
        while idx >= 0:
            if idx + 3 < region_end and buf[idx + 3] != 0xFD:
                return True
            idx = buf.find(_PATTERN, idx + 4, region_end)
        return False

    def _wait(self, keep_from: int) -> int:
        """Stop this feed: bytes from ``keep_from`` stay buffered for the next call."""
        self._stop_at = keep_from
        return _NEED_MORE
