"""The two angle frames of a motor, and the one conversion between them.

The *motor frame* is the servo's own angle (``poppy_core.models`` degrees, 0° mid-range): what
its position registers and its EEPROM angle limits hold, and what a config's ``angle_limit``
gives (as in pypot). The *user frame* is what a robot script sees. With ``s = +1`` (direct) or
``-1`` (indirect)::

    user = s * motor - offset          motor = s * (user + offset)
"""

from __future__ import annotations

from typing import Literal

Orientation = Literal["direct", "indirect"]


def sign_of(orientation: Orientation) -> float:
    """+1 for a direct motor, -1 for an indirect one."""
    return 1.0 if orientation == "direct" else -1.0


def to_user(motor_deg: float, orientation: Orientation, offset: float) -> float:
    """A motor-frame angle seen in the user frame."""
    return sign_of(orientation) * motor_deg - offset


def to_motor(user_deg: float, orientation: Orientation, offset: float) -> float:
    """A user-frame angle in the motor frame."""
    return sign_of(orientation) * (user_deg + offset)


def user_limits(
    motor_limits: tuple[float, float], orientation: Orientation, offset: float
) -> tuple[float, float]:
    """Motor-frame limits (a config's ``angle_limit``) as (min, max) in the user frame."""
    ends = sorted(to_user(v, orientation, offset) for v in motor_limits)
    return ends[0], ends[1]


def motor_limits(
    user_limits_deg: tuple[float, float], orientation: Orientation, offset: float
) -> tuple[float, float]:
    """User-frame limits as (min, max) in the motor frame (a config's ``angle_limit``)."""
    ends = sorted(to_motor(v, orientation, offset) for v in user_limits_deg)
    return ends[0], ends[1]
