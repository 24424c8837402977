"""Bytes of Dynamixel protocols 1.0 and 2.0: packets, checksum/CRC, stuffing, instructions, decoder.

Pure functions and one streaming decoder; no I/O, no threads.
"""

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
from poppy_core.protocol.v1 import checksum
from poppy_core.protocol.v2 import crc16, stuff, unstuff

__all__ = [
    "BROADCAST_ID",
    "MAX_ID",
    "USB2AX_ID",
    "V2_MAX_LENGTH",
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
