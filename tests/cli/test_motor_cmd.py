"""`poppy motor ...` against a `poppy emulate` process, through a real pty."""

from __future__ import annotations

import time
from typing import Any

P1 = ("--baud", "1000000", "--protocol", "1")
P2 = ("--baud", "1000000", "--protocol", "2")


def test_get_prints_degrees(poppy: Any, mx_bus: Any) -> None:
    result = poppy("motor", "get", "11", "present_position", "--port", mx_bus.url)
    assert result.code == 0, result.stderr
    assert result.stdout.strip() == "0 °"


def test_set_goal_moves_the_virtual_motor(poppy: Any, mx_bus: Any) -> None:
    port = ("--port", mx_bus.url, *P1)
    assert poppy("motor", "torque", "11", "on", *port).code == 0
    result = poppy("motor", "set", "11", "goal_position", "30", *port)
    assert result.code == 0, result.stderr
    assert "goal_position = 29.97 °" in result.stdout
    deadline = time.monotonic() + 5
    position = None
    while time.monotonic() < deadline:
        [position] = poppy("motor", "get", "11", "present_position", "--json", *port).json()
        if abs(position["present_position"] - 30) < 0.5:
            break
    assert position is not None and abs(position["present_position"] - 30) < 0.5


def test_get_several_motors_and_registers_as_json(poppy: Any, mx_bus: Any) -> None:
    result = poppy(
        "motor",
        "get",
        "11-13",
        "present_voltage",
        "present_temperature",
        "--json",
        "--port",
        mx_bus.url,
        *P1,
    )
    assert result.code == 0, result.stderr
    values = result.json()
    assert [row["id"] for row in values] == [11, 12, 13]
    assert 9 < values[0]["present_voltage"] < 16
    assert 15 < values[1]["present_temperature"] < 60


def test_info_shows_the_whole_control_table(poppy: Any, ergo_jr: Any) -> None:
    result = poppy("motor", "info", "3", "--json", "--port", ergo_jr.url, *P2)
    assert result.code == 0, result.stderr
    info = result.json()
    assert info["model"] == "XL-320" and info["model_number"] == 350
    registers = {register["name"]: register for register in info["registers"]}
    assert registers["id"]["value"] == 3
    assert registers["baudrate"]["value"] == 1_000_000
    assert registers["model_number"]["access"] == "R"
    assert registers["goal_position"]["memory"] == "RAM"
    assert registers["led"]["value"] == "off"


def test_led_colour_on_xl320(poppy: Any, ergo_jr: Any) -> None:
    port = ("--port", ergo_jr.url, *P2)
    assert poppy("motor", "led", "2", "green", *port).code == 0
    assert poppy("motor", "get", "2", "led", "--json", *port).json() == [{"id": 2, "led": "green"}]
    assert poppy("motor", "led", "2", "on", "--json", *port).json() == [{"id": 2, "led": "white"}]
    assert poppy("motor", "led", "2", "off", *port).code == 0
    assert poppy("motor", "get", "2", "led", *port).stdout.strip() == "off"


def test_set_out_of_range_is_refused_in_one_line(poppy: Any, mx_bus: Any) -> None:
    result = poppy("motor", "set", "11", "moving_speed", "99999", "--port", mx_bus.url, *P1)
    assert result.code == 1
    assert "moving_speed" in result.stderr and "Traceback" not in result.stderr


def test_set_read_only_register_is_refused(poppy: Any, mx_bus: Any) -> None:
    result = poppy("motor", "set", "11", "present_position", "3", "--port", mx_bus.url, *P1)
    assert result.code == 1
    assert "read-only" in result.stderr


def test_unknown_register_suggests_names(poppy: Any, mx_bus: Any) -> None:
    result = poppy("motor", "get", "11", "present_positon", "--port", mx_bus.url, *P1)
    assert result.code == 1
    assert "present_position" in result.stderr


def test_missing_motor_is_one_line(poppy: Any, mx_bus: Any) -> None:
    result = poppy("motor", "get", "99", "present_position", "--port", mx_bus.url, *P1)
    assert result.code == 1
    assert "99" in result.stderr and "Traceback" not in result.stderr


def test_set_id_refuses_a_taken_id_then_changes_a_free_one(poppy: Any, mx_bus: Any) -> None:
    port = ("--port", mx_bus.url, *P1)
    taken = poppy("motor", "set-id", "12", "11", *port)
    assert taken.code == 1
    assert "already taken" in taken.stderr
    moved = poppy("motor", "set-id", "12", "20", "--json", *port)
    assert moved.code == 0, moved.stderr
    assert moved.json()["verified"] is True
    ids = [m["id"] for m in poppy("scan", "--port", mx_bus.url, "--protocol", "1", "--json").json()]
    assert ids == [11, 13, 20, 36]


def test_set_baudrate_then_found_at_the_new_rate(poppy: Any, mx_bus: Any) -> None:
    result = poppy("motor", "set-baudrate", "13", "57600", "--port", mx_bus.url, *P1)
    assert result.code == 0, result.stderr
    found = poppy(
        "scan", "--port", mx_bus.url, "--protocol", "1", "--baud", "57600", "--json"
    ).json()
    assert [(m["id"], m["baud"]) for m in found] == [(13, 57600)]
    # without --baud the motor is searched for over the standard rates
    assert poppy("motor", "get", "13", "id", "--port", mx_bus.url).stdout.strip() == "13"


def test_return_delay_and_angle_limits(poppy: Any, mx_bus: Any) -> None:
    port = ("--port", mx_bus.url, *P1)
    assert poppy("motor", "set-return-delay", "11", "0", *port).code == 0
    assert poppy("motor", "get", "11", "return_delay_time", *port).stdout.strip() == "0 µs"
    assert poppy("motor", "angle-limits", "11", *port, "--", "-90", "90").code == 0
    [limits] = poppy("motor", "angle-limits", "11", "--json", *port).json()
    assert abs(limits["min"] + 90) < 0.1 and abs(limits["max"] - 90) < 0.1


