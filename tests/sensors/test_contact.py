"""ContactSensor: a micro switch on a GPIO pin through gpiozero, driven by its mock pin factory."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

gpiozero = pytest.importorskip("gpiozero")
from gpiozero.pins.mock import MockFactory  # noqa: E402

from poppy_core import from_config  # noqa: E402
from poppy_core.errors import SensorError  # noqa: E402
from poppy_core.robot import RobotConfig, load_profile  # noqa: E402
from poppy_core.sensors.contact import ContactSensor  # noqa: E402
from tests.helpers.sensor_rest import rest  # noqa: E402


@pytest.fixture
def factory() -> Iterator[MockFactory]:
    made = MockFactory()
    yield made
    made.close()


def test_contact_follows_the_data_pin_and_vcc_powers_the_switch(factory: MockFactory) -> None:
    with ContactSensor("switch", 17, 27, pin_factory=factory) as sensor:
        assert factory.pin(27).state == 1  # gpio_vcc driven high, as pypot did
        data = factory.pin(17)
        data.drive_high()
        assert sensor.contact is True
        data.drive_low()
        assert sensor.contact is False
        assert sensor.read("contact") is False
        health = sensor.health()
        assert health.connected and health.kind == "ContactSensor" and health.errors == 0
    # closing frees the pins for another device
    gpiozero.DigitalInputDevice(17, pin_factory=factory).close()


def test_a_pin_already_in_use_is_a_one_line_error(factory: MockFactory) -> None:
    taken = gpiozero.DigitalOutputDevice(17, pin_factory=factory)
    try:
        with pytest.raises(SensorError, match=r"^sensor 'switch': cannot use GPIO 17: ") as caught:
            ContactSensor("switch", 17, 27, pin_factory=factory)
        assert "\n" not in str(caught.value)
        gpiozero.DigitalOutputDevice(27, pin_factory=factory).close()  # vcc was given back
    finally:
        taken.close()


def test_a_pypot_config_entry_is_robot_dot_name(
    factory: MockFactory, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(gpiozero.Device, "pin_factory", factory)
    data = load_profile("ergo-jr").to_pypot_dict()
    data["sensors"] = {"bumper": {"type": "ContactSensor", "gpio_data": 22, "gpio_vcc": 23}}
    with from_config(RobotConfig.from_dict(data), sim=True) as robot:
        factory.pin(22).drive_high()
        assert robot.bumper.contact is True
        with rest(robot) as client:
            assert client.get("/sensors/bumper/registers/contact/value.json").json() == {
                "contact": True
            }
        factory.pin(22).drive_low()
        assert robot.bumper.contact is False
        assert robot.sensor_health()["bumper"].connected
    assert robot.bumper.closed
