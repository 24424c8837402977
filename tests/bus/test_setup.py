"""Setup operations against the emulator: every change verified, no motor stranded."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from poppy_core.bus import (
    DxlBus,
    change_baudrate,
    change_id,
    factory_reset,
    reboot,
    reset_motor,
    set_angle_limits,
    set_return_delay,
)
from poppy_core.errors import RegisterError, SetupError
from poppy_core.models import MX_28, ServoModel, SIValue

if TYPE_CHECKING:
    from tests.helpers.bus import Emulate


def test_change_id_verified(emulate: Emulate, via: str) -> None:
    with emulate("MX-28:1-2", via=via) as (virtual, url), DxlBus(url) as bus:
        steps: list[str] = []
        result = change_id(bus, 1, 11, progress=steps.append)
        assert (result.motor_id, result.changes["id"], result.verified) == (11, (1, 11), True)
        assert bus.ping(1) is None and bus.ping(11) is not None
        assert virtual.motor(11).model is MX_28
        assert steps


def test_change_id_refuses_a_taken_id(emulate: Emulate) -> None:
    with emulate("MX-28:1-2") as (_, url), DxlBus(url) as bus:
        with pytest.raises(SetupError, match=f"ID 2 is already taken on {url}"):
            change_id(bus, 1, 2)
        assert bus.ping(1) is not None


def test_change_id_x_series_turns_torque_off_first(emulate: Emulate) -> None:
    with emulate("XL430-W250:1", protocol=2) as (virtual, url), DxlBus(url, protocol=2) as bus:
        bus.write(1, 64, b"\x01")  # torque on locks the EEPROM (e-manual)
        change_id(bus, 1, 8)
        assert bus.ping(8) is not None
        assert not virtual.motor(8).torque_enabled


def test_change_baudrate_verified(emulate: Emulate) -> None:
    with emulate("MX-28:3") as (virtual, url), DxlBus(url) as bus:
        result = change_baudrate(bus, 3, 57_600)
        assert result.changes["baudrate"] == (1_000_000, 57_600)
        assert bus.baudrate == 57_600 and result.baudrate == 57_600
        assert virtual.motor(3).baudrate_bps == 57_600
        assert bus.ping(3) is not None


class QuirkyBus(DxlBus):
    """A bus whose baud-rate writes land on another rate (a firmware surprise)."""

    def write_register(self, id: int, model: ServoModel, name: str, value: SIValue) -> None:
        super().write_register(id, model, name, 115_200 if name == "baudrate" else value)


def test_change_baudrate_finds_a_lost_motor(emulate: Emulate) -> None:
    with emulate("MX-28:3") as (_, url), QuirkyBus(url) as bus:
        with pytest.raises(SetupError, match="it answers at 115200 bps"):
            change_baudrate(bus, 3, 57_600)
        assert bus.baudrate == 115_200
        assert bus.ping(3) is not None


def test_change_baudrate_rejects_an_impossible_rate(emulate: Emulate) -> None:
    with (
        emulate("XL430-W250:3", protocol=2) as (_, url),
        DxlBus(url, protocol=2) as bus,
        pytest.raises(RegisterError),
    ):
        change_baudrate(bus, 3, 12_345)


def test_return_delay_and_angle_limits(emulate: Emulate) -> None:
    with emulate("MX-28:4") as (_, url), DxlBus(url) as bus:
        delay = set_return_delay(bus, 4, 0)
        assert delay.changes["return_delay_time"] == (500.0, 0.0)
        limits = set_angle_limits(bus, 4, -90, 90)
        assert limits.changes["min_position_limit"][1] == pytest.approx(-90, abs=0.1)
        assert limits.changes["max_position_limit"][1] == pytest.approx(90, abs=0.1)
        with pytest.raises(SetupError):
            set_angle_limits(bus, 4, 10, -10)


def test_reset_motor_like_poppy_reset_motor(emulate: Emulate) -> None:
    with emulate("MX-28:1", baudrate=57_600) as (virtual, url), DxlBus(url, 57_600) as bus:
        steps: list[str] = []
        result = reset_motor(
            bus,
            1,
            "MX-28",
            target_id=42,
            angle_limits=(-100, 100),
            go_to_zero=True,
            progress=steps.append,
        )
        assert (result.motor_id, result.baudrate, result.verified) == (42, 1_000_000, True)
        motor = virtual.motor(42)
        assert motor.baudrate_bps == 1_000_000
        assert motor.return_delay_s == 0
        assert motor.torque_enabled
        assert motor.goal_position_deg == pytest.approx(0, abs=0.1)
        assert set(result.changes) >= {"id", "return_delay_time", "baudrate", "min_position_limit"}
        assert len(steps) >= 4


def test_reset_motor_refuses_the_wrong_model(emulate: Emulate) -> None:
    with (
        emulate("AX-12A:1") as (_, url),
        DxlBus(url) as bus,
        pytest.raises(SetupError, match="is a AX-12A, not a MX-28"),
    ):
        reset_motor(bus, 1, "MX-28", target_id=2)


def test_factory_reset_v1_restores_id_and_rate(emulate: Emulate) -> None:
    with emulate("MX-28:7") as (virtual, url), DxlBus(url) as bus:
        bus.write(7, 5, b"\x00")  # return delay 0
        result = factory_reset(bus, 7)
        assert (result.motor_id, result.baudrate) == (7, 1_000_000)
        motor = virtual.motor(7)
        assert motor.baudrate_bps == 1_000_000
        assert bus.read(7, 5, 1) == b"\xfa"  # factory return delay came back


def test_factory_reset_v1_without_keeping(emulate: Emulate) -> None:
    with emulate("MX-28:7") as (_, url), DxlBus(url) as bus:
        result = factory_reset(bus, 7, keep_id=False, keep_baudrate=False)
        # MX-28 factory settings (e-manual): ID 1, 57600 bps.
        assert (result.motor_id, result.baudrate) == (1, 57_600)
        assert bus.baudrate == 57_600 and bus.ping(1) is not None


def test_factory_reset_refuses_when_factory_id_is_taken(emulate: Emulate) -> None:
    with emulate("MX-28:1,7", baudrate=57_600) as (_, url), DxlBus(url, 57_600) as bus:
        with pytest.raises(SetupError, match="factory ID 1 is already taken"):
            factory_reset(bus, 7)
        assert bus.ping(7) is not None


@pytest.mark.parametrize(
    ("keep_id", "keep_baudrate", "option"),
    [(True, True, "0x02"), (True, False, "0x01"), (False, False, "0xff")],
)
def test_factory_reset_v2_options(
    emulate: Emulate, keep_id: bool, keep_baudrate: bool, option: str
) -> None:
    with emulate("XL430-W250:9", protocol=2) as (_, url), DxlBus(url, protocol=2) as bus:
        result = factory_reset(bus, 9, keep_id=keep_id, keep_baudrate=keep_baudrate)
        assert f"option {option}" in result.notes[0]
        assert result.motor_id == (9 if keep_id else 1)
        # X-series factory rate is 57600 (e-manual)
        assert result.baudrate == (1_000_000 if keep_baudrate else 57_600)
        assert bus.ping(result.motor_id) is not None


def test_reboot(emulate: Emulate) -> None:
    with emulate("XL430-W250:2", protocol=2) as (_, url), DxlBus(url, protocol=2) as bus:
        assert reboot(bus, 2).verified
    with emulate("MX-28:2") as (_, url), DxlBus(url) as bus, pytest.raises(SetupError):
        reboot(bus, 2)


def test_setup_on_a_silent_motor(emulate: Emulate) -> None:
    with (
        emulate("MX-28:2") as (_, url),
        DxlBus(url) as bus,
        pytest.raises(SetupError, match="motor 5 does not answer"),
    ):
        change_id(bus, 5, 6)


def test_reset_motor_without_an_expected_model(emulate: Emulate) -> None:
    with emulate("AX-12A:1") as (virtual, url), DxlBus(url) as bus:
        result = reset_motor(bus, 1, None, target_id=5)
        assert result.motor_id == 5
        assert virtual.motor(5).return_delay_s == 0
