"""pypot's robot names: groups as ``alias``/``motorgroups``, attached primitives, ``to_config``.

``PypotRobotMixin`` is a base of ``Robot`` (``poppy_core.robot.robot``) and takes ``self`` as a
typed host Protocol, ``PypotRobotHost``, so mypy checks that ``Robot`` gives what it uses;
everything here is user API over what ``Robot`` holds.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

from poppy_core.errors import ConfigError
from poppy_core.robot.controller import BusController
from poppy_core.robot.group import MotorGroup
from poppy_core.robot.motor import Motor

if TYPE_CHECKING:
    from poppy_core.robot.config import RobotConfig
    from poppy_core.robot.sync import BusSync

MANAGER_KEY = "primitive_manager"
"""Where the assembly keeps the primitive manager in ``robot.extensions`` (``motion.manager``'s
``MANAGER_KEY``)."""


class Behaviour(Protocol):
    """What ``attach_primitive`` needs of a primitive (``poppy_core.motion.Primitive``)."""

    def is_alive(self) -> bool:
        """True while it runs."""
        ...


class PypotRobotHost(Protocol):
    """What ``PypotRobotMixin`` needs of the robot it is mixed into (``Robot`` gives it)."""

    extensions: dict[str, object]
    _groups: dict[str, MotorGroup]
    _syncs: list[BusSync]
    _primitive_names: list[str]

    def attach(self, name: str, obj: object) -> None:
        """Make ``obj`` reachable as ``robot.<name>``."""
        ...

    def to_robot_config(self) -> RobotConfig:
        """``to_config`` as a validated ``RobotConfig``."""
        ...

    @property
    def primitive_names(self) -> list[str]:
        """Names of the attached primitives (``PypotRobotMixin`` gives it)."""
        ...

    @property
    def primitives(self) -> list[Any]:
        """The attached primitives (``PypotRobotMixin`` gives it)."""
        ...


class PypotRobotMixin:
    """pypot's names for the groups and primitives of a ``PypotRobotHost`` (a ``Robot``), and its
    config as pypot's dict."""

    @property
    def motorgroups(self: PypotRobotHost) -> dict[str, list[Motor]]:
        """Group name -> its motors."""
        return {name: list(members) for name, members in self._groups.items()}

    @property
    def alias(self: PypotRobotHost) -> list[str]:
        """The group names (pypot's ``robot.alias``); each group is ``robot.<name>``."""
        return list(self._groups)

    @property
    def _controllers(self: PypotRobotHost) -> list[BusController]:
        """One controller per bus (pypot's name): ``io`` the bus, ``motors`` its motors,
        ``_updated`` set after each pass of its sync loops (``poppy_core.robot.controller``)."""
        return [BusController(sync) for sync in self._syncs]

    @property
    def _primitive_manager(self: PypotRobotHost) -> Any:
        """The primitive manager (pypot's name; also ``robot.primitive_manager``), attached by
        the assembly when it builds the robot (``poppy_core.motion.primitive_manager``).

        Raises:
            ConfigError: a plain robot (``poppy_core.robot.factory``) that has none yet.
        """
        manager = self.extensions.get(MANAGER_KEY)
        if manager is None:
            raise ConfigError(
                "this robot has no primitive manager: build it with poppy_core.from_config "
                "(or from_profile), or call poppy_core.motion.primitive_manager(robot)",
                field="_primitive_manager",
            )
        return manager

    def attach_primitive(self: PypotRobotHost, primitive: Behaviour, name: str) -> None:
        """Attach a primitive as ``robot.<name>`` and list it in ``primitives`` (pypot's order).

        Raises:
            ConfigError: see ``attach``.
        """
        self.attach(name, primitive)
        if isinstance(getattr(type(primitive), "name", None), property):
            primitive.name = name  # type: ignore[attr-defined]
        if name not in self._primitive_names:
            self._primitive_names.append(name)

    @property
    def primitive_names(self: PypotRobotHost) -> list[str]:
        """Names of the attached primitives, in attach order."""
        return [n for n in self._primitive_names if n in self.extensions]

    @property
    def primitives(self: PypotRobotHost) -> list[Any]:
        """The attached primitives, in attach order."""
        return [self.extensions[n] for n in self.primitive_names]

    @property
    def active_primitives(self: PypotRobotHost) -> list[Any]:
        """The attached primitives that are running (or paused)."""
        return [p for p in self.primitives if p.is_alive()]

    def to_config(self: PypotRobotHost) -> dict[str, Any]:
        """The robot's config as pypot's JSON-ready dict, with the motors' present orientation,
        offset and angle limits (``json.dump(robot.to_config(), f)`` saves it).

        Raises:
            ConfigError: the robot was not built from a config.
        """
        return self.to_robot_config().to_pypot_dict()
