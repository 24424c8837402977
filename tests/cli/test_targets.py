"""Goto targets typed as NAME=DEGREES: the one parser of `poppy robot goto` and the TUI."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_cli.targets import TargetSyntaxError, parse_targets
from poppy_core.checks import MAX_MAGNITUDE
from poppy_core.errors import ConfigError

KNOWN = ["m1", "m2", "m3"]


@given(
    st.dictionaries(st.sampled_from(KNOWN), st.floats(-MAX_MAGNITUDE, MAX_MAGNITUDE), min_size=1)
)
def test_written_targets_read_back(targets: dict[str, float]) -> None:
    words = [f"{name}={value!r}" for name, value in targets.items()]
    assert parse_targets(words, KNOWN) == targets


def test_bad_words_say_what_was_wrong() -> None:
    with pytest.raises(TargetSyntaxError, match="is not NAME=DEGREES"):
        parse_targets(["m1:30"], KNOWN)
    with pytest.raises(TargetSyntaxError, match="'x' is not a number"):
        parse_targets(["m1=x"], KNOWN)
    with pytest.raises(TargetSyntaxError, match="finite"):
        parse_targets(["m1=nan"], KNOWN)
    with pytest.raises(TargetSyntaxError, match="no target"):
        parse_targets([], KNOWN)  # the TUI's empty goto field
    with pytest.raises(ConfigError, match=r"no motor 'm9' \(motors: m1, m2, m3\)"):
        parse_targets(["m9=1"], KNOWN)
    assert parse_targets([" m2 =-10.5"], KNOWN) == {"m2": -10.5}


def test_angles_outside_the_limits_are_clamped_to_them() -> None:
    limits: dict[str, tuple[float, float] | None] = {"m1": (-90.0, 90.0), "m2": None}
    assert parse_targets(["m1=90", "m2=1000"], KNOWN, limits) == {"m1": 90.0, "m2": 1000.0}
    assert parse_targets(["m1=90.5"], KNOWN, limits) == {"m1": 90.0}  # as the library does
    assert parse_targets(["m1=-1000"], KNOWN, limits) == {"m1": -90.0}
