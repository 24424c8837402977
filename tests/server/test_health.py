"""GET /api/v1/robot/health: each bus's health, in the OpenAPI, and through RemoteRobot."""

from __future__ import annotations

import time

import httpx

from poppy_core.remote import RemoteRobot
from tests.helpers.server import Served


def test_health_route(client: httpx.Client, served: Served) -> None:
    schema = client.get("/openapi.json").json()
    assert "/api/v1/robot/health" in schema["paths"]
    assert "BusHealthInfo" in schema["components"]["schemas"]
    end = time.monotonic() + 10
    while time.monotonic() < end:
        health = client.get("/api/v1/robot/health").json()
        if health["my_dxl_controller"]["loop_hz"]["present"] > 0:
            break
        time.sleep(0.05)
    bus = health["my_dxl_controller"]
    assert bus["connected"] is True and bus["ok"] is True and bus["offline"] == []
    assert bus["target_hz"]["present"] == 50.0 and bus["loop_hz"]["present"] > 0
    assert set(bus) >= {"timeouts", "retries", "corrupt_packets", "loop_errors", "losses"}
    assert RemoteRobot(served.url).health()["my_dxl_controller"]["connected"] is True


def test_offline_motor_shows_in_health(client: httpx.Client, served: Served) -> None:
    (server,) = served.robot.emulators.values()
    server.bus.unplug(5)
    try:
        end = time.monotonic() + 10
        while time.monotonic() < end:
            bus = client.get("/api/v1/robot/health").json()["my_dxl_controller"]
            if bus["offline"] == ["m5"]:
                break
            time.sleep(0.05)
        assert bus["offline"] == ["m5"] and bus["ok"] is False and bus["connected"] is True
    finally:
        server.bus.plug(5)
