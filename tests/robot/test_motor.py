"""Motor arithmetic without a bus: frames, limits, goal speed, compliance, pending writes."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core.errors import ArgumentError, RegisterError
from poppy_core.models import model_by_name
from poppy_core.robot import Motor
from poppy_core.robot.config import MotorConfig
from poppy_core.robot.frames import motor_limits, user_limits
from poppy_core.robot.motor_link import link_of

AX = model_by_name("AX-12A")
MX = model_by_name("MX-28")
XL = model_by_name("XL-320")
XM = model_by_name("XM430-W350")


def stiff(motor: Motor, present_user: float = 0.0) -> Motor:
    """Give the motor a present position (as a read would) and switch its torque on."""
    link_of(motor).update({"present_position": motor.to_motor(present_user)})
    motor.compliant = False
    link_of(motor).take_pending(["goal_position", "torque_enable"])
    return motor


@given(
    st.sampled_from(["direct", "indirect"]),
    st.floats(-40, 40, allow_nan=False),
    st.floats(-100, 100, allow_nan=False),
)
def test_frames_are_inverse(orientation: str, offset: float, user: float) -> None:
    motor = Motor("m", MX, 1, orientation=orientation, offset=offset)  # type: ignore[arg-type]
    assert motor.to_user(motor.to_motor(user)) == pytest.approx(user)


@given(
    st.sampled_from(["direct", "indirect"]),
    st.floats(-90, 90, allow_nan=False),
    st.floats(-180, 0, allow_nan=False),
    st.floats(1, 180, allow_nan=False),
)
def test_limit_frames_are_inverse_and_ordered(
    orientation: str, offset: float, low: float, span: float
) -> None:
    user = user_limits((low, low + span), orientation, offset)  # type: ignore[arg-type]
    assert user[0] < user[1]
    assert motor_limits(user, orientation, offset) == pytest.approx((low, low + span))  # type: ignore[arg-type]


def test_config_limits_are_motor_frame_and_the_motor_shows_them_in_the_user_frame() -> None:
    """pypot's reading of poppy_torso.json: l_elbow_y (direct, offset -90) [-140, 0]."""
    entry = MotorConfig(
        id=44, type="MX-28", orientation="direct", offset=-90.0, angle_limit=(-140.0, 0.0)
    )
    assert entry.user_angle_limit == (-50.0, 90.0)
    motor = Motor.from_config("l_elbow_y", entry, MX)
    assert motor.angle_limit == (-50.0, 90.0)
    assert motor.motor_limits() == (-140.0, 0.0) == motor.config_limits()
    right = MotorConfig(
        id=54, type="MX-28", orientation="indirect", offset=-90.0, angle_limit=(0.0, 147.0)
    )
    assert Motor.from_config("r_elbow_y", right, MX).angle_limit == (-57.0, 90.0)


def test_indirect_flips_and_offset_adds() -> None:
    motor = Motor("m", AX, 1, orientation="indirect", offset=20.0, angle_limit=(-40, 8))
    link_of(motor).update({"present_position": 10.0, "present_speed": 5.0, "present_load": -12.0})
    assert motor.present_position == pytest.approx(-30.0)  # -(10) - 20
    assert motor.present_speed == -5.0
    assert motor.present_load == 12.0
    stiff(motor, -30.0)
    motor.goal_position = 0.0
    assert motor.goal_position == pytest.approx(0.0)
    register = AX.register("goal_position")
    raw = link_of(motor).take_pending(["goal_position"])["goal_position"]
    assert register.to_si(raw) == pytest.approx(-20.0, abs=0.3)  # motor = -(0 + 20)


def test_goal_clamped_to_user_limits_and_model_range() -> None:
    motor = stiff(Motor("m", XL, 2, orientation="indirect", angle_limit=(-90, 125)))
    motor.goal_position = 170
    assert motor.goal_position == 125
    motor.goal_position = -1000
    assert motor.goal_position == -90
    assert motor.motor_limits() == (-125, 90)
    whole = stiff(Motor("w", AX, 3, angle_limit=(-150, 150)))
    whole.goal_position = 150  # past the last raw step (149.7°): clamped, no RegisterError
    assert link_of(whole).take_pending(["goal_position"]) == {"goal_position": 1023}


