"""`poppy robot status` shows each bus's health, in its table and in --json."""

from __future__ import annotations

from typing import Any


def test_status_shows_bus_health(poppy: Any, ergo_jr: Any) -> None:
    common = ("--profile", "ergo-jr", "--port", ergo_jr.url)
    data = poppy("robot", "status", *common, "--json").json()
    [bus] = data["buses"]
    assert bus["name"] == "my_dxl_controller"  # the config's (pypot's) controller name
    assert bus["connected"] is True and bus["port"] == ergo_jr.url
    assert bus["offline"] == [] and bus["target_hz"]["present"] == 50.0
    assert set(bus["loop_hz"]) == {"present", "goals", "gains", "limits", "sensors"}
    table = poppy("robot", "status", *common)
    assert table.code == 0, table.stderr
    assert "buses" in table.stdout and "connected" in table.stdout
    assert "connected" in table.stdout


def test_a_bus_is_shown_by_what_it_is_not_by_pypots_placeholder(poppy: Any, ergo_jr: Any) -> None:
    common = ("--profile", "ergo-jr", "--port", ergo_jr.url)
    [bus] = poppy("robot", "status", *common, "--json").json()["buses"]
    assert bus["name"] == bus["controller"] == "my_dxl_controller"  # pypot's API name, kept
    assert bus["label"] == ergo_jr.url  # what people are shown
    table = poppy("robot", "status", *common)
    assert "my_dxl_controller" not in table.stdout
    row = next(line for line in table.stdout.splitlines() if "connected" in line)
    assert row.split("│")[1].strip() == ergo_jr.url


def test_a_bus_label_is_the_ports_last_part_for_the_placeholder_only() -> None:
    from poppy_core.robot.health import bus_label

    assert bus_label("my_dxl_controller", "/dev/ttyUSB0") == "ttyUSB0"
    assert bus_label("my_dxl_controller", "/dev/serial/by-id/usb-Xevelabs_USB2AX") == (
        "usb-Xevelabs_USB2AX"
    )
    assert bus_label("my_dxl_controller", "socket://127.0.0.1:4000") == "socket://127.0.0.1:4000"
    assert bus_label("upper_body_controller", "/dev/ttyUSB1") == "upper_body_controller"


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
