"""How long a fleet's robots have to answer: 2 s, or ``$POPPY_FLEET_TIMEOUT_S`` (a slow network,
busy robots); a bad value is refused in one line, by the library and by `poppy fleet`."""

from __future__ import annotations

import pytest

from poppy_core.errors import ConfigError
from poppy_core.remote import zenoh_fleet
from tests.helpers.cli import run_poppy


@pytest.mark.parametrize(
    ("value", "seconds"), [("", 2.0), ("5", 5.0), (" 0.25 ", 0.25), ("60", 60.0)]
)
def test_the_fleets_timeout_is_two_seconds_or_the_variables(
    value: str, seconds: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(zenoh_fleet.TIMEOUT_ENV, value)
    assert zenoh_fleet.fleet_timeout_s() == seconds


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf", "61", "soon"])
def test_a_bad_timeout_is_refused_in_one_line(value: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(zenoh_fleet.TIMEOUT_ENV, value)
    with pytest.raises(ConfigError, match=r"^POPPY_FLEET_TIMEOUT_S='.*' is not a time-out: give "):
        zenoh_fleet.fleet_timeout_s()


def test_poppy_fleet_refuses_a_bad_timeout_in_one_line() -> None:
    result = run_poppy(
        "fleet", "list", "--connect", "tcp/127.0.0.1:1", env={"POPPY_FLEET_TIMEOUT_S": "soon"}
    )
    assert result.code == 2, result
    assert result.stderr.startswith("error: POPPY_FLEET_TIMEOUT_S='soon' is not a time-out")
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr
