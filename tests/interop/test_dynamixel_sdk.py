"""The official Robotis Dynamixel SDK, as an independent client, against our emulator on a pty.

If the SDK understands our replies (and we understand its instructions), our bytes are the real
ones: checksums, CRCs, byte stuffing, status layouts, sync/bulk/fast-sync replies.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from poppy_core.emulator import EmulatorServer, VirtualBus, build_bus_from_spec, serve_pty
from tests.helpers import eventually
from tests.helpers.bus import client_on_pty

sdk: Any = pytest.importorskip("dynamixel_sdk")

COMM_SUCCESS = sdk.COMM_SUCCESS
COMM_RX_TIMEOUT = sdk.COMM_RX_TIMEOUT

# The SDK waits for a reply the wire time plus twice an FTDI adapter's 16 ms latency timer and
# 2 ms (port_handler.setPacketTimeout): some 34 ms. Our emulator answers from a thread of this
# process, which a busy machine runs tens of milliseconds late now and then (the SDK, busy
# polling the port meanwhile, then reports COMM_RX_TIMEOUT for a motor that is there). The
# replies are what these tests check, not their speed: the SDK's wait gets this much more.
LOADED_MACHINE_MARGIN_MS = 1000.0


class _PatientPort(sdk.PortHandler):  # type: ignore[misc]
    """The SDK's port, waiting ``LOADED_MACHINE_MARGIN_MS`` longer for each reply."""

    def setPacketTimeout(self, packet_length: int) -> None:
        super().setPacketTimeout(packet_length)
        self.packet_timeout += LOADED_MACHINE_MARGIN_MS

    def setPacketTimeoutMillis(self, msec: float) -> None:
        super().setPacketTimeoutMillis(msec + LOADED_MACHINE_MARGIN_MS)  # a broadcast ping's


class SdkSession:
    """A PortHandler + PacketHandler pair opened on an emulator server."""

    def __init__(self, server: EmulatorServer, protocol: float, baudrate: int) -> None:
        self.port = _PatientPort(server.url)
        assert self.port.openPort()
        assert self.port.setBaudRate(baudrate)
        self.packet = sdk.PacketHandler(protocol)

    def close(self) -> None:
        self.port.closePort()


def reg(bus: VirtualBus, motor_id: int, name: str) -> tuple[int, int]:
    register = bus.motor(motor_id).model.register(name)
    return register.address, register.size


@pytest.fixture
def v1_bus() -> VirtualBus:
    return build_bus_from_spec("MX-28:1-3,AX-12A:10", protocol=1, baudrate=1_000_000)


@pytest.fixture
def v1(v1_bus: VirtualBus) -> Iterator[SdkSession]:
    with client_on_pty(v1_bus, lambda s: SdkSession(s, 1.0, 1_000_000)) as session:
        yield session


@pytest.fixture
def v2_bus() -> VirtualBus:
    return build_bus_from_spec("XM430-W350:1-3", protocol=2, baudrate=1_000_000)


@pytest.fixture
def v2(v2_bus: VirtualBus) -> Iterator[SdkSession]:
    with client_on_pty(v2_bus, lambda s: SdkSession(s, 2.0, 1_000_000)) as session:
        yield session


@pytest.fixture
def xl_bus() -> VirtualBus:
    return build_bus_from_spec("XL-320:1-4", protocol=2, baudrate=1_000_000)


@pytest.fixture
def xl(xl_bus: VirtualBus) -> Iterator[SdkSession]:
    with client_on_pty(xl_bus, lambda s: SdkSession(s, 2.0, 1_000_000)) as session:
        yield session


# ---------------------------------------------------------------- protocol 1


def test_v1_ping(v1: SdkSession, v1_bus: VirtualBus) -> None:
    model_number, result, error = v1.packet.ping(v1.port, 2)
    assert (result, error) == (COMM_SUCCESS, 0)
    assert model_number == v1_bus.motor(2).model.model_number
    model_number, result, _ = v1.packet.ping(v1.port, 10)
    assert result == COMM_SUCCESS and model_number == v1_bus.motor(10).model.model_number
    _, result, _ = v1.packet.ping(v1.port, 42)
    assert result == COMM_RX_TIMEOUT


