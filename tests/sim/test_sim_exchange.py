"""The fast exchange with the control tables gives what the tables' own accessors give."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_helpers import World

from poppy_core.emulator import VirtualMotor
from poppy_core.models import model_by_name
from poppy_core.sim.exchange import STATE_REGISTERS, MotorPort

MODELS = ("XL-320", "AX-12A", "MX-28", "MX-64")
values = st.floats(min_value=-2000.0, max_value=2000.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(MODELS), values, values, values, st.booleans())
def test_state_bytes_match_set_si(
    model: str, position: float, speed: float, load: float, moving: bool
) -> None:
    """In range or not (set_si clamps), the table holds the same bytes either way."""
    fast, slow = (VirtualMotor(model_by_name(model), 1) for _ in range(2))
    MotorPort(fast).write_state((position, speed, load, moving))
    for name, value in zip(STATE_REGISTERS, (position, speed, load, moving), strict=True):
        if name == "moving":
            slow.table.set(name, int(value))
        else:
            slow.table.set_si(name, value)
    assert fast.table.data == slow.table.data


def test_non_finite_state_goes_the_slow_way() -> None:
    fast, slow = (VirtualMotor(model_by_name("AX-12A"), 1) for _ in range(2))
    MotorPort(fast).write_state((math.nan, math.inf, -math.inf, False))
    slow.table.set_si("present_position", math.nan)
    slow.table.set_si("present_speed", math.inf)
    slow.table.set_si("present_load", -math.inf)
    assert fast.table.data == slow.table.data


registers = st.sampled_from(
    [
        "goal_position",
        "moving_speed",
        "torque_limit",
        "torque_enable",
        "min_position_limit",
        "max_position_limit",
    ]
)


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(MODELS), st.lists(st.tuples(registers, st.integers(0, 4095)), max_size=8))
def test_command_matches_the_motor_properties(model: str, writes: list[tuple[str, int]]) -> None:
    """After any raw writes, the port's command is what VirtualMotor's properties say."""
    motor = VirtualMotor(model_by_name(model), 1)
    port = MotorPort(motor)
    first = port.read_command()
    assert first is not None
    for name, raw in writes:
        register = motor.table.find(name)
        assert register is not None
        motor.table.set(name, min(raw, register.max_raw))
        command = port.read_command()
        low, high = motor.position_limits_deg()
        expected_goal = min(max(motor.goal_position_deg, low), high)
        current = command if command is not None else first
        assert current.goal_deg == pytest.approx(expected_goal)
        assert current.torque_on == motor.torque_enabled
        assert current.speed_limit_dps == pytest.approx(motor.speed_limit_dps)
        assert current.torque_pct == pytest.approx(motor.table.get_si("torque_limit") or 0.0)
        first = current
    assert port.read_command() is None  # nothing changed since the last read


def test_advance_carries_the_fraction_of_a_timestep(ergo: World) -> None:
    """Simulated time is the sum of the durations asked for, not rounded up per call."""
    start = ergo.sim.data.time
    timestep = float(ergo.sim.model.opt.timestep)
    for _ in range(400):
        ergo.sim.advance(0.005)  # 2.5 timesteps of 2 ms
    assert ergo.sim.data.time - start == pytest.approx(2.0, abs=timestep)
    for _ in range(300):
        ergo.sim.advance(0.0013)
    assert ergo.sim.data.time - start == pytest.approx(2.39, abs=timestep)


def test_state_is_written_at_least_every_state_period(ergo: World) -> None:
    for name in ergo.motors:
        ergo.command(name, 0.0)
    ergo.command("m1", 40.0)
    for _ in range(300):
        ergo.sim.advance(0.005)
        # written every 10 ms of simulated time: never more than two 5 ms calls old
        lag = abs(ergo.present_user_deg("m1") - ergo.sim.joint_deg("m1"))
        assert lag < 0.01 * 684.0 + 0.5  # XL-320 no-load speed × 10 ms, plus a tick
    ergo.sim.advance(0.01)
    assert ergo.present_user_deg("m1") == pytest.approx(ergo.sim.joint_deg("m1"), abs=0.3)
    assert ergo.present_user_deg("m1") == pytest.approx(40.0, abs=2.0)
