"""Property-based API test: schemathesis fuzzes every documented operation; no answer is a 5xx."""

from __future__ import annotations

from typing import Any

import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from schemathesis.checks import not_a_server_error

from tests.helpers.server import Served


@pytest.fixture(scope="module")
def api_schema(served: Served) -> Any:
    schema = schemathesis.openapi.from_url(f"{served.url}/openapi.json")
    # Waiting gotos may last minutes (durations up to 600 s): their checks are in test_security;
    # an MJPEG stream never ends: test_sensor_routes reads one.
    return schema.exclude(path_regex="goto|stream")


schema = schemathesis.pytest.from_fixture("api_schema")


# Ten examples per operation (a hundred under `HYPOTHESIS_PROFILE=thorough`): every route and
# method is still fuzzed in every run; the profile explores further.
EXAMPLES_PER_OPERATION = settings.default.max_examples // 10


@schema.parametrize()
@settings(
    max_examples=EXAMPLES_PER_OPERATION,
    deadline=None,
    suppress_health_check=list(HealthCheck),
)
def test_no_server_error(case: Any, served: Served) -> None:
    case.call_and_validate(checks=[not_a_server_error])


def test_teardown_leaves_robot_idle(served: Served) -> None:
    served.app.state.service.close()
    for primitive in served.robot.primitives:
        primitive.stop()
    assert served.robot.active_primitives == []
