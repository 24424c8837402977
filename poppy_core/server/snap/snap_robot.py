"""``SnapRobot``: what each Snap! route does to the robot, answered as pypot's Snap! server's text.

Built on the REST server's services (``RobotService``, ``MoveService``, ``SensorService``), so a
value is checked the same way whatever the client, and a move recorded from Snap! lands in the
move library of ``poppy record``. Refusals are ``ApiError``s: the app answers them as one line.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any

from poppy_core import checks
from poppy_core.errors import ArgumentError, KinematicsError
from poppy_core.server import values
from poppy_core.server.chain_lookup import find_chain
from poppy_core.server.errors import ApiError
from poppy_core.server.pypot_values import pypot_value
from poppy_core.server.sensors import SensorService
from poppy_core.server.service import RobotService
from poppy_core.server.snap.playlists import Playlists
from poppy_core.server.snap.text import (
    DONE,
    names_text,
    number_text,
    parse_value,
    split_names,
    value_text,
    values_text,
)
from poppy_core.trajectory import goto_duration

PRIMITIVE_STATES = ("running", "started")
"""A primitive's states pypot's ``/primitive/<p>/get/<name>`` read besides its properties (it read
any attribute)."""

NO_DETECTOR = "Error: marker detector is not activated"
"""pypot's answer to ``/detect/<marker>`` without a detector."""


def number(text: str, what: str) -> float:
    """A finite number from a URL segment, else ``ApiError("invalid")``."""
    try:
        return checks.number_from(text, what)
    except ArgumentError as exc:
        raise ApiError("invalid", str(exc)) from None


def _speed(text: str) -> float:
    """A play speed factor from a URL segment: a finite number above 0."""
    factor = number(text, "speed")
    if factor <= 0:
        raise ApiError("invalid", f"speed must be above 0, got {text[:40]!r}")
    return factor


