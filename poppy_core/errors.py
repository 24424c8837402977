"""Typed errors shared by every layer of poppy_core.

The tree (catch the bases, raise the leaves)::

    PoppyError
    ├── BusError                  anything about a bus; carries ``port``
    │   ├── PortError             the port cannot be opened (missing, busy, permission)
    │   └── CommunicationError    a transaction failed on the wire
    │       ├── BusTimeout        no (complete) status packet in time
    │       └── CorruptPacketError  a status packet with a bad checksum/CRC or shape
    ├── ProtocolError             bytes that do not make a valid packet / unsupported instruction
    ├── MotorError                a motor answered with error bits; carries ``motor_id``, ``errors``
    ├── UnknownModelError         a model number or name poppy does not know
    ├── RegisterError             unknown register, read-only register, value out of range;
    │   │                         carries ``register`` and ``motor``
    │   └── MissingRegisterError  a register the motor's model does not have (``pid`` on an
    │                             AX-12A); also an ``AttributeError``
    ├── ArgumentError             a call argument outside what the call takes (negative duration,
    │                             unknown control, a frequency of 0); also a ``ValueError``;
    │                             carries ``field``, ``value``, ``motor``
    ├── RobotClosedError          the robot was closed: no more motions, primitives or writes
    ├── FileError                 a file that cannot be read or written, or that poppy refuses to
    │                             replace (exists, not a regular file); carries ``path``, ``errno``
    ├── SetupError                a setup operation refused or could not be verified (ID taken, ...)
    ├── ConfigError               a bad robot config, move or name; carries ``file``, ``field``,
    │   │                         ``value``, ``reason`` and ``problems`` (every problem found)
    │   └── UnknownNameError      a name that is not there; carries ``kind``, ``name``, ``known``
    │       │                     (servers answer 404 for every one)
    │       ├── UnknownMotorError a motor (or group) name the robot does not have; ``motor``
    │       │   └── UnknownGroupError  a group name
    │       ├── UnknownPrimitiveError  a primitive not attached
    │       ├── UnknownMoveError  a move not in the moves folder
    │       └── UnknownCardError  a card (marker name) a detector does not know
    ├── KinematicsError           a target out of a chain's reach; carries ``nearest``
    ├── SensorError               a camera or other sensor cannot be opened or read; ``sensor``
    ├── MissingExtraError         a feature whose optional dependencies (an extra, e.g.
    │                             ``poppy[sim]``) are not installed; carries ``extra``, ``module``
    ├── PrimitiveError            a primitive's thread died; carries ``primitive`` and ``failure``
    ├── MotorLeasedError          a goal for a motor another owner drives (teleop, a move...);
    │                             carries ``motors`` and ``owner`` (servers answer 409)
    ├── ControllerError           a controller's setup failed (pypot's ``MotorsController``);
    │                             also a ``RuntimeError``
    └── CalibrationCancelled      the user cancelled a calibration (nothing was written)

This module imports nothing of ours, so every layer (protocol included) may use it.
"""

from __future__ import annotations


class PoppyError(Exception):
    """Base of every error poppy raises on purpose."""


class BusError(PoppyError):
    """Something went wrong on a bus."""

    def __init__(self, message: str, *, port: str | None = None) -> None:
        super().__init__(message)
        self.port = port


class PortError(BusError):
    """The serial port cannot be opened or used."""


class CommunicationError(BusError):
    """A transaction on the bus failed."""

    def __init__(
        self, message: str, *, port: str | None = None, motor_id: int | None = None
    ) -> None:
        super().__init__(message, port=port)
        self.motor_id = motor_id


class BusTimeout(CommunicationError):
    """No complete status packet arrived before the deadline."""


class CorruptPacketError(CommunicationError):
    """A status packet arrived with a bad checksum/CRC or a wrong shape."""


class ProtocolError(PoppyError):
    """Bytes or arguments that do not make a valid Dynamixel packet."""


class MotorError(PoppyError):
    """A motor answered with error bits set in its status packet."""

    def __init__(
        self,
        message: str,
        *,
        motor_id: int,
        errors: list[str] | None = None,
        register: str | None = None,
        port: str | None = None,
    ) -> None:
        super().__init__(message)
        self.motor_id = motor_id
        self.errors = errors or []
        self.register = register
        self.port = port


class UnknownModelError(PoppyError):
    """A model number or model name that poppy does not know."""


class RegisterError(PoppyError):
    """An unknown register, a write to a read-only register, or a value out of range."""

    def __init__(
        self, message: str, *, register: str | None = None, motor: str | None = None
    ) -> None:
        super().__init__(message)
        self.register = register
        self.motor = motor


class MissingRegisterError(RegisterError, AttributeError):
    """A register the motor's model does not have (``pid`` on an AX-12A).

    Also an ``AttributeError``: ``hasattr(motor, "pid")`` is False, as on pypot, whose motors of
    such a model had no such attribute.
    """


class ArgumentError(PoppyError, ValueError):
    """A call argument outside what the call takes (also a ``ValueError`` for old callers)."""

    def __init__(
        self,
        message: str,
        *,
        field: str | None = None,
        value: object = None,
        motor: str | None = None,
    ) -> None:
        super().__init__(message)
        self.field = field
        self.value = value
        self.motor = motor


class RobotClosedError(PoppyError):
    """The robot was closed: motions, primitives and writes are refused."""


