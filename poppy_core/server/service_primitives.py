"""``PrimitiveOperations``: the primitives' part of ``RobotService`` (list, control, properties,
methods) and pypot's ``/robot.json`` description that lists them."""

from __future__ import annotations

import json
import time
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from poppy_core.motion import Primitive, attached_primitive, attached_primitives
from poppy_core.server import primitive_calls, values
from poppy_core.server.errors import ApiError
from poppy_core.server.pypot_json import html_safe
from poppy_core.server.start_time import StartTimes, check_start_at

if TYPE_CHECKING:
    from poppy_core.robot import Robot
    from poppy_core.server.moves import MoveService

DESCRIPTION_TTL_S = 0.01


class PrimitiveOperations:
    """What the routes do to a robot's primitives (a ``RobotService`` mixin)."""

    robot: Robot
    starts: StartTimes
    moves: MoveService
    _description: tuple[float, bytes] | None

    def primitives(self) -> dict[str, Primitive]:
        """Name -> every attached primitive."""
        return attached_primitives(self.robot)

    def description_json(self) -> bytes:
        """``description()`` encoded as pypot's routes answer it (``pypot_json.html_safe``),
        rebuilt at most every ``DESCRIPTION_TTL_S``.

        The motors' values come from caches the sync loops refresh at 50 Hz, so a description
        up to 10 ms old says the same; pollers asking many times a second share one encoding.
        """
        now = time.monotonic()
        if self._description is None or now - self._description[0] > DESCRIPTION_TTL_S:
            self._description = (now, html_safe(json.dumps(self.description()).encode()))
        return self._description[1]

    def description(self) -> dict[str, Any]:
        """pypot's ``/robot.json``: every motor's registers and every primitive."""
        primitives = []
        for name, primitive in self.primitives().items():
            props = values.jsonable(primitive.property_values())
            primitives.append(
                {
                    "primitive": name,
                    "running": primitive.is_alive(),
                    "properties": [{"property": p, "value": v} for p, v in props.items()],
                    "methods": list(primitive.methods),
                }
            )
        motors = [values.motor_registers(m) for m in self.robot.motors]
        return {"motors": motors, "primitives": primitives}

    def primitive(self, name: str) -> Primitive:
        """The primitive ``name`` (``UnknownPrimitiveError``, a 404, for another name)."""
        return attached_primitive(self.robot, name)

    def running_primitives(self) -> list[str]:
        """Names of the primitives running (or paused)."""
        return [name for name, p in self.primitives().items() if p.is_alive()]

    def pypot_running_primitives(self) -> list[str]:
        """``running_primitives()`` and the moves recorded or played, under pypot's names.

        pypot attached the recorder and the player of a move as primitives named
        ``_<move>_recorder`` and ``_<move>_player`` (pypot 5.0.2, ``pypot/server/rest.py``), so
        its running list held them; puppet-master's move recorder polls it for ``_<move>_player``
        to know when a move has ended.
        """
        recording = [f"_{name}_recorder" for name in self.moves.recording_live()]
        playing = [f"_{name}_player" for name in self.moves.playing()]
        return [*self.running_primitives(), *recording, *playing]

    def control_primitive(
        self, name: str, action: str, *, start_at: float | None = None
    ) -> Primitive:
        """``start``, ``stop``, ``pause`` or ``resume`` a primitive (``stop`` joins its thread).

        A start with ``start_at`` (wall clock, ``check_start_at``) is armed now and fires then
        (``StartTimes``); another action takes none.

        Raises:
            ArgumentError: a ``start_at`` too far from now, or one given to another action.
        """
        when = check_start_at(start_at)
        if when is not None and action != "start":
            raise ApiError("invalid", f"only a start takes a start_at, not {action!r}")
        primitive = self.primitive(name)
        if action == "start":
            primitive.start(gate=self.starts.gate(when))
        elif action == "stop":
            primitive.halt(wait=True)
        elif action == "pause":
            primitive.pause()
        elif action == "resume":
            primitive.resume()
        else:
            raise ApiError("not_found", f"no action {action!r} on primitives")
        return primitive

    def property_names(self, name: str) -> list[str]:
        """The properties a primitive exposes."""
        return list(self.primitive(name).properties)

    def get_property(self, name: str, prop: str) -> Any:
        """A primitive's property as JSON."""
        return primitive_calls.get_property(self.primitive(name), name, prop)

    def set_property(self, name: str, prop: str, value: Any) -> Any:
        """Set a primitive's property (converted and checked by the primitive)."""
        return primitive_calls.set_property(self.primitive(name), name, prop, value)

    def method_names(self, name: str) -> list[str]:
        """The methods a primitive exposes."""
        return list(self.primitive(name).methods)

    def call_method(
        self,
        name: str,
        method: str,
        args: Sequence[Any] = (),
        kwargs: Mapping[str, Any] | None = None,
    ) -> Any:
        """Call a declared method of a primitive; returns its result as JSON."""
        return primitive_calls.call_method(self.primitive(name), name, method, args, kwargs)

    def describe_primitive(self, name: str) -> dict[str, Any]:
        """State, properties, methods and error of a primitive (JSON)."""
        return primitive_calls.describe(self.primitive(name), name)
