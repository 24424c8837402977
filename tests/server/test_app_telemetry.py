"""The REST app turns FastAPI's OpenTelemetry support off (a per-request cost), where it exists."""

from __future__ import annotations

import inspect

from poppy_core.server.app import no_telemetry


class OldFastAPI:
    """A FastAPI before its ``telemetry`` argument (0.110 is allowed by pyproject)."""

    def __init__(self, *, title: str = "") -> None:
        self.title = title


class NewFastAPI:
    """A FastAPI with the ``telemetry`` argument (0.16x)."""

    def __init__(self, *, title: str = "", telemetry: dict[str, bool] | None = None) -> None:
        self.telemetry = telemetry


def test_telemetry_is_turned_off_only_where_fastapi_takes_the_argument() -> None:
    assert no_telemetry(OldFastAPI) == {}
    off = no_telemetry(NewFastAPI)
    assert off == {"telemetry": {"tracing": False, "metrics": False, "logs": False}}
    NewFastAPI(**off)  # accepted as is


def test_the_installed_fastapi_builds_with_it() -> None:
    from fastapi import FastAPI

    expected = "telemetry" in inspect.signature(FastAPI).parameters
    assert ("telemetry" in no_telemetry(FastAPI)) == expected
    FastAPI(**no_telemetry(FastAPI))
