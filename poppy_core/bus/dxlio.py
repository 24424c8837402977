"""pypot's low-level IO for scripts that use it: ``DxlIO`` / ``Dxl320IO`` over a ``DxlBus``.

Calls take a list of IDs and return a tuple of values in the same order
(``io.get_present_position([4, 5]) -> (67.8, -12.6)``), or take ``{id: value}``
(``io.set_goal_position({4: 0})``), in degrees, deg/s, %, V and °C as pypot. Any register of the
motors' models works as ``get_<register>`` / ``set_<register>``; the ID, baud rate and return
delay changes go through the verified setup operations of ``poppy_core.bus.setup``.
"""

from __future__ import annotations

import glob
import sys
from collections.abc import Iterable, Mapping
from typing import Any

from poppy_core.bus import setup, setup_reset
from poppy_core.bus.dxlbus import DxlBus
from poppy_core.bus.dxlio_pypot import GROUPS, RENAMED, PypotCalls, _ids, _mapping, capped
from poppy_core.bus.ports import list_ports
from poppy_core.errors import ArgumentError, CommunicationError, RegisterError
from poppy_core.models import ServoModel, SIValue

# pypot's getters named is_<flag> and their registers.
FLAGS = {"is_led_on": "led", "is_moving": "moving", "is_torque_enabled": "torque_enable"}
SCAN_IDS = range(254)


def get_available_ports(only_free: bool = False) -> list[str]:
    """The serial ports of this machine (pypot's name); ``only_free`` is accepted and ignored."""
    ports = [p.device for p in list_ports()]
    if not ports and sys.platform.startswith("linux"):
        ports = sorted(glob.glob("/dev/ttyUSB*") + glob.glob("/dev/ttyACM*"))
    return ports


