"""Wire-limited loop rates: how fast a present-state read could repeat, from packet sizes alone.

For one bus reading the same block of every motor, the time of one read transaction is

* **on the Dynamixel wire**: every byte the motors' half-duplex line carries, 10 bits per byte
  (8N1), return delay 0 (Poppy robots are set up so, and both libraries write it);
* **as emulated**: the emulator also charges, at line rate, the host's packet to a USB2AX (in
  reality it travels over USB) and adds its configured adapter latency once per transaction
  (every reply of a SYNC_READ is delayed by the same latency, so they overlap).

The loop rate limit is one transaction per period: ``1 / time``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

BITS_PER_BYTE = 10  # e-manual "Protocol 1.0"/"Protocol 2.0": 8 data bits, 1 stop bit, no parity.

# e-manual Protocol 2.0: FF FF FD 00 ID LEN_L LEN_H INST ... CRC_L CRC_H; status adds ERR after
# INST (0x55). SYNC_READ (0x82) parameters: start address (2), data length (2), then the IDs.
P2_INSTRUCTION_OVERHEAD = 10
P2_STATUS_OVERHEAD = 11
P2_SYNC_READ_PARAMS = 4
# e-manual Protocol 1.0: FF FF ID LEN INST ... CHK; status FF FF ID LEN ERR ... CHK.
# READ_DATA (0x02) parameters: address, length.
P1_INSTRUCTION_OVERHEAD = 6
P1_STATUS_OVERHEAD = 6
P1_READ_PARAMS = 2
# USB2AX sync read (0x84, USB2AX documentation): parameters address, length, then the IDs; the
# adapter sends one READ_DATA per motor on the Dynamixel bus and answers the host once.
USB2AX_SYNC_READ_PARAMS = 2


@dataclass(frozen=True)
class ReadGroup:
    """Motors read together: how many, and the bytes read from each."""

    motors: int
    length: int


@dataclass(frozen=True)
class WireLimit:
    """The wire-limited rate of one bus's present read.

    Attributes:
        method: ``sync_read`` (protocol 2), ``usb2ax`` or ``read`` (protocol 1, one per motor).
        transactions: host round trips per loop run.
        bus_bytes: bytes on the Dynamixel wire per loop run.
        host_bytes: bytes of the host's USB2AX packets (not on the Dynamixel wire, but charged
            at line rate by the emulator).
        wire_s: time of ``bus_bytes`` on the wire.
        wire_hz: ``1 / wire_s``, the pure-wire limit.
    """

    method: str
    transactions: int
    bus_bytes: int
    host_bytes: int
    wire_s: float
    wire_hz: float
    baudrate: int

    def emulated_s(self, latency_s: float) -> float:
        """One loop run as the emulator times it with ``latency_s`` of adapter latency."""
        host_s = self.host_bytes * BITS_PER_BYTE / self.baudrate
        return self.wire_s + host_s + self.transactions * latency_s

    def emulated_hz(self, latency_s: float) -> float:
        """The loop rate limit on the emulator with ``latency_s`` of adapter latency."""
        return 1.0 / self.emulated_s(latency_s)


def wire_limit(
    protocol: int, groups: Sequence[ReadGroup], baudrate: int, *, sync_read: bool = True
) -> WireLimit:
    """Compute the wire-limited rate of reading ``groups`` once per loop run.

    Args:
        protocol: 1 or 2.
        groups: one entry per read transaction (motors sharing a register layout).
        baudrate: line rate in bit/s.
        sync_read: protocol 1 only: the adapter is a USB2AX answering its sync read; when
            False every motor is read with its own READ_DATA round trip.

    Returns:
        The limit.

    Raises:
        ValueError: an unknown protocol or an empty group.
    """
    if protocol not in (1, 2):
        raise ValueError(f"protocol must be 1 or 2, got {protocol}")
    if not groups or any(g.motors < 1 or g.length < 1 for g in groups):
        raise ValueError("every group needs at least one motor and one byte")
    bus_bytes = host_bytes = transactions = 0
    read_bytes = P1_INSTRUCTION_OVERHEAD + P1_READ_PARAMS
    for group in groups:
        if protocol == 2:
            method = "sync_read"
            transactions += 1
            bus_bytes += P2_INSTRUCTION_OVERHEAD + P2_SYNC_READ_PARAMS + group.motors
            bus_bytes += group.motors * (P2_STATUS_OVERHEAD + group.length)
        elif sync_read:
            method = "usb2ax"
            transactions += 1
            host_bytes += P1_INSTRUCTION_OVERHEAD + USB2AX_SYNC_READ_PARAMS + group.motors
            bus_bytes += group.motors * (read_bytes + P1_STATUS_OVERHEAD + group.length)
        else:
            method = "read"
            transactions += group.motors
            bus_bytes += group.motors * (read_bytes + P1_STATUS_OVERHEAD + group.length)
    wire_s = bus_bytes * BITS_PER_BYTE / baudrate
    return WireLimit(method, transactions, bus_bytes, host_bytes, wire_s, 1.0 / wire_s, baudrate)
