"""Write protocol 2 PINGs to a port at a steady pace; print each write's time as one JSON line.

Run as ``python bench/emulator_ping.py --port /dev/pts/N --count 300`` (standard library only):
the port is opened raw at 1 Mbit/s, one PING to ID 1 is written every ``--every-ms`` (its time
taken right after ``os.write`` returned: the bytes are in the kernel's queue), and the reply is
drained before the next one. ``bench.emulator_bench`` compares these times with the ones the
emulator stamped when it read each packet.
"""

from __future__ import annotations

import argparse
import json
import os
import select
import sys
import termios
import time
import tty


def crc16(data: bytes) -> int:
    """CRC-16 of a protocol 2 packet (polynomial 0x8005, initial 0, no reflection: e-manual)."""
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else crc << 1
            crc &= 0xFFFF
    return crc


def ping_packet(motor_id: int) -> bytes:
    """Protocol 2 PING (instruction 0x01) to ``motor_id``."""
    body = bytes([0xFF, 0xFF, 0xFD, 0x00, motor_id, 0x03, 0x00, 0x01])
    crc = crc16(body)
    return body + bytes([crc & 0xFF, crc >> 8])


def main() -> int:
    """Open the port, write the PINGs, print ``{"writes": [...], "size": N}``."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--port", required=True)
    parser.add_argument("--count", type=int, default=300)
    parser.add_argument("--every-ms", type=float, default=5.0)
    args = parser.parse_args()
    fd = os.open(args.port, os.O_RDWR | os.O_NOCTTY)
    tty.setraw(fd)
    attrs = termios.tcgetattr(fd)
    attrs[4] = attrs[5] = termios.B1000000
    termios.tcsetattr(fd, termios.TCSANOW, attrs)
    packet = ping_packet(1)
    writes: list[float] = []
    next_at = time.perf_counter()
    for _ in range(args.count):
        next_at += args.every_ms / 1000
        os.write(fd, packet)
        writes.append(time.perf_counter())
        while (left := next_at - time.perf_counter()) > 0:  # drain the reply meanwhile
            ready, _, _ = select.select([fd], [], [], left)
            if ready:
                os.read(fd, 1024)
    os.close(fd)
    sys.stdout.write(json.dumps({"writes": writes, "size": len(packet)}) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