class DxlIO(PypotCalls):
    """A protocol 1 bus (AX, MX...) spoken as pypot's ``DxlIO``.

    Args:
        port: the serial port (any pyserial URL: ``socket://``, a pty...).
        baudrate: the bus speed.
        timeout: the shortest wait for a reply in seconds, as pypot's (longer replies, at low
            baud rates, get the time their bytes take).
        use_sync_read: use the sync read of a USB2AX.
        error_handler_cls: refused unless None (errors are raised as poppy's typed errors).
        convert: refused unless True (values are always in SI units).
        bus: an open ``DxlBus`` to use instead of opening ``port``.

    Raises:
        PortError: the port cannot be opened.
    """

    protocol = 1

    def __init__(
        self,
        port: str,
        baudrate: int = 1_000_000,
        timeout: float = 0.05,
        use_sync_read: bool = False,
        error_handler_cls: object = None,
        convert: bool = True,
        *,
        bus: DxlBus | None = None,
    ) -> None:
        if error_handler_cls is not None or not convert:
            raise ArgumentError(
                "error_handler_cls and convert=False are not supported: errors are raised as "
                "poppy's typed errors and values are in degrees",
                field="error_handler_cls",
            )
        self.bus = bus or DxlBus(
            port,
            baudrate,
            self.protocol,
            sync_read=use_sync_read or None,
            min_timeout_s=float(timeout),
        )
        self._models: dict[int, ServoModel] = {}
        super().__init__(self)  # pypot's grouped calls read and write through this IO

    # -- the bus ---------------------------------------------------------------------------------

    @property
    def port(self) -> str:
        """The serial port."""
        return self.bus.port

    @property
    def baudrate(self) -> int:
        """The bus speed."""
        return self.bus.baudrate

    def close(self) -> None:
        """Close the port."""
        self.bus.close()

    def __enter__(self) -> DxlIO:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<{type(self).__name__} port={self.port!r} baudrate={self.baudrate}>"

    # -- finding motors --------------------------------------------------------------------------

    def ping(self, id: int) -> bool:
        """True when motor ``id`` answers."""
        found = self.bus.ping(id)
        if found is not None and found.model is not None:
            self._models[id] = found.model
        return found is not None

    def scan(self, ids: Iterable[int] = SCAN_IDS) -> list[int]:
        """The IDs among ``ids`` that answer, in order."""
        return [i for i in ids if self.ping(int(i))]

    def get_model(self, ids: Iterable[int]) -> tuple[str, ...]:
        """The model names of the motors (``'MX-28'``...)."""
        return tuple(self.model_of(i).name for i in ids)

    def model_of(self, id: int) -> ServoModel:
        """The model of motor ``id`` (asked once, then remembered).

        Raises:
            CommunicationError: the motor does not answer.
            RegisterError: it answers with a model number poppy does not know.
        """
        model = self._models.get(id)
        if model is None:
            found = self.bus.ping(id)
            if found is None:
                raise CommunicationError(
                    f"motor {id} does not answer on {self.port} at {self.baudrate} bps",
                    port=self.port,
                )
            if found.model is None:
                raise RegisterError(
                    f"motor {id}: unknown model number {found.model_number}", motor=str(id)
                )
            model = self._models[id] = found.model
        return model

    # -- registers -------------------------------------------------------------------------------

    def get(self, register: str, ids: Iterable[int]) -> tuple[Any, ...]:
        """Register ``register`` of each motor, in SI units."""
        return tuple(self.bus.read_register(i, self.model_of(i), register) for i in _ids(ids))

    def set(self, register: str, value_for_id: Mapping[int, Any]) -> None:
        """Write ``register`` of each motor (``{id: value}``, SI units)."""
        for motor_id, value in _mapping(value_for_id).items():
            model = self.model_of(motor_id)
            self.bus.write_register(motor_id, model, register, capped(model, register, value))

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        if name in FLAGS:
            register = FLAGS[name]
            return lambda ids: tuple(v not in (False, 0, "off") for v in self.get(register, ids))
        register = name[4:]
        pypot_name = register in GROUPS or register in RENAMED
        if name.startswith("get_"):
            if pypot_name:
                return lambda ids: self.get_grouped(register, ids)
            return lambda ids: self.get(register, ids)
        if name.startswith("set_"):
            if pypot_name:
                return lambda value_for_id: self.set_grouped(register, value_for_id)
            return lambda value_for_id: self.set(register, value_for_id)
        raise AttributeError(f"{type(self).__name__} has no {name!r}")

    def enable_torque(self, ids: Iterable[int]) -> None:
        """Turn the torque on."""
        self.set("torque_enable", dict.fromkeys(_ids(ids), True))

    def disable_torque(self, ids: Iterable[int]) -> None:
        """Turn the torque off (compliant)."""
        self.set("torque_enable", dict.fromkeys(_ids(ids), False))

    def switch_led_on(self, ids: Iterable[int]) -> None:
        """Light the LED (white on an XL-320, whose LED has colours)."""
        for motor_id in _ids(ids):
            self.set("led", {motor_id: self._led_value(motor_id, on=True)})

    def switch_led_off(self, ids: Iterable[int]) -> None:
        """Switch the LED off."""
        for motor_id in _ids(ids):
            self.set("led", {motor_id: self._led_value(motor_id, on=False)})

    def _led_value(self, motor_id: int, *, on: bool) -> SIValue:
        return self.model_of(motor_id).register("led").switched(on)

    def get_angle_limit(self, ids: Iterable[int]) -> tuple[tuple[float, float], ...]:
        """(min, max) position limits in degrees."""
        chosen = _ids(ids)
        low, high = self.get("min_position_limit", chosen), self.get("max_position_limit", chosen)
        return tuple((float(a), float(b)) for a, b in zip(low, high, strict=True))

    def set_angle_limit(self, limit_for_id: Mapping[int, tuple[float, float]]) -> None:
        """Set (min, max) position limits in degrees (verified)."""
        for motor_id, (low, high) in _mapping(limit_for_id).items():
            setup.set_angle_limits(self.bus, motor_id, float(low), float(high))

    # -- setup (verified) ------------------------------------------------------------------------

    def change_id(self, new_id_for_id: Mapping[int, int]) -> None:
        """Give motors new IDs (``{old: new}``), each verified."""
        for old, new in _mapping(new_id_for_id).items():
            setup.change_id(self.bus, old, int(new))
            model = self._models.pop(old, None)
            if model is not None:
                self._models[int(new)] = model

    def change_baudrate(self, baudrate_for_ids: Mapping[int, int]) -> None:
        """Set motors' baud rates (``{id: bps}``); the IO then speaks the last one's rate."""
        for motor_id, rate in _mapping(baudrate_for_ids).items():
            setup.change_baudrate(self.bus, motor_id, int(rate))

    def set_return_delay_time(self, delay_for_id: Mapping[int, float]) -> None:
        """Set return delays in µs (verified)."""
        for motor_id, delay in _mapping(delay_for_id).items():
            setup.set_return_delay(self.bus, motor_id, float(delay))

    def factory_reset(self, ids: Iterable[int] | None = None) -> None:
        """Reset motors to their factory settings (pypot resets every motor; name them here).

        Raises:
            ArgumentError: no IDs given.
        """
        if ids is None:
            raise ArgumentError("name the motors to reset: factory_reset([ids])", field="ids")
        for motor_id in _ids(ids):
            setup_reset.factory_reset(self.bus, motor_id)


class Dxl320IO(DxlIO):
    """A protocol 2 bus (XL-320, X series) spoken as pypot's ``Dxl320IO``."""

    protocol = 2
