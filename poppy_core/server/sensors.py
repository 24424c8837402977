"""``SensorService``: the robot's sensors as the routes see them (values as JSON, frames as images).

Register values are made JSON-safe here: a frame is described (shape, image URL), markers become
dicts. Reading a sensor may wait for its first value (a camera's first frame), so routes call
these methods from the thread pool.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from poppy_core.errors import UnknownCardError
from poppy_core.robot import Robot
from poppy_core.sensors import Camera, MarkerDetector, Sensor
from poppy_core.server.errors import ApiError

SENSOR_TIP = "the sensors are listed by /sensors/list.json"
CARD_SPELLINGS = {"rabbit": "lapin"}
"""pypot's other names of a card (pypot 5.0.2's snap.py and rest.py list ``rabbit`` with
``lapin``'s id; its demo project's card menu offers ``rabbit``)."""
IMAGE_TYPES = {"png": "image/png", "jpg": "image/jpeg"}


def json_value(value: Any, sensor: str) -> Any:
    """A register value as JSON data (a frame is described, not sent: see its image routes)."""
    if isinstance(value, np.ndarray):
        if value.ndim == 3:
            return {
                "shape": list(value.shape),
                "png": f"/sensors/{sensor}/frame.png",
                "jpg": f"/sensors/{sensor}/frame.jpg",
            }
        return value.tolist()
    if isinstance(value, list):
        return [json_value(v, sensor) for v in value]
    if hasattr(value, "as_dict"):
        return value.as_dict()
    if isinstance(value, dict):
        return {str(k): json_value(v, sensor) for k, v in value.items()}
    if isinstance(value, np.generic):
        return value.item()
    return value


class SensorService:
    """The sensors of ``robot``: list, registers, values, frames, markers, cards."""

    def __init__(self, robot: Robot) -> None:
        self.robot = robot

    def names(self) -> list[str]:
        """Sensor names in config order."""
        return [s.name for s in self.robot.sensors]

    def sensor(self, name: str) -> Sensor:
        """The sensor ``name``, or ``ApiError("not_found")``."""
        for sensor in self.robot.sensors:
            if sensor.name == name:
                return sensor
        raise ApiError("not_found", f"Sensor '{name}' does not exist.", tip=SENSOR_TIP)

    def camera(self, name: str) -> Camera:
        """The camera ``name``, or ``ApiError("not_found")``."""
        sensor = self.sensor(name)
        if not isinstance(sensor, Camera):
            raise ApiError("not_found", f"Sensor '{name}' is not a camera.", tip=SENSOR_TIP)
        return sensor

    def detector(self) -> MarkerDetector:
        """The first marker detector, or ``ApiError("not_found")`` (pypot's tip)."""
        for sensor in self.robot.sensors:
            if isinstance(sensor, MarkerDetector):
                return sensor
        raise ApiError(
            "not_found",
            "Code detection has been removed from robot",
            tip="add a MarkerDetector to the config's sensors (the Ergo Jr profile has one)",
        )

    def registers(self, name: str) -> list[str]:
        """The register names of sensor ``name``."""
        return list(self.sensor(name).registers)

    def read(self, name: str, register: str) -> Any:
        """A register's value as JSON data (may wait for the sensor's first value)."""
        sensor = self.sensor(name)
        if register not in sensor.registers:
            raise ApiError(
                "not_found",
                f"Either sensor '{name}' or register '{register}' does not exist.",
                tip=f"{SENSOR_TIP} and their registers with /sensors/{name}/registers/list.json",
            )
        return json_value(sensor.read(register), name)

    def describe(self, name: str) -> dict[str, Any]:
        """Every register (a frame described) and the health of sensor ``name``."""
        sensor = self.sensor(name)
        data: dict[str, Any] = {"name": name, "type": sensor.kind}
        data["registers"] = {r: self.read(name, r) for r in sensor.registers}
        data["health"] = sensor.health().as_dict()
        return data

    def image(self, name: str, ext: str) -> bytes:
        """The latest frame of camera ``name`` as ``png`` or ``jpg`` bytes."""
        if ext not in IMAGE_TYPES:
            raise ApiError("not_found", f"no image format {ext!r} (png or jpg)")
        camera = self.camera(name)
        return camera.encoded(camera.latest(), f".{ext}")

    def health(self) -> dict[str, dict[str, object]]:
        """Sensor name -> its health as data."""
        return {n: h.as_dict() for n, h in self.robot.sensor_health().items()}

    def markers(self) -> list[dict[str, Any]]:
        """The markers seen now."""
        return [m.as_dict() for m in self.detector().markers]

    def sees(self, card: str) -> bool:
        """Whether card (or marker id) ``card`` is in view (``ApiError`` for unknown cards)."""
        detector = self.detector()
        if card not in detector.card_ids and CARD_SPELLINGS.get(card) in detector.card_ids:
            card = CARD_SPELLINGS[card]
        try:
            return detector.sees(card)
        except UnknownCardError as exc:
            known = ", ".join(exc.known) or "none"
            raise ApiError(
                "not_found",
                "The code you asked for does not exist",
                tip=f"All preset codes are {known}",
            ) from None
