"""``ContactSensor``: a micro switch on a GPIO pin, through gpiozero (pypot's, on RPi.GPIO).

pypot's config entry: ``{"type": "ContactSensor", "gpio_data": 17, "gpio_vcc": 27}`` (BCM
numbers); ``contact`` is True while the data pin reads high. ``gpio_vcc``, when given, is
driven high to power the switch, as pypot did. gpiozero picks the board's pin library (or
``GPIOZERO_PIN_FACTORY``; ``mock`` in tests).
"""

from __future__ import annotations

import warnings
from typing import Any, ClassVar

from poppy_core.errors import SensorError
from poppy_core.sensors.base import Sensor

DEFAULT_CONTACT_HZ = 50.0


class ContactSensor(Sensor):
    """Whether the switch on ``gpio_data`` is pressed (pypot's ``ContactSensor``).

    Args:
        name: the sensor's name (``robot.<name>``).
        gpio_data: the data pin (BCM number, or a gpiozero pin name such as ``"GPIO17"``).
        gpio_vcc: a pin driven high to power the switch (None: powered otherwise).
        rate_hz: how often the background loop samples the pin (for health).
        pin_factory: a gpiozero pin factory (None: gpiozero's default).

    Raises:
        SensorError: gpiozero is not installed, or the pins cannot be claimed (no GPIO here,
            a pin in use).
    """

    registers: ClassVar[tuple[str, ...]] = ("contact",)

    def __init__(
        self,
        name: str,
        gpio_data: int | str,
        gpio_vcc: int | str | None = None,
        rate_hz: float = DEFAULT_CONTACT_HZ,
        *,
        pin_factory: Any = None,
    ) -> None:
        super().__init__(name, rate_hz)
        try:
            import gpiozero
        except ImportError:
            raise SensorError(
                f"sensor {name!r}: ContactSensor needs gpiozero: pip install 'poppy[gpio]'",
                sensor=name,
            ) from None
        self._vcc: Any = None
        try:
            # gpiozero warns about each pin library it falls back from; the error says it all
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                if gpio_vcc is not None:
                    self._vcc = gpiozero.DigitalOutputDevice(
                        gpio_vcc, initial_value=True, pin_factory=pin_factory
                    )
                self._input: Any = gpiozero.DigitalInputDevice(
                    gpio_data, pull_up=None, active_state=True, pin_factory=pin_factory
                )
        except Exception as exc:  # gpiozero's errors: no pin library, pin in use, bad pin
            if self._vcc is not None:
                self._vcc.close()
            raise SensorError(
                f"sensor {name!r}: cannot use GPIO {gpio_data}: {exc}", sensor=name
            ) from None
        self.gpio_data = gpio_data
        self.gpio_vcc = gpio_vcc

    @property
    def contact(self) -> bool:
        """True while the switch is closed (the data pin high)."""
        self.wait_first()
        return bool(self._input.value)

    def update(self) -> bool | None:
        _ = self._input.value  # a pin that can no longer be read fails here, counted in health
        return None

    def release(self) -> None:
        for device in (self._input, self._vcc):
            if device is not None:
                device.close()
