"""Property tests: every raw value of every register survives raw → SI → raw."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poppy_core.errors import RegisterError
from poppy_core.models import ALL_MODELS, Register

REGISTERS = [
    pytest.param(reg, id=f"{model.name}.{reg.name}")
    for model in ALL_MODELS
    for reg in model.registers.values()
]


@pytest.mark.parametrize("reg", REGISTERS)
@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_raw_si_raw_round_trip(reg: Register, data: st.DataObject) -> None:
    raw = data.draw(st.integers(reg.min_raw, reg.max_raw))
    value = reg.to_si(raw)
    assert reg.from_si(value) == raw
    assert reg.decode(reg.encode(raw)) == raw


@pytest.mark.parametrize("reg", REGISTERS)
def test_range_ends_round_trip(reg: Register) -> None:
    for raw in (reg.min_raw, reg.max_raw):
        assert reg.from_si(reg.to_si(raw)) == raw


@given(value=st.floats(min_value=-150.0, max_value=149.7))
def test_si_raw_si_stays_within_half_a_tick(value: float) -> None:
    reg = ALL_MODELS[0].register("goal_position")
    back = reg.to_si(reg.from_si(value))
    assert isinstance(back, float)
    assert abs(back - value) <= 300 / 1024 / 2 + 1e-9


@given(value=st.floats(allow_nan=False, allow_infinity=False))
def test_from_si_returns_in_range_or_raises(value: float) -> None:
    for model in ALL_MODELS:
        reg = model.register("goal_position")
        try:
            raw = reg.from_si(value)
        except RegisterError as exc:
            assert "goal_position" in str(exc)
        else:
            assert reg.min_raw <= raw <= reg.max_raw
