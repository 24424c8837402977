"""Serving threads: bytes heard as they arrive, replies written whole, the line lost and back."""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import serial
from emulator_client import RawClient

from poppy_core.bus import DxlBus
from poppy_core.emulator import build_bus_from_spec, serve_pty, serve_tcp
from poppy_core.errors import PortError
from poppy_core.protocol import (
    PacketDecoder,
    StatusPacket,
    encode_instruction,
    ping,
    read,
    sync_write,
    write,
)
from tests.helpers.bus import loaded_reply_floor_s
from tests.helpers.waiting import eventually, scaled, within

XL320_TORQUE_ENABLE = 24
XL320_PRESENT_POSITION = 37


def test_a_write_is_heard_while_an_earlier_reply_is_held_back() -> None:
    # A slow adapter holds the reply to a read for 2 s; a write sent meanwhile reaches the
    # motor at once (the reader does not wait for the reply's due time).
    bus = build_bus_from_spec("XL-320:1-2", protocol=2)
    bus.extra_delay_s = 2.0
    with serve_pty(bus) as server:
        client = RawClient(server.url, 2)
        client.send(read(2, 1, XL320_PRESENT_POSITION, 2))
        client.port.write(encode_instruction(2, write(2, 2, XL320_TORQUE_ENABLE, b"\x01")))
        heard = within(lambda: bus.motor(2).table.get("torque_enable") == 1, 1.5)
        client.close()
    assert heard


def test_replies_are_written_whole_when_the_client_reads_late() -> None:
    # 6,000 pings whose 84 kB of replies go unread until every ping is sent: more than the
    # pty holds, so writes come back short or refused; every reply must still arrive whole.
    bus = build_bus_from_spec("XL-320:1", protocol=2)
    count = 6000
    with serve_pty(bus) as server:
        port = serial.Serial(server.url, 1_000_000, timeout=0.05)
        packet = encode_instruction(2, ping(1))
        for _ in range(count):
            port.write(packet)
        decoder = PacketDecoder(2, "status")
        replies = 0
        quiet_since = time.monotonic()
        quiet_s = scaled(1.5)  # the emulator thread may wait that long for a core
        while time.monotonic() - quiet_since < quiet_s and replies < count:
            chunk = port.read(65536)
            if chunk:
                quiet_since = time.monotonic()
                replies += sum(isinstance(p, StatusPacket) for p in decoder.feed(chunk))
        port.close()
    assert decoder.corrupt_packets == 0 and decoder.skipped_bytes == 0
    assert replies == count
    assert server.replies_dropped == 0


def _lose_the_line(server: Any, dxl: DxlBus) -> None:
    """Motor 1 answers; the line goes for 0.5 s: the server says so and the bus fails."""
    assert dxl.ping(1) is not None
    server.lose(0.5)
    assert eventually(lambda: not server.connected)
    with pytest.raises(PortError):
        for _ in range(3):
            dxl.ping(1)


def test_pty_line_lost_and_back_under_its_link(tmp_path: Path) -> None:
    link = tmp_path / "ttyDXL"
    bus = build_bus_from_spec("XL-320:1", protocol=2)
    with serve_pty(bus, link=link) as server:
        first = server.url
        assert os.readlink(link) == first
        with DxlBus(str(link), 1_000_000, 2, min_timeout_s=loaded_reply_floor_s()) as dxl:
            _lose_the_line(server, dxl)
            assert not link.exists()
        assert eventually(lambda: server.connected and link.exists())
        assert os.readlink(link) == server.url
        with DxlBus(str(link), 1_000_000, 2, min_timeout_s=loaded_reply_floor_s()) as dxl:
            assert dxl.ping(1) is not None
    assert not link.exists()


def test_tcp_line_lost_and_back_on_the_same_port() -> None:
    bus = build_bus_from_spec("XL-320:1", protocol=2)
    with serve_tcp(bus) as server:
        url = server.url
        with DxlBus(url, 1_000_000, 2, min_timeout_s=loaded_reply_floor_s()) as dxl:
            _lose_the_line(server, dxl)
        with pytest.raises(PortError):
            DxlBus(url, 1_000_000, 2)
        assert eventually(lambda: server.connected)
        assert server.url == url
        with DxlBus(url, 1_000_000, 2, min_timeout_s=loaded_reply_floor_s()) as dxl:
            assert dxl.ping(1) is not None


class FlushingClient:
    """Does what pypot's ``DxlIO``/``Dxl320IO`` do: flush input and output before every packet.

    One difference: after a packet that gets no reply, it waits until the emulator has taken
    it. Linux moves bytes written to a pty slave to the master's side in a kernel worker, and
    a flush of the slave's output before that worker ran discards them before any reader can
    see them (see docs/emulator.md). pypot does not wait, so on a machine with no free CPU
    some of its writes vanish in the kernel; waiting keeps this test about the emulator.
    """

    def __init__(self, url: str, received: Callable[[], int]) -> None:
        # pyserial checks its write timeout after the write: a thread the busy machine ran late
        # got "Write timeout" for bytes it had written, so the timeout follows the load
        self.port = serial.Serial(url, 1_000_000, timeout=0.05, write_timeout=scaled(0.5))
        self.decoder = PacketDecoder(2, "status")
        self.received = received

    def send(self, data: bytes) -> None:
        self.port.reset_input_buffer()
        self.port.reset_output_buffer()
        self.port.write(data)

    def write_no_reply(self, data: bytes) -> None:
        before = self.received()
        self.send(data)
        within(lambda: self.received() > before, 2.0)

    def read(self, motor_id: int, address: int, length: int) -> bytes | None:
        self.send(encode_instruction(2, read(2, motor_id, address, length)))
        self.decoder.reset()
        end = time.monotonic() + scaled(0.5)
        while time.monotonic() < end:
            for packet in self.decoder.feed(self.port.read(max(1, self.port.in_waiting))):
                if isinstance(packet, StatusPacket) and packet.id == motor_id:
                    return packet.params
        return None


@pytest.mark.parametrize("wire_timing", [False, True])
def test_no_write_lost_with_a_client_that_flushes_before_every_packet(wire_timing: bool) -> None:
    bus = build_bus_from_spec("XL-320:1-6", protocol=2, wire_timing=wire_timing, latency_s=0.001)
    ids = range(1, 7)
    lost = unanswered = 0
    with serve_pty(bus) as server:
        client = FlushingClient(server.url, lambda: bus.packets_received)
        for _ in range(40):
            for on in (1, 0):
                data = {i: bytes([on]) for i in ids}
                packet = sync_write(2, XL320_TORQUE_ENABLE, 1, data)
                client.write_no_reply(encode_instruction(2, packet))
                for motor_id in ids:
                    state = client.read(motor_id, XL320_TORQUE_ENABLE, 1)
                    unanswered += state is None
                    lost += state is not None and state[0] != on
        client.port.close()
    assert (lost, unanswered) == (0, 0)
