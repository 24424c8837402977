"""The least a responder can be: six XL-320 registers behind a pty, for ``bench emulator``.

Run as ``python bench/emulator_minimal.py`` (standard library only): prints its pty path, then
answers protocol 2 READ and takes SYNC_WRITE for IDs 1-6 (a byte table each, all 0 at start)
until Ctrl-C. One thread, blocked in ``read()`` on the pty's master between packets, nothing
else running: what any emulator loses to a flush-happy client on this machine, at the least.
"""

from __future__ import annotations

import os
import signal
import sys
import tty

from emulator_ping import crc16

IDS = range(1, 7)
READ, SYNC_WRITE, STATUS = 0x02, 0x83, 0x55
HEADER = b"\xff\xff\xfd\x00"


def _status(motor_id: int, data: bytes) -> bytes:
    length = len(data) + 4  # instruction, error, CRC
    body = HEADER + bytes([motor_id, length & 0xFF, length >> 8, STATUS, 0]) + data
    crc = crc16(body)
    return body + bytes([crc & 0xFF, crc >> 8])


def _handle(packet: bytes, tables: dict[int, bytearray]) -> bytes:
    motor_id, instruction, params = packet[4], packet[7], packet[8:-2]
    if instruction == READ and motor_id in tables:
        address, size = params[0] | params[1] << 8, params[2] | params[3] << 8
        return _status(motor_id, bytes(tables[motor_id][address : address + size]))
    if instruction == SYNC_WRITE:
        address, size = params[0] | params[1] << 8, params[2] | params[3] << 8
        for at in range(4, len(params), size + 1):
            if params[at] in tables:
                tables[params[at]][address : address + size] = params[at + 1 : at + 1 + size]
    return b""


def main() -> int:
    """Open the pty, print its path, answer until interrupted."""
    master, slave = os.openpty()
    tty.setraw(master)
    tty.setraw(slave)
    sys.stdout.write(os.ttyname(slave) + "\n")
    sys.stdout.flush()
    signal.signal(signal.SIGINT, lambda *_: os._exit(0))
    tables = {motor_id: bytearray(256) for motor_id in IDS}
    buffer = b""
    while True:
        buffer += os.read(master, 4096)
        while True:
            start = buffer.find(HEADER)
            if start < 0 or len(buffer) < start + 7:
                break
            buffer = buffer[start:]
            end = 7 + (buffer[5] | buffer[6] << 8)
            if len(buffer) < end:
                break
            packet, buffer = buffer[:end], buffer[end:]
            if crc16(packet[:-2]) == (packet[-2] | packet[-1] << 8):
                reply = _handle(packet, tables)
                if reply:
                    os.write(master, reply)


if __name__ == "__main__":
    raise SystemExit(main())