def test_reset_prepares_a_new_motor_for_poppy(poppy: Any, emulator_factory: Any) -> None:
    emulator = emulator_factory("--motors", "MX-28:1", "--baud", "57600")
    result = poppy(
        "motor",
        "reset",
        "1",
        "42",
        "--angle-limits",
        "-100,100",
        "--json",
        "--port",
        emulator.url,
        "--baud",
        "57600",
        "--protocol",
        "1",
    )
    assert result.code == 0, result.stderr
    assert result.json()["id"] == 42 and result.json()["baud"] == 1_000_000
    found = poppy("scan", "--port", emulator.url, "--protocol", "1", "--json").json()
    assert [(m["id"], m["baud"]) for m in found] == [(42, 1_000_000)]
    port = ("--port", emulator.url, *P1)
    assert poppy("motor", "get", "42", "return_delay_time", *port).stdout.strip() == "0 µs"


def test_reboot_and_factory_reset(poppy: Any, ergo_jr: Any) -> None:
    port = ("--port", ergo_jr.url, *P2)
    assert poppy("motor", "set", "4", "max_torque", "50", *port).code == 0
    assert poppy("motor", "reboot", "4", *port).code == 0
    refused = poppy("motor", "factory-reset", "4", *port, input="n\n")
    assert refused.code != 0
    reset = poppy("motor", "factory-reset", "4", "--yes", *port)
    assert reset.code == 0, reset.stderr
    assert poppy("motor", "get", "4", "max_torque", *port).stdout.strip() == "100 %"
    assert poppy("motor", "get", "4", "id", *port).stdout.strip() == "4"


def test_port_is_required(poppy: Any, monkeypatch: Any) -> None:
    monkeypatch.delenv("POPPY_PORT", raising=False)
    result = poppy("motor", "get", "1", "id")
    assert result.code == 2
    assert "--port" in result.stderr


def test_every_command_has_help(poppy: Any) -> None:
    for args in (
        [],
        ["scan"],
        ["ports"],
        ["emulate"],
        ["demo"],
        ["motor"],
        *(
            ["motor", c]
            for c in (
                "info",
                "get",
                "set",
                "set-id",
                "set-baudrate",
                "set-return-delay",
                "angle-limits",
                "reset",
                "reboot",
                "factory-reset",
                "torque",
                "led",
            )
        ),
    ):
        result = poppy(*args, "--help")
        assert result.code == 0, (args, result.stderr)
        assert "Usage" in result.stdout


def test_a_goal_to_a_compliant_motor_says_why_it_does_not_move(poppy: Any, ergo_jr: Any) -> None:
    port = ("--port", ergo_jr.url, *P2)
    written = poppy("motor", "set", "2", "goal_position", "-60", *port)  # no `--` needed
    assert written.code == 0, written.stderr
    assert written.stdout.strip() == "motor 2: goal_position = -60.06 °"
    note = written.stderr.strip()
    assert note.startswith("note: motor 2 is compliant") and "\n" not in note
    stiffen = note.split("`")[1]
    assert stiffen == f"poppy motor torque 2 on --port {ergo_jr.url}"
    assert poppy(*stiffen.split()[1:]).code == 0
    again = poppy("motor", "set", "2", "goal_position", "-60", *port)
    assert again.code == 0 and again.stderr == ""
    position = -999.0
    deadline = time.monotonic() + 10
    while abs(position + 60) > 0.5 and time.monotonic() < deadline:
        [row] = poppy("motor", "get", "2", "present_position", "--json", *port).json()
        position = row["present_position"]
    assert abs(position + 60) < 0.5
    quiet = poppy("motor", "set", "3", "goal_position", "10", "--json", *port)
    assert quiet.code == 0 and quiet.stderr == ""  # --json: data only


def test_negative_values_need_no_double_dash(poppy: Any, ergo_jr: Any) -> None:
    port = ("--port", ergo_jr.url, *P2)
    limits = poppy("motor", "angle-limits", "4-5", "-90.5", "1e2", *port)  # an ID list too
    assert limits.code == 0, limits.stderr
    read = poppy("motor", "angle-limits", "4,5", "--json", *port).json()
    assert [r["id"] for r in read] == [4, 5]
    assert all(abs(r["min"] + 90.5) < 0.3 and abs(r["max"] - 100) < 0.3 for r in read), read
    unknown = poppy("motor", "set", "4", "goal_position", "-6", "--jsn", *port)
    assert unknown.code == 2 and "No such option: --jsn" in unknown.stderr


def test_set_return_delay_and_reboot_take_id_lists(poppy: Any, ergo_jr: Any) -> None:
    port = ("--port", ergo_jr.url, *P2)
    assert poppy("motor", "torque", "1,3", "on", *port).code == 0  # their EEPROM is locked
    result = poppy("motor", "set-return-delay", "1-3,5", "0", "--json", *port)
    assert result.code == 0, result.stderr
    assert [r["id"] for r in result.json()] == [1, 2, 3, 5]
    rows = poppy("motor", "get", "1-6", "return_delay_time", "torque_enable", "--json", *port)
    assert [r["return_delay_time"] for r in rows.json()] == [0, 0, 0, 500, 0, 500]
    assert [r["torque_enable"] for r in rows.json()] == [1, 0, 1, 0, 0, 0]
    rebooted = poppy("motor", "reboot", "5-6", *port)
    assert rebooted.code == 0 and rebooted.stdout.count("verified") == 2
