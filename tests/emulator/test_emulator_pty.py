"""The emulator served on a real pty, driven with raw bytes through pyserial."""

from __future__ import annotations

import time

import pytest
from emulator_client import RawClient

from poppy_core.emulator import VirtualBus, build_bus_from_spec, serve_pty
from poppy_core.protocol import (
    BROADCAST_ID,
    PacketDecoder,
    StatusPacket,
    action,
    bulk_read,
    bulk_write,
    decode_errors,
    encode_instruction,
    fast_sync_read,
    parse_fast_sync_status,
    parse_usb2ax_sync_status,
    ping,
    read,
    reg_write,
    sync_read,
    sync_write,
    write,
)


def reg(bus: VirtualBus, motor_id: int, name: str) -> tuple[int, int]:
    register = bus.motor(motor_id).model.register(name)
    return register.address, register.size


def test_ping_read_write(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    (reply,) = xl320.transact(ping(2))
    assert reply.id == 2 and int.from_bytes(reply.params[:2], "little") == 350
    address, size = reg(xl320_bus, 1, "goal_position")
    assert xl320.transact(write(2, 1, address, (600).to_bytes(2, "little"))) == [
        StatusPacket(1, 0, b"")
    ]
    (reply,) = xl320.transact(read(2, 1, address, size))
    assert reply.params == (600).to_bytes(2, "little")


def test_no_motor_no_reply(xl320: RawClient) -> None:
    assert xl320.silent(ping(42))


def test_reg_write_action(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    address, _ = reg(xl320_bus, 1, "led")
    for motor_id in (1, 2):
        assert xl320.transact(reg_write(2, motor_id, address, b"\x05"))[0].error == 0
    assert xl320.silent(action())
    assert [m.table.get("led") for m in xl320_bus.motors] == [5, 5, 0]


def test_broadcast_ping_answers_in_id_order(xl320: RawClient) -> None:
    replies = xl320.transact(ping(BROADCAST_ID), count=3)
    assert [r.id for r in replies] == [1, 2, 3]


def test_sync_read_and_sync_write(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    address, size = reg(xl320_bus, 1, "goal_position")
    values = {1: 300, 2: 400, 3: 500}
    packet = sync_write(2, address, size, {i: v.to_bytes(2, "little") for i, v in values.items()})
    assert xl320.silent(packet)
    replies = xl320.transact(sync_read(2, address, size, [3, 1, 2]), count=3)
    assert [(r.id, int.from_bytes(r.params, "little")) for r in replies] == [
        (3, 500),
        (1, 300),
        (2, 400),
    ]


def test_sync_read_chain_stops_at_a_missing_motor(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    address, size = reg(xl320_bus, 1, "present_position")
    xl320_bus.unplug(2)
    replies = xl320.transact(sync_read(2, address, size, [1, 2, 3]), count=3, timeout_s=0.3)
    assert [r.id for r in replies] == [1]


def test_bulk_read_and_bulk_write_v2(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    led, _ = reg(xl320_bus, 1, "led")
    goal, _ = reg(xl320_bus, 1, "goal_position")
    assert xl320.silent(bulk_write([(1, led, b"\x02"), (3, goal, (100).to_bytes(2, "little"))]))
    replies = xl320.transact(bulk_read(2, [(3, goal, 2), (1, led, 1)]), count=2)
    assert [(r.id, r.params) for r in replies] == [(3, (100).to_bytes(2, "little")), (1, b"\x02")]


def test_fast_sync_read(xm: RawClient, x_bus: VirtualBus) -> None:
    address, size = reg(x_bus, 1, "present_position")
    (reply,) = xm.transact(fast_sync_read(address, size, [2, 3, 1]))
    result = parse_fast_sync_status(reply, size)
    assert list(result) == [2, 3, 1]
    for motor_id, (error, data) in result.items():
        assert error == 0
        assert int.from_bytes(data, "little", signed=True) == x_bus.motor(motor_id).table.get(
            "present_position"
        )


def test_bulk_read_v1_mx(mx: RawClient, mx_bus: VirtualBus) -> None:
    address, size = reg(mx_bus, 11, "model_number")
    replies = mx.transact(bulk_read(1, [(12, address, size), (11, 3, 1)]), count=2)
    assert [(r.id, r.params) for r in replies] == [
        (12, mx_bus.motor(12).table.read(address, size)),
        (11, b"\x0b"),
    ]


def test_bulk_read_v1_not_on_ax(mx: RawClient) -> None:
    # AX firmware has no bulk read: it stays silent and so does everything after it.
    replies = mx.transact(bulk_read(1, [(11, 3, 1), (36, 3, 1), (12, 3, 1)]), 3, timeout_s=0.3)
    assert [r.id for r in replies] == [11]


def test_v1_sync_read_ignored_without_usb2ax(mx: RawClient) -> None:
    assert mx.silent(sync_read(1, 36, 2, [11, 12]))


def test_v1_sync_read_with_usb2ax() -> None:
    bus = build_bus_from_spec("MX-28:11-13", adapter="usb2ax")
    with serve_pty(bus) as server:
        client = RawClient(server.url, 1)
        (reply,) = client.transact(sync_read(1, 3, 1, [13, 11, 99]))
        assert parse_usb2ax_sync_status(reply, 1, [13, 11, 99]) == {
            13: b"\x0d",
            11: b"\x0b",
            99: b"\xff",
        }
        client.close()


def test_status_return_level_over_pty(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    address, _ = reg(xl320_bus, 2, "status_return_level")
    xl320.transact(write(2, 2, address, b"\x01"))
    led, _ = reg(xl320_bus, 2, "led")
    assert xl320.silent(write(2, 2, led, b"\x01"))
    assert xl320.transact(read(2, 2, led, 1))[0].params == b"\x01"


def test_eeprom_refused_with_torque_on(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    torque, _ = reg(xl320_bus, 1, "torque_enable")
    delay, _ = reg(xl320_bus, 1, "return_delay_time")
    xl320.transact(write(2, 1, torque, b"\x01"))
    (reply,) = xl320.transact(write(2, 1, delay, b"\x05"))
    assert decode_errors(2, reply.error) == ["access error"]


def test_read_only_write_error(mx: RawClient, mx_bus: VirtualBus) -> None:
    address, _ = reg(mx_bus, 11, "present_temperature")
    (reply,) = mx.transact(write(1, 11, address, b"\x20"))
    assert decode_errors(1, reply.error) == ["range"]


def test_id_change(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    address, _ = reg(xl320_bus, 3, "id")
    (reply,) = xl320.transact(write(2, 3, address, b"\x07"))
    assert reply.id == 3 and reply.error == 0
    assert xl320.silent(ping(3))
    assert xl320.transact(ping(7))[0].id == 7


def test_baud_change(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    address, _ = reg(xl320_bus, 1, "baudrate")
    code = xl320_bus.motor(1).model.baudrate_code(57_600)
    (reply,) = xl320.transact(write(2, 1, address, bytes((code,))))
    assert reply.id == 1
    assert xl320.silent(ping(1))
    xl320.reopen(57_600)
    assert xl320.transact(ping(1))[0].id == 1
    assert xl320.silent(ping(2))  # still at 1 Mbps


def test_wrong_client_baudrate_gets_silence(xl320_bus: VirtualBus) -> None:
    with serve_pty(xl320_bus) as server:
        client = RawClient(server.url, 2, baudrate=115_200)
        assert client.silent(ping(1))
        client.reopen(1_000_000)
        assert client.transact(ping(1))[0].id == 1
        client.close()


def test_unplugged_is_silent_then_back(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    xl320_bus.unplug(2)
    assert xl320.silent(ping(2))
    xl320_bus.plug(2)
    assert xl320.transact(ping(2))[0].id == 2


def test_corrupt_replies_are_counted(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    xl320_bus.corrupt_rate = 0.05  # a 14-byte reply: about half of them get a flipped bit
    decoder = PacketDecoder(2, "status")
    good = 0
    for _ in range(30):
        xl320.send(ping(1))
        time.sleep(0.01)
        good += len(decoder.feed(xl320.port.read(256)))
    assert xl320_bus.faults.corrupted_bytes > 0
    assert decoder.corrupt_packets > 0
    assert 0 < good < 30


def test_dropped_replies(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    xl320_bus.drop_rate = 1.0
    assert xl320.silent(ping(1))
    xl320_bus.drop_rate = 0.0
    assert xl320.transact(ping(1))[0].id == 1


def test_extra_delay(xl320: RawClient, xl320_bus: VirtualBus) -> None:
    xl320_bus.extra_delay_s = 0.15
    start = time.perf_counter()
    assert xl320.transact(ping(1))[0].id == 1
    assert time.perf_counter() - start >= 0.14


def test_split_writes_are_reassembled(xl320: RawClient) -> None:
    data = encode_instruction(2, ping(3))
    xl320.port.reset_input_buffer()
    for i in range(len(data)):
        xl320.port.write(data[i : i + 1])
        xl320.port.flush()
        time.sleep(0.002)
    assert [r.id for r in xl320.receive(1)] == [3]


@pytest.mark.parametrize("baudrate", [57_600, 1_000_000])
def test_wire_timing_ping_takes_the_physical_minimum(baudrate: int) -> None:
    bus = build_bus_from_spec("XL-320:1", baudrate=baudrate, wire_timing=True, latency_s=0.001)
    delay_s = bus.motor(1).return_delay_s  # factory: 250 x 2 µs = 500 µs
    instruction = encode_instruction(2, ping(1))
    reply_bytes = 14
    minimum = (len(instruction) + reply_bytes) * 10 / baudrate + delay_s + 0.001
    with serve_pty(bus) as server:
        client = RawClient(server.url, 2, baudrate=baudrate)
        timings = []
        for _ in range(5):
            start = time.perf_counter()
            assert client.transact(ping(1))[0].id == 1
            timings.append(time.perf_counter() - start)
        client.close()
    assert min(timings) >= minimum * 0.98
    assert min(timings) < minimum + 0.05
