"""Instruction codes, special IDs and size limits of Dynamixel protocols 1.0 and 2.0."""

from __future__ import annotations

from enum import IntEnum


class Instruction(IntEnum):
    """Instruction byte of an instruction packet (e-manual: Protocol 1.0 / 2.0, Instruction)."""

    PING = 0x01
    READ = 0x02
    WRITE = 0x03
    REG_WRITE = 0x04
    ACTION = 0x05
    FACTORY_RESET = 0x06
    REBOOT = 0x08
    CLEAR = 0x10
    STATUS = 0x55
    SYNC_READ = 0x82
    SYNC_WRITE = 0x83
    SYNC_READ_USB2AX = 0x84
    FAST_SYNC_READ = 0x8A
    BULK_READ = 0x92
    BULK_WRITE = 0x93


#: Every motor executes a packet sent to this ID (and none answers, except PING in protocol 2).
BROADCAST_ID = 0xFE
#: Largest ID a single motor may have (0xFD is also the USB2AX adapter's own ID).
MAX_ID = 0xFD
#: ID the USB2AX adapter answers with (USB2AX firmware: advanced_commands.txt).
USB2AX_ID = 0xFD

PROTOCOLS = (1, 2)
KINDS = ("instruction", "status")

# Protocol 1: LEN is one byte and counts INS/ERR + params + checksum.
V1_HEADER = b"\xff\xff"
V1_MAX_PARAMS = 0xFF - 2

# Protocol 2: LEN is two bytes and counts INS (+ ERR) + stuffed params + CRC. The e-manual allows
# up to 0xFFFF but no device buffers that much; this sanity limit lets the decoder give up on a
# garbage length quickly instead of waiting for kilobytes that will never come.
V2_HEADER = b"\xff\xff\xfd\x00"
V2_MAX_LENGTH = 4096

# e-manual (Protocol 2.0, Factory Reset): option byte.
FACTORY_RESET_ALL = 0xFF
FACTORY_RESET_ALL_BUT_ID = 0x01
FACTORY_RESET_ALL_BUT_ID_AND_BAUDRATE = 0x02
FACTORY_RESET_OPTIONS = (
    FACTORY_RESET_ALL,
    FACTORY_RESET_ALL_BUT_ID,
    FACTORY_RESET_ALL_BUT_ID_AND_BAUDRATE,
)

# e-manual (Protocol 2.0, Clear): option 0x01 (multi-turn) followed by the fixed key 'DXL' 0x22.
CLEAR_MULTI_TURN = 0x01
CLEAR_KEY = b"\x44\x58\x4c\x22"
