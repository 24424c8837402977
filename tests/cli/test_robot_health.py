"""`poppy robot status` shows each bus's health, in its table and in --json."""

from __future__ import annotations

from typing import Any


def test_status_shows_bus_health(poppy: Any, ergo_jr: Any) -> None:
    common = ("--profile", "ergo-jr", "--port", ergo_jr.url)
    data = poppy("robot", "status", *common, "--json").json()
    bus = data["health"]["my_dxl_controller"]
    assert bus["connected"] is True and bus["port"] == ergo_jr.url
    assert bus["offline"] == [] and bus["target_hz"]["present"] == 50.0
    assert set(bus["loop_hz"]) == {"present", "goals", "gains", "limits", "sensors"}
    table = poppy("robot", "status", *common)
    assert table.code == 0, table.stderr
    assert "buses" in table.stdout and "my_dxl_controller" in table.stdout
    assert "connected" in table.stdout


def test_health_table_says_a_bus_is_lost_and_names_offline_motors() -> None:
    from rich.console import Console

    from poppy_cli.commands.robot import health_table

    bus = {
        "port": "/dev/ttyUSB0",
        "connected": False,
        "running": True,
        "down_s": 2.4,
        "loop_hz": {"present": 0.0},
        "target_hz": {"present": 50.0},
        "timeouts": 3,
        "retries": 1,
        "corrupt_packets": 0,
        "offline": ["m1", "m2"],
    }
    console = Console(record=True, width=160)
    console.print(health_table({"upper": bus}))
    text = console.export_text()
    assert "LOST 2.4 s (reopening)" in text and "m1, m2" in text and "present 0/50" in text