class SnapRobot:
    """The robot as Snap!'s blocks see it.

    Args:
        service: the robot's REST service (shared with the HTTP server when both run).
    """

    def __init__(self, service: RobotService) -> None:
        self.service = service
        self.robot = service.robot
        self.sensors = SensorService(service.robot)
        self._lock = threading.Lock()
        self._attached: dict[str, list[str]] = {}
        """Move name -> the motors a recorder was attached to (pypot's ``attach``)."""
        self.playlists = Playlists(service.moves)

    def connected(self) -> str:
        """``/connected``: ``True`` (the Snap! block "robot connected?" sees any other answer)."""
        return "True"

    def motor_index(self, motor: str) -> str:
        """``/motor/<m>/index``: its place in ``/motors/motors``, from 1 as Snap!'s lists count."""
        found = self.service.motor(motor)
        return str(self.robot.motors.index(found) + 1)

    # -- motors --------------------------------------------------------------------------------

    def motors_of(self, alias: str) -> str:
        """``/motors/<alias>``: the motors of a group (``motors``: every motor)."""
        return names_text(self.service.group(alias))

    def aliases(self) -> str:
        """``/motors/alias``: the group names."""
        return names_text(self.service.groups())

    def positions(self) -> str:
        """``/motors/get/positions``: every motor's present position, in motor order."""
        return values_text(m.present_position for m in self.robot.motors)

    def read(self, motor: str, register: str) -> str:
        """``/motor/<m>/get/<register>`` (``registers``: the list of them, as pypot)."""
        if register == "registers":
            return str(list(self.service.motor(motor).registers))
        return value_text(self.service.read(motor, register))

    def read_many(self, motors: str, register: str) -> str:
        """``/motors/<m1;m2>/get/<register>``."""
        names = split_names(motors)
        return values_text(self.service.read(name, register) for name in names)

    def write(self, motor: str, register: str, value: str) -> str:
        """``/motor/<m>/set/<register>/<value>``."""
        written = pypot_value(motor, register, parse_value(value))
        self.service.write_many({motor: {register: written}})
        return DONE

    def write_many(self, settings: str) -> str:
        """``/motors/set/registers/<m:reg:val;...>``: every value checked before any is written."""
        commands: dict[str, dict[str, Any]] = {}
        for item in settings.split(";"):
            if not item.strip():
                continue
            parts = item.split(":")
            if len(parts) != 3:
                raise ApiError("invalid", f"{item!r} is not motor:register:value, e.g. m1:led:red")
            motor, register, value = (p.strip() for p in parts)
            written = pypot_value(motor, register, parse_value(value))
            commands.setdefault(motor, {})[register] = written
        if not commands:
            raise ApiError("invalid", "no motor:register:value given, e.g. m1:compliant:False")
        self.service.write_many(commands)
        return DONE

    def set_positions(self, positions: str) -> str:
        """``/motors/set/positions/<p1;p2;...>``: goal positions of the motors in order."""
        given = [p for p in positions.split(";") if p.strip()]
        motors = self.robot.motors
        if len(given) > len(motors):
            raise ApiError("invalid", f"{len(given)} positions for {len(motors)} motors")
        commands = {
            m.name: {"goal_position": number(p, f"the position of {m.name}")}
            for m, p in zip(motors, given, strict=False)
        }
        if not commands:
            raise ApiError("invalid", "no position given, e.g. 0;10;-20;0;0;0")
        self.service.write_many(commands)
        return DONE

    def goto(self, motor: str, position: str, duration: str) -> str:
        """``/motor/<m>/goto/<position>/<duration>``."""
        return self.goto_many(f"{motor}:{position}:{duration}")

    def goto_many(self, settings: str) -> str:
        """``/motors/set/goto/<m:pos:dur;...>``: every target checked before any motor moves."""
        by_duration: dict[float, dict[str, float]] = {}
        for item in settings.split(";"):
            if not item.strip():
                continue
            parts = item.split(":")
            if len(parts) != 3:
                raise ApiError("invalid", f"{item!r} is not motor:position:duration, e.g. m1:30:2")
            name, position, duration = (p.strip() for p in parts)
            motor = self.service.motor(name)
            target = values.check_position(motor, "goal_position", number(position, "position"))
            seconds = goto_duration(number(duration, "duration"))
            by_duration.setdefault(seconds, {})[name] = target
        if not by_duration:
            raise ApiError("invalid", "no motor:position:duration given, e.g. m1:30:2")
        for seconds, targets in by_duration.items():
            self.robot.goto_position(targets, seconds, wait=False)
        return DONE

    # -- primitives ------------------------------------------------------------------------------

    def primitives(self) -> str:
        """``/primitives``."""
        return names_text(self.service.primitives())

    def running(self) -> str:
        """``/primitives/running``."""
        return names_text(self.service.running_primitives())

    def control(self, primitive: str, action: str) -> str:
        """``/primitive/<p>/start|stop|pause|resume`` (``stop`` waits for its thread)."""
        found = self.service.primitive(primitive)
        if action == "start" and found.is_alive():
            return DONE  # already running: as pypot, nothing to do
        self.service.control_primitive(primitive, action)
        return DONE

    def properties(self, primitive: str) -> str:
        """``/primitive/<p>/properties``."""
        return names_text(self.service.property_names(primitive))

    def methods(self, primitive: str) -> str:
        """``/primitive/<p>/methodes`` (pypot's spelling)."""
        return names_text(self.service.method_names(primitive))

    def get_property(self, primitive: str, prop: str) -> str:
        """``/primitive/<p>/get/<property>``; also pypot's primitive states ``running`` and
        ``started``: ``True``, or nothing when false (pypot's answer then; it failed with a 500
        when true)."""
        if prop in PRIMITIVE_STATES:
            return "True" if getattr(self.service.primitive(primitive), prop) else ""
        return value_text(self.service.get_property(primitive, prop))

    def set_property(self, primitive: str, prop: str, value: str) -> str:
        """``/primitive/<p>/set/<property>/<value>`` (pypot answers nothing)."""
        self.service.set_property(primitive, prop, parse_value(value))
        return ""

    def call(self, primitive: str, method: str, args: str | None = None) -> str:
        """``/primitive/<p>/call/<method>[/<k:v;...>]``: the method's result (nothing for None)."""
        kwargs: dict[str, Any] = {}
        for item in (args or "").split(";"):
            if item.strip():
                key, sep, value = item.partition(":")
                if not sep:
                    raise ApiError("invalid", f"{item!r} is not name:value, e.g. duration:2")
                kwargs[key.strip()] = parse_value(value)
        result = self.service.call_method(primitive, method, (), kwargs)
        return "" if result is None else value_text(result)

    # -- moves: pypot's MoveRecorder / MovePlayer routes -----------------------------------------

    def moves(self) -> str:
        """``/primitive/MoveRecorder`` and ``/primitive/MovePlayer``: the library's moves."""
        return names_text(self.service.moves.names())

    def _motor_names(self, motors: str) -> list[str]:
        names = split_names(motors)
        if not names:
            raise ApiError("invalid", "no motor given, e.g. m1;m2;m3")
        for name in names:
            if name not in self.robot.motorgroups:
                self.service.motor(name)  # raises, naming the robot's motors
        return names

    def record(self, move: str, motors: str | None = None) -> str:
        """``/primitive/MoveRecorder/<move>/start[/<m1;m2>]``: record (attached motors, or all)."""
        with self._lock:
            names = self._motor_names(motors) if motors is not None else self._attached.get(move)
            if names is not None:
                self._attached[move] = list(names)
        self.service.moves.record(move, names)
        return DONE

    def attach(self, move: str, motors: str) -> str:
        """``/primitive/MoveRecorder/<move>/attach/<m1;m2>``: the motors a later start records."""
        names = self._motor_names(motors)
        with self._lock:
            self._attached[move] = names
        return DONE

    def recorded_motors(self, move: str) -> str:
        """``/primitive/MoveRecorder/<move>/get_motors`` (``None`` for an unknown recorder)."""
        with self._lock:
            names = self._attached.get(move)
        if names is None and move in self.service.moves.recording():
            names = [m.name for m in self.robot.motors]
        if names is None:
            return "None"
        return names_text(m.name for m in self.robot.motors_of(names))

    def save(self, move: str) -> str:
        """``/primitive/MoveRecorder/<move>/stop``: stop recording and save it in the library."""
        self.service.moves.save(move)
        return DONE

    def remove(self, move: str) -> str:
        """``/primitive/MoveRecorder/<move>/remove``: delete it from the library (if there)."""
        if move in self.service.moves.names():
            self.service.moves.delete(move)
        with self._lock:
            self._attached.pop(move, None)
        return DONE

    def play(self, move: str, speed: str = "1", backwards: bool = False) -> str:
        """``/primitive/MovePlayer/<move>/start[/<speed>[/backwards]]``: its duration (s)."""
        player = self.service.moves.play(move, _speed(speed), backwards, client="Snap!")
        return number_text(player.duration_s)

    def play_together(self, moves: str, speed: str = "1") -> str:
        """``/moves/concurrently/<m1;m2>/<speed>``: start them all; the longest duration (s)."""
        return number_text(self.playlists.together(split_names(moves), _speed(speed)))

    def play_in_sequence(self, moves: str, speed: str = "1") -> str:
        """``/moves/sequentially/<m1;m2>/<speed>``: one after the other; the total duration (s)."""
        return number_text(self.playlists.in_sequence(split_names(moves), _speed(speed)))

    def stop_playing(self, move: str) -> str:
        """``/primitive/MovePlayer/<move>/stop`` (a move that is not playing: nothing to do).

        A sequence holding the move ends there.
        """
        self.playlists.stop(move)
        if move in self.service.moves.playing():
            self.service.moves.stop(move)
        return DONE

    # -- sensors, simulation, kinematics ---------------------------------------------------------

    def detect(self, marker: str) -> str:
        """``/detect/<marker>``: ``True`` when that card is in view."""
        try:
            detector = self.sensors.detector()
        except ApiError:
            raise ApiError("not_found", NO_DETECTOR) from None
        try:
            return str(self.sensors.sees(marker))
        except ApiError as exc:
            if exc.kind != "not_found":
                raise
            known = ", ".join(detector.card_ids) or "none"
            raise ApiError("not_found", f"no card {marker[:40]!r} (cards: {known})") from None

    def frame_png(self) -> bytes:
        """``/frame.png``: the first camera's latest frame."""
        for name in self.sensors.names():
            try:
                self.sensors.camera(name)
            except ApiError:
                continue
            return self.sensors.image(name, "png")
        raise ApiError("not_found", "Error: this robot has no camera")

    def reset_simulation(self) -> str:
        """``/reset-simulation``: the MuJoCo world back to its start (nothing without one)."""
        simulation = getattr(self.robot, "simulation", None)
        if simulation is not None:
            simulation.reset()
        return DONE

    def tip(self, chain: str) -> str:
        """``/ik/<chain>/endeffector``: ``x,y,z`` of the tip (metres, 4 decimals)."""
        position = find_chain(self.robot, chain).position
        return ",".join(str(round(float(v), 4)) for v in position)

    def ik_goto(self, chain: str, xyz: Sequence[str], duration: str) -> str:
        """``/ik/<chain>/goto/<x>/<y>/<z>/<duration>``: move the tip there (metres)."""
        found = find_chain(self.robot, chain)
        target = [number(v, axis) for v, axis in zip(xyz, "xyz", strict=True)]
        seconds = goto_duration(number(duration, "duration"))
        try:
            found.goto(target, None, duration=seconds, wait=False)
        except KinematicsError as exc:
            raise ApiError("invalid", f"cannot reach {target} with {chain}: {exc}") from None
        return DONE
