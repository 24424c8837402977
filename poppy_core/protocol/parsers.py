"""Parsers of instruction parameters (for the emulator); bad shapes raise ``ProtocolError``."""

from __future__ import annotations

from poppy_core.errors import ProtocolError
from poppy_core.protocol.base import DxlProtocol, check_ids
from poppy_core.protocol.constants import CLEAR_KEY, CLEAR_MULTI_TURN
from poppy_core.protocol.versions import protocol_for

Proto = int | DxlProtocol


def _size(protocol: Proto) -> int:
    """Width of an address or length field: 1 byte (protocol 1) or 2 (protocol 2)."""
    return protocol_for(protocol).word_size


def _value(params: bytes, offset: int, size: int) -> int:
    return params[offset] if size == 1 else params[offset] | (params[offset + 1] << 8)


_ids = check_ids


def parse_read(protocol: Proto, params: bytes) -> tuple[int, int]:
    """``(address, length)`` of a READ."""
    size = _size(protocol)
    if len(params) != 2 * size:
        raise ProtocolError(f"READ needs {2 * size} parameter bytes, got {len(params)}")
    return _value(params, 0, size), _value(params, size, size)


def parse_write(protocol: Proto, params: bytes) -> tuple[int, bytes]:
    """``(address, data)`` of a WRITE or REG_WRITE."""
    size = _size(protocol)
    if len(params) <= size:
        raise ProtocolError(f"WRITE needs an address and data, got {len(params)} bytes")
    return _value(params, 0, size), bytes(params[size:])


def parse_sync_read(protocol: Proto, params: bytes) -> tuple[int, int, list[int]]:
    """``(address, length, ids)`` of a SYNC_READ, FAST_SYNC_READ or USB2AX 0x84 sync read."""
    size = _size(protocol)
    if len(params) <= 2 * size:
        raise ProtocolError(
            f"SYNC_READ needs an address, a length and IDs, got {len(params)} bytes"
        )
    length = _value(params, size, size)
    if length < 1:
        raise ProtocolError("SYNC_READ data length must be at least 1")
    return _value(params, 0, size), length, _ids(params[2 * size :], "SYNC_READ")


def parse_sync_write(protocol: Proto, params: bytes) -> tuple[int, int, dict[int, bytes]]:
    """``(address, length, {id: data})`` of a SYNC_WRITE."""
    size = _size(protocol)
    if len(params) <= 2 * size:
        raise ProtocolError(f"SYNC_WRITE needs an address, a length and data, got {len(params)}")
    address, length = _value(params, 0, size), _value(params, size, size)
    body = params[2 * size :]
    if length < 1 or len(body) % (length + 1):
        raise ProtocolError(
            f"SYNC_WRITE body of {len(body)} bytes is not a whole number of (ID + {length}) blocks"
        )
    ids = _ids(body[:: length + 1], "SYNC_WRITE")
    data = {
        motor_id: bytes(body[i * (length + 1) + 1 : (i + 1) * (length + 1)])
        for i, motor_id in enumerate(ids)
    }
    return address, length, data


def parse_bulk_read(protocol: Proto, params: bytes) -> list[tuple[int, int, int]]:
    """``[(id, address, length)]`` of a BULK_READ.

    Protocol 1 (e-manual, MX Bulk Read): ``00`` then ``(LEN ID ADDR)`` blocks; protocol 2:
    ``(ID ADDR_L ADDR_H LEN_L LEN_H)`` blocks.
    """
    blocks = protocol_for(protocol).parse_bulk_read(params)
    _ids(bytes(b[0] for b in blocks), "BULK_READ")
    if any(length < 1 for _, _, length in blocks):
        raise ProtocolError("BULK_READ data length must be at least 1")
    return blocks


def parse_bulk_write(params: bytes) -> list[tuple[int, int, bytes]]:
    """``[(id, address, data)]`` of a BULK_WRITE (protocol 2)."""
    blocks: list[tuple[int, int, bytes]] = []
    i = 0
    while i < len(params):
        if i + 5 > len(params):
            raise ProtocolError(f"BULK_WRITE block at byte {i} is truncated")
        length = _value(params, i + 3, 2)
        end = i + 5 + length
        if length < 1 or end > len(params):
            raise ProtocolError(f"BULK_WRITE block at byte {i} has a bad length {length}")
        blocks.append((params[i], _value(params, i + 1, 2), bytes(params[i + 5 : end])))
        i = end
    if not blocks:
        raise ProtocolError("BULK_WRITE needs at least one block")
    _ids(bytes(b[0] for b in blocks), "BULK_WRITE")
    return blocks


def parse_factory_reset(protocol: Proto, params: bytes) -> int:
    """Option of a FACTORY_RESET (protocol 1 has none: 0xFF, reset everything)."""
    return protocol_for(protocol).parse_factory_reset(params)


def parse_clear(params: bytes) -> int:
    """Option of a CLEAR (protocol 2); only the multi-turn clear (0x01 + 'DXL' key) exists."""
    if len(params) != 5 or params[0] != CLEAR_MULTI_TURN or params[1:] != CLEAR_KEY:
        raise ProtocolError(f"CLEAR parameters {params.hex(' ')!r} are not 01 44 58 4C 22")
    return params[0]
