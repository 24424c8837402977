"""Drift-free schedules, rate meters, and the sync loop's batching on an emulated bus."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from poppy_core.bus import DxlBus
from poppy_core.emulator import VirtualBus, VirtualMotor, serve_link
from poppy_core.models import model_by_name
from poppy_core.robot import BASE_LOOPS, BusSync, Motor, loops_for
from poppy_core.schedule import Periodic, RateMeter


def test_periodic_is_drift_free_and_counts_skips() -> None:
    schedule = Periodic(0.02, 1.0)
    assert not schedule.due(0.99) and schedule.due(1.0)
    assert schedule.advance(1.005) == 0  # a little late: next deadline unchanged
    assert schedule.next_deadline == pytest.approx(1.02)
    assert schedule.advance(1.071) == 2  # ran at 1.071: 1.04 and 1.06 are skipped
    assert schedule.next_deadline == pytest.approx(1.08)
    assert schedule.missed == 2
    with pytest.raises(ValueError):
        Periodic(0, 0)


def test_periodic_catch_up_keeps_one_overdue_deadline() -> None:
    schedule = Periodic(0.02, 1.0, catch_up=1)
    assert schedule.advance(1.025) == 0  # overran 1.02: it stays due, the next run starts now
    assert schedule.next_deadline == pytest.approx(1.02) and schedule.due(1.026)
    assert schedule.advance(1.071) == 1  # more than a period late: 1.04 skipped, 1.06 kept
    assert schedule.next_deadline == pytest.approx(1.06)
    assert schedule.missed == 1


def test_rate_meter() -> None:
    meter = RateMeter(window=10)
    assert meter.rate_hz == 0
    for k in range(30):
        meter.tick(k * 0.04)
    assert meter.rate_hz == pytest.approx(25) and meter.count == 30


def test_loop_choice() -> None:
    assert loops_for("BaseDxlController") is BASE_LOOPS
    light = loops_for("LightDxlController")
    assert light[0].registers == ("present_position", "present_speed")


@pytest.fixture
def line() -> Iterator[tuple[VirtualBus, DxlBus]]:
    motors = [
        VirtualMotor(model_by_name("AX-12A"), 1, 1_000_000),
        VirtualMotor(model_by_name("MX-28"), 2, 1_000_000),
    ]
    virtual = VirtualBus(motors, 1, adapter="usb2ax")
    server = serve_link(virtual)
    bus = DxlBus(server.url, 1_000_000, 1)
    yield virtual, bus
    bus.close()
    server.stop()


def test_same_layout_is_one_transaction(line: tuple[VirtualBus, DxlBus]) -> None:
    virtual, bus = line
    motors = [Motor("a", model_by_name("AX-12A"), 1), Motor("b", model_by_name("MX-28"), 2)]
    sync = BusSync("c", bus, motors)
    sync.run_once("present")  # finds the USB2AX sync read
    before = bus.stats.transactions
    virtual.motor(2).move_by_hand(45.0)
    sync.run_once("present")
    assert bus.stats.transactions == before + 1
    assert motors[1].present_position == pytest.approx(45, abs=0.1)
    sync.run_once("goals")  # nothing changed: nothing sent
    assert bus.stats.transactions == before + 1


def test_writes_only_changes_and_in_order(line: tuple[VirtualBus, DxlBus]) -> None:
    virtual, bus = line
    motor = Motor("a", model_by_name("AX-12A"), 1, orientation="indirect")
    sync = BusSync("c", bus, [motor])
    sync.run_once("present")
    motor.compliant = False
    motor.goal_position = 30
    motor.led = True
    sync.run_once("goals")
    bus.ping(1)  # sync writes get no reply: a round trip shows they were handled
    assert virtual.motor(1).torque_enabled
    assert virtual.motor(1).goal_position_deg == pytest.approx(-30, abs=0.3)
    assert virtual.motor(1).table.get("led") == 1
    before = bus.stats.transactions
    motor.goal_position = 30  # same value again: written again (a new order), torque is not
    sync.run_once("goals")
    assert bus.stats.transactions == before + 1


def test_missing_motor_goes_offline_then_back(line: tuple[VirtualBus, DxlBus]) -> None:
    virtual, bus = line
    motors = [Motor("a", model_by_name("AX-12A"), 1), Motor("b", model_by_name("MX-28"), 2)]
    sync = BusSync("c", bus, motors, offline_after=2)
    virtual.unplug(1)
    sync.run_once("present")
    assert motors[0].online and motors[0].errors == 1
    sync.run_once("present")
    assert not motors[0].online and motors[1].online
    assert sync.stats().offline == ["a"]
    virtual.plug(1)
    sync.run_once("retry")
    assert motors[0].online


def test_a_failing_pass_of_the_sync_thread_is_logged_once_counted_and_the_loops_resume(
    line: tuple[VirtualBus, DxlBus],
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    """A pass that raises (a bug, not a lost port) costs a WARNING once, is counted in health,
    and the thread goes on with backoff: the loops resume when the passes succeed again."""
    import logging

    from tests.helpers import eventually

    virtual, bus = line
    motors = [Motor("a", model_by_name("AX-12A"), 1)]
    sync = BusSync("c", bus, motors)
    real = sync._run_due_loops
    failing = [True]

    def flaky(now: float) -> None:
        if failing[0]:
            raise RuntimeError("a pass went wrong")
        real(now)

    monkeypatch.setattr(sync, "_run_due_loops", flaky)
    caplog.set_level(logging.WARNING, logger="poppy_core.schedule")
    sync.start()
    try:
        assert eventually(lambda: sync.health().loop_errors >= 3)
        assert sync.running
        failing[0] = False
        virtual.motor(1).move_by_hand(30.0)
        assert eventually(lambda: motors[0].present_position == pytest.approx(30, abs=0.5))
    finally:
        sync.stop()
    warned = [r for r in caplog.records if "a tick failed" in r.getMessage()]
    assert len(warned) == 1 and "sync c" in warned[0].getMessage()