def test_goal_waits_while_compliant() -> None:
    motor = Motor("m", MX, 1)
    link_of(motor).update({"present_position": 12.0})
    motor.goal_position = 30
    assert link_of(motor).take_pending(["goal_position"]) == {}
    motor.compliant = False  # goal = present, then torque on
    pending = link_of(motor).take_pending(["goal_position", "torque_enable"])
    assert pending["torque_enable"] == 1
    goal = MX.register("goal_position").to_si(pending["goal_position"])
    assert goal == pytest.approx(12, abs=0.1)


def test_goal_speed_uses_limits() -> None:
    motor = stiff(Motor("m", AX, 1, orientation="indirect", angle_limit=(-40, 30)), 5.0)
    motor.goal_speed = 20
    assert motor.goal_position == 30 and motor.moving_speed == 20 and motor.goal_speed == 20
    motor.goal_speed = -1e6
    assert motor.goal_position == -40
    assert motor.moving_speed == pytest.approx(AX.no_load_speed_dps)
    motor.goal_speed = 0
    assert motor.goal_position == pytest.approx(5.0) and motor.goal_speed == 0
    motor.goal_speed = 0.01  # below one step: sent as the smallest speed, never 0 (= full)
    assert motor.moving_speed > 0
    motor.goal_position = 0
    assert motor.goal_speed == 0


def test_safe_compliance_stiffens_past_a_limit() -> None:
    motor = Motor("m", MX, 1, angle_limit=(-30, 30))
    motor.compliant_behavior = "safe"
    motor.compliant = True
    link_of(motor).update({"present_position": 10.0})
    assert not motor.torque_enabled
    link_of(motor).update({"present_position": 42.0})
    assert motor.torque_enabled and motor.compliant
    assert motor.goal_position == 30
    link_of(motor).update({"present_position": 29.5})  # still at the wall: keeps holding
    assert motor.torque_enabled
    link_of(motor).update({"present_position": 20.0})  # pulled back inside: free again
    assert not motor.torque_enabled
    motor.compliant_behavior = "dummy"
    link_of(motor).update({"present_position": 50.0})
    assert not motor.torque_enabled
    with pytest.raises(RegisterError):
        motor.compliant_behavior = "soft"


def test_model_specific_registers() -> None:
    ax, mx, xm = Motor("a", AX, 1), Motor("b", MX, 2), Motor("c", XM, 3)
    assert "compliance_margin" in ax.registers and "pid" not in ax.registers
    assert "pid" in mx.registers and "torque_limit" not in xm.registers
    mx.pid = (4.0, 0.0, 1.0)
    assert mx.pid == (4.0, 0.0, 1.0)
    gains = ["p_gain", "i_gain", "d_gain"]
    assert set(link_of(mx).take_pending(gains)) == set(gains)
    ax.compliance_margin = 2
    assert ax.compliance_margin == (2, 2)
    with pytest.raises(RegisterError):
        ax.pid = (1.0, 0.0, 0.0)
    with pytest.raises(RegisterError):
        mx.compliance_slope = 32
    assert xm.torque_limit == 100.0
    with pytest.raises(RegisterError):
        xm.torque_limit = 50
    mx.max_torque = 40
    assert mx.torque_limit == 40
    with pytest.raises(RegisterError):
        mx.torque_limit = 150
    with pytest.raises(RegisterError):
        mx.moving_speed = -5


def test_restore_keeps_newer_values() -> None:
    motor = stiff(Motor("m", MX, 1))
    motor.moving_speed = 10
    taken = link_of(motor).take_pending(["moving_speed"])
    motor.moving_speed = 20
    link_of(motor).restore_pending(taken)
    newer = link_of(motor).take_pending(["moving_speed"])["moving_speed"]
    assert MX.register("moving_speed").to_si(newer) == pytest.approx(20, abs=0.7)


def test_bad_limits_refused() -> None:
    with pytest.raises(RegisterError):
        Motor("m", MX, 1, angle_limit=(10, -10))
    motor = Motor("m", MX, 1)
    with pytest.raises(RegisterError):
        motor.angle_limit = (5, 5)


