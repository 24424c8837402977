"""Minimum-jerk trajectories and the dummy control's speed (pure math)."""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core.errors import ArgumentError
from poppy_core.motion import MinimumJerk, dummy_speed
from poppy_core.trajectory import GotoPlan, minimum_jerk_weight, plan_goto

angles = st.floats(-300, 300, allow_nan=False)
rates = st.floats(-200, 200, allow_nan=False)
durations = st.floats(0.05, 20, allow_nan=False)


@given(angles, angles, durations, rates, rates, rates, rates)
def test_boundaries_hold_at_both_ends(
    p0: float, p1: float, t: float, v0: float, a0: float, v1: float, a1: float
) -> None:
    traj = MinimumJerk(p0, p1, t, v0, a0, v1, a1)
    scale = 1 + abs(p0) + abs(p1) + (abs(v0) + abs(v1)) * t + (abs(a0) + abs(a1)) * t * t
    tol = 1e-7 * scale
    assert traj.position(0) == pytest.approx(p0, abs=tol)
    assert traj.velocity(0) == pytest.approx(v0, abs=tol)
    assert traj.acceleration(0) == pytest.approx(a0, abs=tol)
    assert traj.position(t) == pytest.approx(p1, abs=tol)
    assert traj.velocity(t) == pytest.approx(v1, abs=tol / t)
    assert traj.acceleration(t) == pytest.approx(a1, abs=tol / t / t)


@given(angles, angles, durations)
def test_rest_to_rest_is_monotonic_without_overshoot(p0: float, p1: float, t: float) -> None:
    traj = MinimumJerk(p0, p1, t)
    samples = [traj.position(t * k / 50) for k in range(51)]
    low, high = min(p0, p1), max(p0, p1)
    assert all(low - 1e-9 <= s <= high + 1e-9 for s in samples)
    steps = [b - a for a, b in itertools.pairwise(samples)]
    assert all(math.copysign(1, p1 - p0) * d >= -1e-9 for d in steps)
    # Symmetric bell: half way at mid-time, peak speed 1.875 * mean speed.
    assert traj.position(t / 2) == pytest.approx((p0 + p1) / 2, abs=1e-9 * (1 + abs(p0) + abs(p1)))
    assert abs(traj.velocity(t / 2)) == pytest.approx(1.875 * abs(p1 - p0) / t, rel=1e-9, abs=1e-9)


def test_held_outside_the_motion() -> None:
    traj = MinimumJerk(10, 40, 2)
    assert traj.evaluate(-1) == (10, 0)
    assert traj.position(5) == pytest.approx(40)
    assert traj.velocity(5) == pytest.approx(0, abs=1e-12)
    assert traj.done(2) and not traj.done(1.99)


@pytest.mark.parametrize("duration", [0, -1, math.nan])
def test_bad_duration_is_refused(duration: float) -> None:
    with pytest.raises(ValueError):
        MinimumJerk(0, 1, duration)


def test_dummy_speed() -> None:
    assert dummy_speed(10, -20, 3) == pytest.approx(10)
    assert dummy_speed(5, 5, 1) == 0
    assert dummy_speed(0, 90, 0) == 0


def test_goto_plan() -> None:
    smooth = plan_goto(0.0, 500.0, 2.0, "minijerk", (-90.0, 90.0))
    assert smooth.goal == 90.0 and smooth.speed == 0.0  # clamped; full speed, the curve paces
    assert smooth.trajectory is not None and smooth.trajectory.position(2.0) == 90.0
    wheel = plan_goto(0.0, 500.0, 2.0, "dummy", None)
    assert (wheel.goal, wheel.trajectory, wheel.speed) == (500.0, None, pytest.approx(250.0))
    slow = plan_goto(0.0, 0.001, 100.0, "dummy", None, min_speed=0.7)
    assert slow.speed == 0.7  # one register step, never 0 (= full speed)
    assert plan_goto(5.0, 5.0, 1.0, "dummy", None, min_speed=0.7).speed == 0.0
    at_once = plan_goto(0.0, 10.0, 0.0, "minjerk", (-90.0, 90.0))
    assert (at_once.trajectory, at_once.speed) == (None, 0.0)
    with pytest.raises(ArgumentError, match="control"):
        plan_goto(0.0, 1.0, 1.0, "teleport", None)
    with pytest.raises(ArgumentError, match="duration"):
        plan_goto(0.0, 1.0, -1.0, "dummy", None)


@pytest.mark.parametrize("control", ["minjerk", "dummy"])
@pytest.mark.parametrize("duration", [1e-300, 5e-324, 1e-4])
def test_a_goto_shorter_than_a_millisecond_is_refused(control: str, duration: float) -> None:
    """`robot goto --duration 1e-300` was a ZeroDivisionError (t**3 is 0.0): 0 is a jump, and
    anything between 0 and 1 ms is refused by the core's one rule (poppy_core.checks)."""
    with pytest.raises(ArgumentError, match=r"at least 0\.001 s"):
        plan_goto(0.0, 30.0, duration, control, (-90.0, 90.0))
    assert plan_goto(0.0, 30.0, 0.0, control, (-90.0, 90.0)) == GotoPlan(30.0, None, 0.0)


@given(angles, angles, durations, st.floats(0, 1))
def test_the_weight_is_the_rest_to_rest_curve(p0: float, p1: float, t: float, f: float) -> None:
    """Ramps and straight moves blend with the weight: it is the same curve as a goto's."""
    traj = MinimumJerk(p0, p1, t)
    blended = p0 + minimum_jerk_weight(f) * (p1 - p0)
    assert blended == pytest.approx(traj.position(f * t), abs=1e-9)
