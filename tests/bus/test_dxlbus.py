"""DxlBus transactions against the emulator over a real pty and socket://."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from poppy_core.bus import DxlBus
from poppy_core.errors import BusTimeout, CorruptPacketError, MotorError, ProtocolError
from poppy_core.models import MX_28, XL430_W250
from tests.helpers.bus import loaded_reply_floor_s
from tests.helpers.waiting import eventually

# e-manual MX-28 (protocol 1): goal position at 30, present position at 36 (2 bytes each).
MX_GOAL, MX_PRESENT = 30, 36
# e-manual XL430-W250: goal position at 116, present position at 132 (4 bytes each).
X_GOAL, X_PRESENT = 116, 132

if TYPE_CHECKING:
    from tests.helpers.bus import Emulate


def loaded_floor(via: str) -> float | None:
    """The first-reply floor of a bus whose emulator is served ``via``: the loaded one for an
    emulator thread on a pty or TCP (a busy machine runs it late), the product's own on the
    in-process link (replies come in the writer's thread, never late)."""
    return None if via == "link" else loaded_reply_floor_s()


def test_ping_read_write(emulate: Emulate, via: str) -> None:
    with (
        emulate("MX-28:1-2", via=via) as (_, url),
        DxlBus(url, min_timeout_s=loaded_floor(via)) as bus,
    ):
        found = bus.ping(1)
        assert found is not None
        assert (found.id, found.model_number, found.model) == (1, 29, MX_28)
        assert found.firmware is not None
        floor = bus.min_timeout_s
        bus.min_timeout_s = 0.0  # no motor 9: nothing can answer late, its two pings need no floor
        assert bus.ping(9) is None
        bus.min_timeout_s = floor
        bus.write(1, MX_GOAL, (1000).to_bytes(2, "little"))
        assert bus.read(1, MX_GOAL, 2) == (1000).to_bytes(2, "little")
        bus.write_register(2, MX_28, "goal_position", 45.0)
        assert bus.read_register(2, MX_28, "goal_position") == pytest.approx(45.0, abs=0.1)
        assert bus.stats.transactions >= 5
        assert bus.stats.motor_errors == 0


def test_reg_write_waits_for_action(emulate: Emulate) -> None:
    with emulate("MX-28:1") as (_, url), DxlBus(url) as bus:
        before = bus.read(1, MX_GOAL, 2)
        bus.reg_write(1, MX_GOAL, (3000).to_bytes(2, "little"))
        assert bus.read(1, MX_GOAL, 2) == before
        bus.action()
        assert bus.read(1, MX_GOAL, 2) == (3000).to_bytes(2, "little")


def test_write_without_reply_and_broadcast(emulate: Emulate) -> None:
    with emulate("MX-28:1-3") as (_, url), DxlBus(url) as bus:
        bus.write(1, MX_GOAL, (100).to_bytes(2, "little"), reply=False)
        bus.write(0xFE, MX_GOAL + 2, (50).to_bytes(2, "little"))
        assert bus.read(1, MX_GOAL, 2) == (100).to_bytes(2, "little")
        assert all(bus.read(i, MX_GOAL + 2, 2) == (50).to_bytes(2, "little") for i in (1, 2, 3))
        assert bus.stats.timeouts == 0


def _individual(bus: DxlBus, ids: list[int], address: int, length: int) -> dict[int, bytes]:
    return {i: bus.read(i, address, length) for i in ids}


@pytest.mark.parametrize(
    ("spec", "adapter", "mode"),
    [
        ("MX-28:1-4", "usb2ax", "sync"),
        ("MX-28:1-4", "u2d2", "bulk"),
        ("MX-28:1-3,AX-12A:4", "u2d2", "sequential"),
    ],
)
def test_v1_sync_read_strategies_give_the_same_data(
    emulate: Emulate, spec: str, adapter: str, mode: str
) -> None:
    with emulate(spec, adapter=adapter) as (virtual, url), DxlBus(url) as bus:
        for i, motor in enumerate(virtual.motors):
            motor.move_by_hand(10.0 * (i + 1))
        ids = [1, 2, 3, 4]
        expected = _individual(bus, ids, MX_PRESENT, 2)
        assert bus.sync_read(MX_PRESENT, 2, ids) == expected
        assert bus.sync_read_mode == mode
        assert bus.usb2ax is (adapter == "usb2ax")
        # The strategy is remembered: a second call gives the same data the same way.
        assert bus.sync_read(MX_PRESENT, 2, ids) == expected
        assert bus.sync_read_mode == mode


def test_v1_sync_read_disabled_falls_back_to_bulk(emulate: Emulate) -> None:
    with emulate("MX-28:1-3", adapter="usb2ax") as (_, url), DxlBus(url, sync_read=False) as bus:
        assert bus.sync_read(MX_PRESENT, 2, [1, 2, 3]) == _individual(bus, [1, 2, 3], MX_PRESENT, 2)
        assert bus.sync_read_mode == "bulk"
        assert bus.usb2ax is None


def test_v1_sync_read_missing_motor_is_none(emulate: Emulate) -> None:
    with emulate("MX-28:1-3", adapter="usb2ax") as (virtual, url), DxlBus(url) as bus:
        virtual.unplug(2)
        result = bus.sync_read(MX_PRESENT, 2, [1, 2, 3])
        assert result[2] is None
        assert result[1] is not None and result[3] is not None


def test_v2_group_transactions(emulate: Emulate, via: str) -> None:
    with (
        emulate("XL430-W250:1-3", via=via, protocol=2) as (virtual, url),
        DxlBus(url, protocol=2, min_timeout_s=loaded_floor(via)) as bus,
    ):
        virtual.motor(2).move_by_hand(30.0)
        ids = [1, 2, 3]
        expected = _individual(bus, ids, X_PRESENT, 4)
        assert bus.sync_read(X_PRESENT, 4, ids) == expected
        assert bus.sync_read_mode == "sync"
        assert bus.fast_sync_read(X_PRESENT, 4, ids) == expected
        assert bus.bulk_read([(1, X_PRESENT, 4), (2, X_GOAL, 4)]) == {
            1: expected[1],
            2: bus.read(2, X_GOAL, 4),
        }
        bus.sync_write(X_GOAL, {1: (1000).to_bytes(4, "little"), 3: (3000).to_bytes(4, "little")})
        assert bus.read(3, X_GOAL, 4) == (3000).to_bytes(4, "little")
        bus.bulk_write([(2, X_GOAL, (2500).to_bytes(4, "little")), (1, 65, b"\x01")])
        assert bus.read(2, X_GOAL, 4) == (2500).to_bytes(4, "little")
        assert bus.read(1, 65, 1) == b"\x01"
        pinged = bus.broadcast_ping()
        assert [p.id for p in pinged] == [1, 2, 3]
        assert all(p.model is XL430_W250 for p in pinged)


def test_v2_sync_read_with_a_silent_motor_still_reads_the_others(emulate: Emulate) -> None:
    with emulate("XL430-W250:1-4", protocol=2) as (virtual, url), DxlBus(url, protocol=2) as bus:
        virtual.unplug(2)
        result = bus.sync_read(X_PRESENT, 4, [1, 2, 3, 4])
        assert result[2] is None
        assert all(result[i] is not None for i in (1, 3, 4))
        fast = bus.fast_sync_read(X_PRESENT, 4, [1, 2, 3, 4])
        assert fast == result


def test_v2_reboot_clear_factory_reset(emulate: Emulate) -> None:
    with emulate("XL430-W250:5", protocol=2) as (_, url), DxlBus(url, protocol=2) as bus:
        bus.write(5, 9, b"\x00")  # return delay time (address 9) -> 0
        bus.reboot(5)
        bus.clear(5)
        bus.factory_reset(5, 0x02)
        assert bus.ping(5) is not None
        assert bus.read(5, 9, 1) == b"\xfa"  # factory return delay 250 (e-manual)


def test_v2_only_instructions_refused_on_v1(emulate: Emulate) -> None:
    with emulate("MX-28:1") as (_, url), DxlBus(url) as bus:
        for call in (lambda: bus.reboot(1), bus.broadcast_ping, lambda: bus.bulk_write([])):
            with pytest.raises(ProtocolError):
                call()


def test_motor_error_on_refusal(emulate: Emulate, via: str) -> None:
    with (
        emulate("XL430-W250:1", via=via, protocol=2) as (_, url),
        DxlBus(url, protocol=2, min_timeout_s=loaded_floor(via)) as bus,
    ):
        with pytest.raises(MotorError) as info:
            bus.write(1, 0, b"\x00\x00")  # model number is read-only
        assert info.value.motor_id == 1
        assert info.value.errors
        assert "motor 1" in str(info.value)
        assert bus.stats.motor_errors == 1
        assert bus.stats.retries == 0  # a refusal is not retried


def test_v1_motor_error_bits(emulate: Emulate) -> None:
    with emulate("MX-28:3") as (virtual, url), DxlBus(url) as bus:
        virtual.motor(3).fail_with(["instruction"])
        with pytest.raises(MotorError) as info:
            bus.read(3, MX_PRESENT, 2)
        assert info.value.errors == ["instruction"]


def test_alarm_bits_still_return_data(emulate: Emulate, caplog: pytest.LogCaptureFixture) -> None:
    with emulate("MX-28:3") as (virtual, url), DxlBus(url) as bus:
        virtual.motor(3).fail_with(["overload"])
        assert len(bus.read(3, MX_PRESENT, 2)) == 2
        assert bus.alarms[3] == ["overload"]
        assert bus.stats.alarms == 1
        assert bus.stats.motor_errors == 0
        assert "overload" in caplog.text
        assert bus.ping(3) is not None


def test_v2_hardware_alert_is_an_alarm(emulate: Emulate) -> None:
    with emulate("XL430-W250:1", protocol=2) as (virtual, url), DxlBus(url, protocol=2) as bus:
        virtual.motor(1).fail_with(["overheating"])
        assert len(bus.read(1, X_PRESENT, 4)) == 4
        assert bus.alarms[1] == ["hardware alert"]


def test_timeouts_and_retries_are_counted(emulate: Emulate, via: str) -> None:
    with emulate("MX-28:4", via=via) as (virtual, url), DxlBus(url, retries=2) as bus:
        virtual.drop_rate = 1.0
        with pytest.raises(BusTimeout) as info:
            bus.read(4, MX_PRESENT, 2)
        assert info.value.motor_id == 4
        assert info.value.port == url
        assert bus.stats.timeouts == 3
        assert bus.stats.retries == 2
        assert bus.stats.transactions == 1


def test_corrupt_replies_are_counted(emulate: Emulate) -> None:
    with emulate("MX-28:4") as (virtual, url), DxlBus(url, retries=1) as bus:
        virtual.corrupt_rate = 1.0
        with pytest.raises(CorruptPacketError) as info:
            bus.read(4, MX_PRESENT, 2)
        assert info.value.motor_id == 4
        assert bus.stats.corrupt_packets >= 1
        assert bus.stats.retries == 1


def test_retries_recover_from_dropped_replies(emulate: Emulate) -> None:
    with emulate("MX-28:4", seed=7) as (virtual, url), DxlBus(url, retries=8) as bus:
        virtual.drop_rate = 0.3
        for _ in range(30):
            assert len(bus.read(4, MX_PRESENT, 2)) == 2
        assert bus.stats.retries > 0
        assert bus.stats.timeouts == bus.stats.retries


def test_late_reply_is_kept_as_stray(emulate: Emulate) -> None:
    with emulate("MX-28:4") as (virtual, url), DxlBus(url, retries=0) as bus:
        virtual.extra_delay_s = 0.05
        assert bus.ping(4) is None
        virtual.extra_delay_s = 0.0
        strays: list[int] = []  # the late reply, whenever a busy machine delivers it

        def arrived() -> bool:
            strays.extend(s.id for s in bus.take_strays())
            return bool(strays)

        assert eventually(arrived)
        assert strays == [4]


def test_baudrate_switch_on_pty(emulate: Emulate) -> None:
    with emulate("MX-28:1", baudrate=57_600) as (_, url), DxlBus(url, 1_000_000) as bus:
        assert bus.ping(1) is None
        bus.baudrate = 57_600
        assert bus.baudrate == 57_600
        assert bus.ping(1) is not None


def test_unknown_model_number(emulate: Emulate) -> None:
    with emulate("MX-28:1") as (virtual, url), DxlBus(url) as bus:
        virtual.motor(1).table.set("model_number", 4242)
        found = bus.ping(1)
        assert found is not None
        assert (found.model_number, found.model, found.model_name) == (4242, None, None)


def test_close_and_context_manager(emulate: Emulate) -> None:
    with emulate("MX-28:1") as (_, url):
        bus = DxlBus(url)
        assert repr(bus).startswith("DxlBus(")
        assert (bus.port, bus.protocol) == (url, 1)
        bus.close()
        bus.close()
        assert not bus.transport.is_open
        with pytest.raises(ProtocolError):
            DxlBus(url, protocol=3)


def test_fixed_timeout_overrides_the_physical_estimate(emulate: Emulate) -> None:
    with emulate("MX-28:4") as (virtual, url), DxlBus(url, retries=0, timeout_s=0.2) as bus:
        virtual.extra_delay_s = 0.05  # far beyond the physical estimate, within 0.2 s
        assert bus.ping(4) is not None
        assert bus.stats.timeouts == 0


def test_broadcast_ping_waits_at_least_the_buses_floor(emulate: Emulate) -> None:
    # Replies 4 ms behind the latency assumed (the OS ran the emulator late, under load) come
    # within the 10 ms floor every transaction of a bus gets (a scan's bus has no floor).
    slow = emulate("XL430-W250:1-2", protocol=2, wire_timing=True, latency_s=0.004)
    with slow as (_, url), DxlBus(url, protocol=2, latency_s=0.001) as bus:
        assert [p.id for p in bus.broadcast_ping()] == [1, 2]
