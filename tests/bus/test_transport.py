"""Transport: opening errors translated to PortError, packet reads with deadlines."""

from __future__ import annotations

import errno
import socket

import pytest
import serial

from poppy_core.bus.timing import Deadline
from poppy_core.bus.transport import Transport, port_error
from poppy_core.errors import PortError
from poppy_core.protocol import StatusPacket, encode_status


def test_missing_device_message() -> None:
    with pytest.raises(PortError) as info:
        Transport("/dev/ttyUSB_poppy_missing_9")
    message = str(info.value)
    assert (
        message == "no such port /dev/ttyUSB_poppy_missing_9: plug the adapter or run `poppy ports`"
    )
    assert info.value.port == "/dev/ttyUSB_poppy_missing_9"


def test_permission_denied_message(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("sys.platform", "linux")
    exc = serial.SerialException(
        errno.EACCES, "could not open port /dev/ttyUSB0: Permission denied"
    )
    error = port_error("/dev/ttyUSB0", exc)
    assert "sudo usermod -aG dialout $USER, then log in again" in str(error)
    assert "\n" not in str(error)


def test_busy_message() -> None:
    exc = serial.SerialException("Could not exclusively lock port /dev/ttyUSB0: [Errno 11]")
    assert "is busy" in str(port_error("/dev/ttyUSB0", exc))
    exc2 = serial.SerialException(errno.EBUSY, "Device or resource busy")
    assert "is busy" in str(port_error("/dev/ttyUSB0", exc2))


def test_refused_socket_message() -> None:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    with pytest.raises(PortError) as info:
        Transport(f"socket://127.0.0.1:{port}")
    assert "nothing answers at socket://127.0.0.1" in str(info.value)


def test_loop_reads_a_packet_split_across_garbage() -> None:
    with Transport("loop://", 1_000_000, 1) as transport:
        data = encode_status(1, StatusPacket(5, 0, b"\x01\x02"))
        transport.write(b"\x00\x13" + data[:3])
        transport.write(data[3:])
        packet = transport.read_packet(Deadline(0.5))
        assert packet == StatusPacket(5, 0, b"\x01\x02")
        assert transport.read_packet(Deadline(0.01)) is None


def test_read_packet_respects_deadline() -> None:
    with Transport("loop://", 57_600, 2) as transport:
        deadline = Deadline(0.02)
        assert transport.read_packet(deadline) is None
        assert deadline.expired()


def test_drain_returns_late_packets_and_resets() -> None:
    with Transport("loop://", 1_000_000, 1) as transport:
        transport.write(encode_status(1, StatusPacket(3, 0)) + b"\xff\xff\x07")
        late = transport.drain()
        assert late == [StatusPacket(3, 0)]
        transport.write(encode_status(1, StatusPacket(4, 0)))
        assert transport.read_packet(Deadline(0.5)) == StatusPacket(4, 0)


def test_protocol_and_baudrate_can_change() -> None:
    with Transport("loop://", 1_000_000, 1) as transport:
        transport.protocol = 2
        transport.set_baudrate(57_600)
        assert transport.baudrate == 57_600
        transport.write(encode_status(2, StatusPacket(9, 0, b"\x06\x04\x26")))
        assert transport.read_packet(Deadline(0.5)) == StatusPacket(9, 0, b"\x06\x04\x26")
    assert not transport.is_open