SYNC_SIDE = {
    "update",
    "take_pending",
    "restore_pending",
    "has_pending",
    "mark_missed",
    "mark_answered",
    "mark_offline",
    "mark_closed",
    "resend_state",
    "set_goal",
    "set_torque",
    "attach_runner",
    "cached",
    "cached_number",
    "store",
    "runner",
    "lock",
    "torque",
}
USER_API = {
    "id",
    "name",
    "model",
    "orientation",
    "offset",
    "direct",
    "wheel_mode",
    "online",
    "errors",
    "present_position",
    "present_speed",
    "present_load",
    "present_temperature",
    "present_voltage",
    "temperature",
    "voltage",
    "load",
    "goal_position",
    "goal_speed",
    "moving_speed",
    "torque_limit",
    "max_torque",
    "compliant",
    "compliant_behavior",
    "safe_compliant",
    "torque_enabled",
    "goto_behavior",
    "goto_position",
    "angle_limit",
    "lower_limit",
    "upper_limit",
    "control_mode",
    "registers",
    "led",
    "to_user",
    "to_motor",
    "motor_limits",
    "config_limits",
    "from_config",
}


@pytest.mark.parametrize("model", [AX, MX, XL, XM], ids=lambda m: m.name)
def test_tab_completion_shows_the_user_api_and_not_the_sync_side(model: object) -> None:
    motor = Motor("m", model, 1)  # type: ignore[arg-type]
    public = {n for n in dir(motor) if not n.startswith("_")}
    assert public & SYNC_SIDE == set()
    assert USER_API - public == set()
    assert set(motor.registers) - public == set()
    link = link_of(motor)  # the robot's side is still there, one step away
    assert SYNC_SIDE - {"attach_runner", "cached_number"} - set(dir(link)) == set()


def test_the_sync_loop_side_is_not_on_the_users_motor() -> None:
    motor = Motor("m", MX, 1)
    public = {name for name in dir(motor) if not name.startswith("_")}
    assert public.isdisjoint(SYNC_SIDE), public & SYNC_SIDE
    assert {"goal_position", "present_position", "compliant", "online"} <= public
    assert link_of(motor).take_pending(["goal_position"]) == {}


@pytest.mark.parametrize("model", [AX, MX, XL, XM], ids=lambda m: m.name)
def test_speeds_beyond_the_register_are_capped_as_pypot(model: object) -> None:
    # pypot accepted `m.moving_speed = 10000` and capped it to the servo's top speed (its
    # speed_to_dxl); the lead's decision for poppy: clamp what is beyond a register's range.
    motor = stiff(Motor("m", model, 1))  # type: ignore[arg-type]
    register = motor.model.register("moving_speed")
    top = max(abs(float(register.to_si(0x3FF))), float(register.to_si(register.max_raw)))
    for huge in (10000, top * 10, 1e12, 10**400):
        motor.moving_speed = huge
        assert motor.moving_speed == pytest.approx(min(huge, top))
    raw = link_of(motor).take_pending(["moving_speed"])["moving_speed"]
    assert register.to_si(raw) == pytest.approx(top)
    motor.moving_speed = 100  # within the range: kept as given
    assert motor.moving_speed == pytest.approx(100, abs=1.0)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf"), "fast", None, True])
@pytest.mark.parametrize(
    "register", ["moving_speed", "goal_position", "goal_speed", "torque_limit", "pid"]
)
def test_non_finite_and_wrong_types_are_refused(register: str, bad: object) -> None:
    motor = stiff(Motor("m4", MX, 4))
    link_of(motor).take_pending(MX.registers)
    value = (bad, 0.0, 0.0) if register == "pid" else bad
    with pytest.raises(ArgumentError, match=rf"m4\.{register} must be a"):
        setattr(motor, register, value)
    assert not link_of(motor).has_pending()  # nothing was queued for the servo


def test_pid_gains_are_capped_to_their_registers() -> None:
    motor = stiff(Motor("m", MX, 1))
    motor.pid = (100.0, -3.0, 1e9)  # pypot truncated each gain to its register's 0-254
    p, i, d = motor.pid
    assert p == pytest.approx(254 / 8) and i == 0.0 and d == pytest.approx(254 * 4 / 1000)
