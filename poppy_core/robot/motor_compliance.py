"""A motor's compliance: free or stiff, its compliant behaviour, and safe compliance at the limits.

``MotorCompliance`` is a base of ``Motor`` (``poppy_core.robot.motor``). A compliant motor is
free (torque off); with the ``"safe"`` behaviour it is stiffened where it was pushed past an
angle limit and freed again once back inside them, checked after each present position read
(``MotorLink``'s ``on_position`` hook) and whenever compliance or its behaviour changes. Every
change holds the motor's ``MotorLink`` lock, as the sync loops do.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TYPE_CHECKING, Literal, Protocol

from poppy_core.errors import RegisterError

if TYPE_CHECKING:
    from poppy_core.robot.motor_link import MotorLink

logger = logging.getLogger(__name__)

CompliantBehavior = Literal["dummy", "safe"]
BEHAVIORS: tuple[str, ...] = ("dummy", "safe")
# A motor stiffened by safe compliance goes compliant again once this far inside its limits.
SAFE_RELEASE_MARGIN_DEG = 1.0


class CompliantBehaviorSetting(str):
    """A motor's compliant behaviour: a string (``"dummy"``/``"safe"``) that can be called to set
    it, as the Poppy documentation writes ``robot.head_z.compliant_behavior('safe')``."""

    __slots__ = ("_set",)
    _set: Callable[[str], None]

    def __new__(cls, value: str, set_behavior: Callable[[str], None]) -> CompliantBehaviorSetting:
        setting = super().__new__(cls, value)
        setting._set = set_behavior
        return setting

    def __call__(self, value: str) -> None:
        """Set the motor's compliant behaviour to ``value``."""
        self._set(value)


class ComplianceHost(Protocol):
    """What ``MotorCompliance`` needs of the motor it is mixed into (``Motor`` gives it)."""

    name: str
    wheel_mode: bool
    _link: MotorLink
    _limits: tuple[float, float]
    _behavior: CompliantBehavior

    @property
    def present_position(self) -> float:
        """Position in degrees (user frame), as last read."""
        ...

    def _set_goal(self, user_deg: float) -> None:
        """Set the goal position (clamped to the limits) without cancelling a goto."""
        ...

    def _set_behavior(self, value: str) -> None:
        """Set the compliant behaviour (``MotorCompliance`` gives it)."""
        ...

    def _apply_safe_compliance(self) -> None:
        """Stiffen or free a safe-compliant motor (``MotorCompliance`` gives it)."""
        ...


class MotorCompliance:
    """Compliance of a ``ComplianceHost`` (a ``Motor``): ``compliant``, ``torque_enabled``,
    ``compliant_behavior`` (pypot's ``safe_compliant`` flag too) and safe compliance."""

    @property
    def compliant(self: ComplianceHost) -> bool:
        """True when the motor is meant to be free (torque off)."""
        return self._link.compliant

    @compliant.setter
    def compliant(self: ComplianceHost, value: bool) -> None:
        link = self._link
        with link.lock:
            link.compliant = bool(value)
            if link.compliant:
                link.set_torque(False)
                self._apply_safe_compliance()
            elif not link.torque:
                self._set_goal(self.present_position)
                link.set_torque(True)

    @property
    def torque_enabled(self: ComplianceHost) -> bool:
        """True when the torque is (meant to be) on, including a safe-compliance stiffening."""
        return self._link.torque

    @property
    def compliant_behavior(self: ComplianceHost) -> CompliantBehaviorSetting:
        """``"dummy"``: compliant means free; ``"safe"``: free inside the limits, stiff at them.

        Set it (``m.compliant_behavior = "safe"``) or call it as the Poppy documentation does
        (``m.compliant_behavior("safe")``); read, it compares and prints as the name.
        """
        return CompliantBehaviorSetting(self._behavior, self._set_behavior)

    @compliant_behavior.setter
    def compliant_behavior(self: ComplianceHost, value: str) -> None:
        self._set_behavior(value)

    @property
    def safe_compliant(self: ComplianceHost) -> bool:
        """pypot's flag: True when the compliant behaviour is ``"safe"``."""
        return self._behavior == "safe"

    @safe_compliant.setter
    def safe_compliant(self: ComplianceHost, value: bool) -> None:
        self._set_behavior("safe" if value else "dummy")

    def _set_behavior(self: ComplianceHost, value: str) -> None:
        if value not in BEHAVIORS:
            raise RegisterError(
                f"{self.name}: compliant behavior must be 'dummy' or 'safe', not {value!r}",
                register="compliant_behavior",
                motor=self.name,
            )
        link = self._link
        with link.lock:
            self._behavior = "safe" if value == "safe" else "dummy"
            if link.compliant:
                link.set_torque(False)
                self._apply_safe_compliance()

    def _apply_safe_compliance(self: ComplianceHost) -> None:
        """Safe compliance: stiffen a compliant motor pushed past a limit, free it once back.

        Runs under the link's lock (after each present position read, or from a setter).
        """
        link = self._link
        if not (link.compliant and self._behavior == "safe") or self.wheel_mode:
            return
        if link.cached("present_position") is None:
            return
        position = self.present_position
        low, high = self._limits
        if not link.torque and not low <= position <= high:
            logger.debug("%s pushed past its limits (%.1f°): holding it", self.name, position)
            self._set_goal(position)
            link.set_torque(True)
        elif link.torque and low + SAFE_RELEASE_MARGIN_DEG <= position <= high - (
            SAFE_RELEASE_MARGIN_DEG
        ):
            link.set_torque(False)