class FileError(PoppyError):
    """A file cannot be read or written, or poppy refuses to replace what is there."""

    def __init__(self, message: str, *, path: str | None = None, errno: int | None = None) -> None:
        super().__init__(message)
        self.path = path
        self.errno = errno


class DownloadError(PoppyError):
    """A download failed or its content is not what was pinned; nothing was installed."""


class SetupError(PoppyError):
    """A setup operation was refused or could not be verified."""


class ConfigError(PoppyError):
    """A robot configuration is invalid."""

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        field: str | None = None,
        value: object = None,
        reason: str | None = None,
    ) -> None:
        super().__init__(message)
        self.file = file
        self.field = field
        self.value = value
        self.reason = reason
        self.problems: list[ConfigError] = [self]
        """Every problem found (this one alone unless a whole document was checked)."""

    @classmethod
    def of_problems(cls, problems: list[ConfigError]) -> ConfigError:
        """One error standing for several: its message is the first problem's plus a count.

        Args:
            problems: the problems, at least one, in the order they were found.
        """
        first = problems[0]
        if len(problems) == 1:
            return first
        more = len(problems) - 1
        error = cls(
            f"{first} (and {more} more problem{'s' if more > 1 else ''})",
            file=first.file,
            field=first.field,
            value=first.value,
            reason=first.reason,
        )
        error.problems = list(problems)
        return error


class SensorError(PoppyError):
    """A sensor (camera...) cannot be opened, or gave no value in time."""

    def __init__(
        self, message: str, *, sensor: str | None = None, device: str | None = None
    ) -> None:
        super().__init__(message)
        self.sensor = sensor
        self.device = device


class UnknownNameError(ConfigError):
    """A name (motor, group, primitive, move, card...) that is not there.

    Attributes:
        kind: what was looked for (``"motor"``, ``"group"``, ``"primitive"``, ``"move"``,
            ``"card"``); servers answer "not found" (404) for every kind.
        name: the name asked for.
        known: the names that are there (for the message's "did you mean").
    """

    kind_name = "name"
    """The ``kind`` of the subclass (what it looks for)."""

    def __init__(
        self,
        message: str,
        *,
        name: str,
        known: list[str] | None = None,
        kind: str | None = None,
    ) -> None:
        self.kind = kind or self.kind_name
        super().__init__(message, field=name, value=name, reason=f"unknown {self.kind}")
        self.name = name
        self.known = list(known or [])


class UnknownMotorError(UnknownNameError):
    """A motor or group name the robot does not have (``motor`` is the name asked for)."""

    kind_name = "motor"

    def __init__(
        self, message: str, *, motor: str, known: list[str] | None = None, kind: str = "motor"
    ) -> None:
        super().__init__(message, name=motor, known=known, kind=kind)
        self.motor = motor


class UnknownGroupError(UnknownMotorError):
    """A group name (an alias of several motors) the robot does not have."""

    kind_name = "group"

    def __init__(self, message: str, *, motor: str, known: list[str] | None = None) -> None:
        super().__init__(message, motor=motor, known=known, kind="group")


class UnknownPrimitiveError(UnknownNameError):
    """A primitive name that is not attached to the robot."""

    kind_name = "primitive"


class UnknownMoveError(UnknownNameError):
    """A recorded move name that is not in the moves folder."""

    kind_name = "move"


class UnknownCardError(UnknownNameError, SensorError):
    """A card (a marker's name) a detector does not know (also a ``SensorError``)."""

    kind_name = "card"

    def __init__(
        self, message: str, *, name: str, known: list[str] | None = None, sensor: str | None = None
    ) -> None:
        super().__init__(message, name=name, known=known)
        self.sensor = sensor
        self.device = None


class KinematicsError(PoppyError):
    """A kinematic chain cannot reach a target within its joint limits.

    Attributes:
        chain: the chain's name.
        target: the position asked for (m).
        nearest: the closest position the chain reached (m), or None.
        distance_m: how far ``nearest`` is from ``target``.
    """

    def __init__(
        self,
        message: str,
        *,
        chain: str | None = None,
        target: tuple[float, float, float] | None = None,
        nearest: tuple[float, float, float] | None = None,
        distance_m: float | None = None,
    ) -> None:
        super().__init__(message)
        self.chain = chain
        self.target = target
        self.nearest = nearest
        self.distance_m = distance_m


class ControllerError(PoppyError, RuntimeError):
    """A controller thread's ``setup`` failed (``poppy_core.robot.controller``); also a
    ``RuntimeError``, as pypot's ``MotorsController.start`` raised."""


class PrimitiveError(PoppyError):
    """A primitive's thread died: raised to whoever waits on it, from the original exception."""

    def __init__(self, message: str, *, primitive: str, failure: str) -> None:
        super().__init__(message)
        self.primitive = primitive
        self.failure = failure


class MotorLeasedError(PoppyError):
    """A goal refused: another owner holds the motor's lease (``motion/leases.py``)."""

    def __init__(self, message: str, *, motors: list[str], owner: str) -> None:
        super().__init__(message)
        self.motors = motors
        self.owner = owner


class CalibrationCancelled(PoppyError):
    """The user cancelled a calibration or a check; nothing was written."""


class MissingExtraError(PoppyError):
    """A feature needs an optional dependency that is not installed (``pip install 'poppy[x]'``)."""

    def __init__(self, message: str, *, extra: str, module: str) -> None:
        super().__init__(message)
        self.extra = extra
        self.module = module
