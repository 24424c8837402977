"""Bytes of Dynamixel protocols 1.0 and 2.0: packets, checksum/CRC, stuffing, instructions, decoder.

One object per protocol (``PROTOCOL_1``, ``PROTOCOL_2``; ``protocol_for(1 | 2)``) holds its sizes,
error layout, codec and capabilities; the functions taking a protocol number delegate to it.
Pure: no I/O, no threads.
"""

from poppy_core.protocol.base import DxlProtocol, ErrorCodes
from poppy_core.protocol.constants import (
    BROADCAST_ID,
    MAX_ID,
    USB2AX_ID,
    V2_MAX_LENGTH,
    Instruction,
)
from poppy_core.protocol.decoder import PacketDecoder
from poppy_core.protocol.encoding import encode_instruction, encode_status
from poppy_core.protocol.fast_sync import encode_fast_sync_status, parse_fast_sync_status
from poppy_core.protocol.instructions import (
    action,
    bulk_read,
    bulk_write,
    clear,
    factory_reset,
    fast_sync_read,
    parse_usb2ax_sync_status,
    ping,
    read,
    reboot,
    reg_write,
    sync_read,
    sync_write,
    usb2ax_sync_status,
    write,
)
from poppy_core.protocol.packets import InstructionPacket, StatusPacket
from poppy_core.protocol.parsers import (
    parse_bulk_read,
    parse_bulk_write,
    parse_clear,
    parse_factory_reset,
    parse_read,
    parse_sync_read,
    parse_sync_write,
    parse_write,
)
from poppy_core.protocol.status import decode_errors
from poppy_core.protocol.v1 import PROTOCOL_1, checksum
from poppy_core.protocol.v2 import PROTOCOL_2, crc16, stuff, unstuff
from poppy_core.protocol.versions import PROTOCOLS_BY_VERSION, protocol_for

__all__ = [
    "BROADCAST_ID",
    "MAX_ID",
    "PROTOCOLS_BY_VERSION",
    "PROTOCOL_1",
    "PROTOCOL_2",
    "USB2AX_ID",
    "V2_MAX_LENGTH",
    "DxlProtocol",
    "ErrorCodes",
    "Instruction",
    "InstructionPacket",
    "PacketDecoder",
    "StatusPacket",
    "action",
    "bulk_read",
    "bulk_write",
    "checksum",
    "clear",
    "crc16",
    "decode_errors",
    "encode_fast_sync_status",
    "encode_instruction",
    "encode_status",
    "factory_reset",
    "fast_sync_read",
    "parse_bulk_read",
    "parse_bulk_write",
    "parse_clear",
    "parse_factory_reset",
    "parse_fast_sync_status",
    "parse_read",
    "parse_sync_read",
    "parse_sync_write",
    "parse_usb2ax_sync_status",
    "parse_write",
    "ping",
    "protocol_for",
    "read",
    "reboot",
    "reg_write",
    "stuff",
    "sync_read",
    "sync_write",
    "unstuff",
    "usb2ax_sync_status",
    "write",
]