def test_v1_read_write(v1: SdkSession, v1_bus: VirtualBus) -> None:
    goal, _ = reg(v1_bus, 1, "goal_position")
    result, error = v1.packet.write2ByteTxRx(v1.port, 1, goal, 1234)
    assert (result, error) == (COMM_SUCCESS, 0)
    value, result, error = v1.packet.read2ByteTxRx(v1.port, 1, goal)
    assert (value, result, error) == (1234, COMM_SUCCESS, 0)
    assert v1_bus.motor(1).table.get("goal_position") == 1234


def test_v1_error_bits_reach_the_sdk(v1: SdkSession, v1_bus: VirtualBus) -> None:
    present, _ = reg(v1_bus, 1, "present_position")
    result, error = v1.packet.write2ByteTxRx(v1.port, 1, present, 10)
    assert result == COMM_SUCCESS
    assert error & sdk.protocol1_packet_handler.ERRBIT_RANGE


def test_v1_sync_write(v1: SdkSession, v1_bus: VirtualBus) -> None:
    goal, size = reg(v1_bus, 1, "goal_position")
    group = sdk.GroupSyncWrite(v1.port, v1.packet, goal, size)
    for motor_id, value in ((1, 1000), (2, 2000), (3, 3000)):
        assert group.addParam(motor_id, list(value.to_bytes(2, "little")))
    assert group.txPacket() == COMM_SUCCESS
    assert eventually(
        lambda: (
            [v1_bus.motor(i).table.get("goal_position") for i in (1, 2, 3)] == [1000, 2000, 3000]
        )
    )


def test_v1_bulk_read_mx(v1: SdkSession, v1_bus: VirtualBus) -> None:
    model, _ = reg(v1_bus, 1, "model_number")
    goal, _ = reg(v1_bus, 1, "goal_position")
    v1_bus.motor(3).table.set("goal_position", 777)
    group = sdk.GroupBulkRead(v1.port, v1.packet)
    assert group.addParam(1, model, 2)
    assert group.addParam(3, goal, 2)
    assert group.addParam(2, 3, 1)
    # dynamixel_sdk 4.1.0: GroupBulkRead.txPacket passes a 5th argument that protocol 1's
    # bulkReadTx does not take; send the group's own parameters through bulkReadTx directly.
    group.makeParam()
    assert v1.packet.bulkReadTx(v1.port, group.param, len(group.param)) == COMM_SUCCESS
    assert group.rxPacket() == COMM_SUCCESS
    assert group.getData(1, model, 2) == v1_bus.motor(1).model.model_number
    assert group.getData(3, goal, 2) == 777
    assert group.getData(2, 3, 1) == 2


# ---------------------------------------------------------------- protocol 2


def test_v2_ping(v2: SdkSession, v2_bus: VirtualBus) -> None:
    model_number, result, error = v2.packet.ping(v2.port, 3)
    assert (result, error) == (COMM_SUCCESS, 0)
    assert model_number == v2_bus.motor(3).model.model_number


def test_v2_read_write_4_bytes(v2: SdkSession, v2_bus: VirtualBus) -> None:
    goal, _ = reg(v2_bus, 1, "goal_position")
    result, error = v2.packet.write4ByteTxRx(v2.port, 2, goal, 3000)
    assert (result, error) == (COMM_SUCCESS, 0)
    value, result, error = v2.packet.read4ByteTxRx(v2.port, 2, goal)
    assert (value, result, error) == (3000, COMM_SUCCESS, 0)


def test_v2_access_error_reaches_the_sdk(v2: SdkSession, v2_bus: VirtualBus) -> None:
    torque, _ = reg(v2_bus, 1, "torque_enable")
    delay, _ = reg(v2_bus, 1, "return_delay_time")
    assert v2.packet.write1ByteTxRx(v2.port, 1, torque, 1) == (COMM_SUCCESS, 0)
    result, error = v2.packet.write1ByteTxRx(v2.port, 1, delay, 5)
    assert result == COMM_SUCCESS
    assert error == 7  # e-manual Protocol 2.0: Access Error


def test_v2_broadcast_ping(v2: SdkSession, v2_bus: VirtualBus) -> None:
    found, result = v2.packet.broadcastPing(v2.port)
    assert result == COMM_SUCCESS
    number = v2_bus.motor(1).model.model_number
    assert sorted(found) == [1, 2, 3]
    assert all(found[i][0] == number for i in found)


