"""The suite's own time limits grow with the machine's load (tests/conftest.py)."""

from __future__ import annotations

import pytest

from tests.helpers.waiting import MAX_LOAD_FACTOR

INI_TIMEOUT_S = 120  # pyproject.toml's [tool.pytest.ini_options] timeout


def _limit(request: pytest.FixtureRequest) -> float:
    marker = request.node.get_closest_marker("timeout")
    assert marker is not None, "no time limit was set for this test"
    return float(marker.args[0])


def test_a_tests_time_limit_is_the_ini_s_times_the_load_factor(
    request: pytest.FixtureRequest,
) -> None:
    assert INI_TIMEOUT_S <= _limit(request) <= INI_TIMEOUT_S * MAX_LOAD_FACTOR


@pytest.mark.timeout(7)
def test_a_limit_a_test_sets_is_scaled_too(request: pytest.FixtureRequest) -> None:
    assert 7 <= _limit(request) <= 7 * MAX_LOAD_FACTOR
