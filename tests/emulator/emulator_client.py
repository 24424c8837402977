"""A tiny raw-bytes Dynamixel client over pyserial, for emulator tests."""

from __future__ import annotations

import time

import serial

from poppy_core.protocol import InstructionPacket, PacketDecoder, StatusPacket, encode_instruction


class RawClient:
    """Sends instruction packets on a real serial port and decodes what comes back."""

    def __init__(self, url: str, protocol: int, baudrate: int = 1_000_000) -> None:
        self.protocol = protocol
        self.port = serial.serial_for_url(url, baudrate=baudrate, timeout=0.02)
        self.decoder = PacketDecoder(protocol, "status")
        self.raw = bytearray()

    def reopen(self, baudrate: int) -> None:
        """Close and reopen the port at another baud rate."""
        url = self.port.port
        self.port.close()
        self.port = serial.serial_for_url(url, baudrate=baudrate, timeout=0.02)

    def send(self, packet: InstructionPacket) -> None:
        self.send_bytes(encode_instruction(self.protocol, packet))

    def send_bytes(self, data: bytes) -> None:
        self.port.reset_input_buffer()
        self.decoder.reset()
        self.raw.clear()
        self.port.write(data)
        self.port.flush()

    def receive(self, count: int = 1, timeout_s: float = 1.0) -> list[StatusPacket]:
        """Collect up to ``count`` status packets, waiting at most ``timeout_s``."""
        found: list[StatusPacket] = []
        deadline = time.monotonic() + timeout_s
        while len(found) < count and time.monotonic() < deadline:
            chunk = self.port.read(256)
            if chunk:
                self.raw += chunk
                found += [p for p in self.decoder.feed(chunk) if isinstance(p, StatusPacket)]
        return found

    def transact(
        self, packet: InstructionPacket, count: int = 1, timeout_s: float = 1.0
    ) -> list[StatusPacket]:
        self.send(packet)
        return self.receive(count, timeout_s)

    def silent(self, packet: InstructionPacket, wait_s: float = 0.15) -> bool:
        """True when nothing at all comes back within ``wait_s``."""
        self.send(packet)
        self.receive(1, wait_s)
        return not self.raw

    def close(self) -> None:
        self.port.close()