def test_v2_sync_read_and_write(v2: SdkSession, v2_bus: VirtualBus) -> None:
    goal, size = reg(v2_bus, 1, "goal_position")
    writer = sdk.GroupSyncWrite(v2.port, v2.packet, goal, size)
    for motor_id, value in ((1, 100), (2, 2000), (3, 4000)):
        assert writer.addParam(motor_id, list(value.to_bytes(4, "little")))
    assert writer.txPacket() == COMM_SUCCESS
    reader = sdk.GroupSyncRead(v2.port, v2.packet, goal, size)
    for motor_id in (3, 1, 2):
        assert reader.addParam(motor_id)
    assert reader.txRxPacket() == COMM_SUCCESS
    assert [reader.getData(i, goal, size) for i in (1, 2, 3)] == [100, 2000, 4000]


def test_v2_fast_sync_read(v2: SdkSession, v2_bus: VirtualBus) -> None:
    goal, size = reg(v2_bus, 1, "goal_position")
    for motor_id, value in ((1, 11), (2, 22), (3, 33)):
        v2_bus.motor(motor_id).table.set("goal_position", value)
    reader = sdk.GroupSyncRead(v2.port, v2.packet, goal, size)
    for motor_id in (1, 2, 3):
        assert reader.addParam(motor_id)
    assert reader.fastSyncRead() == COMM_SUCCESS
    assert [reader.getData(i, goal, size) for i in (1, 2, 3)] == [11, 22, 33]


def test_v2_bulk_read_and_write(v2: SdkSession, v2_bus: VirtualBus) -> None:
    goal, _ = reg(v2_bus, 1, "goal_position")
    led, _ = reg(v2_bus, 1, "led")
    writer = sdk.GroupBulkWrite(v2.port, v2.packet)
    assert writer.addParam(1, led, 1, [1])
    assert writer.addParam(3, goal, 4, list((1500).to_bytes(4, "little")))
    assert writer.txPacket() == COMM_SUCCESS
    assert eventually(lambda: v2_bus.motor(3).table.get("goal_position") == 1500)
    reader = sdk.GroupBulkRead(v2.port, v2.packet)
    assert reader.addParam(3, goal, 4)
    assert reader.addParam(1, led, 1)
    assert reader.txRxPacket() == COMM_SUCCESS
    assert reader.getData(3, goal, 4) == 1500
    assert reader.getData(1, led, 1) == 1


def test_xl320_sync_read_and_broadcast_ping(xl: SdkSession, xl_bus: VirtualBus) -> None:
    found, result = xl.packet.broadcastPing(xl.port)
    assert result == COMM_SUCCESS and sorted(found) == [1, 2, 3, 4]
    assert all(found[i][0] == 350 for i in found)
    present, size = reg(xl_bus, 1, "present_position")
    reader = sdk.GroupSyncRead(xl.port, xl.packet, present, size)
    for motor_id in (1, 2, 3, 4):
        assert reader.addParam(motor_id)
    assert reader.txRxPacket() == COMM_SUCCESS
    assert [reader.getData(i, present, size) for i in (1, 2, 3, 4)] == [512] * 4


def test_v2_reboot_and_factory_reset(v2: SdkSession, v2_bus: VirtualBus) -> None:
    assert v2.packet.reboot(v2.port, 2) == (COMM_SUCCESS, 0)
    assert v2.packet.factoryReset(v2.port, 3, 0x01) == (COMM_SUCCESS, 0)
    assert v2_bus.motor(3).baudrate_bps == 57_600  # back to factory, id kept (option 0x01)


def test_sdk_with_wire_timing_and_a_slower_line() -> None:
    bus = build_bus_from_spec("AX-12A:1-2", baudrate=57_600, wire_timing=True, latency_s=0.001)
    with serve_pty(bus) as server:
        session = SdkSession(server, 1.0, 57_600)
        model_number, result, error = session.packet.ping(session.port, 2)
        assert (model_number, result, error) == (bus.motor(2).model.model_number, COMM_SUCCESS, 0)
        assert session.port.setBaudRate(1_000_000)
        _, result, _ = session.packet.ping(session.port, 2)
        assert result == COMM_RX_TIMEOUT  # the motors only hear 57 600 bps
        session.close()
