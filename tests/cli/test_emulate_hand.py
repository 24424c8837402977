"""`poppy emulate --control`'s hand commands: parsed lines, and the process driven on stdin."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from poppy_cli.commands.emulate_hand import HandCommands, Joint
from poppy_core.emulator import Hand, VirtualBus, build_bus_from_spec
from poppy_core.emulator.control import ControlError
from poppy_core.motion import Move, write_move


@pytest.fixture
def bus() -> Iterator[VirtualBus]:
    virtual = build_bus_from_spec("XL-320:1-3", protocol=2)
    yield virtual
    virtual.hand.close()


def where(commands: HandCommands) -> str:
    return commands.execute("where", [])


def test_hand_commands(bus: VirtualBus) -> None:
    commands = HandCommands(Hand(bus), {"base": Joint(1, "indirect", 10.0), "top": Joint(2)})
    assert commands.execute("move", ["base", "20", "--over", "0.2", "--linear"]).startswith(
        "hand: base to 20°"
    )
    assert commands.hand.wait(10.0)
    # base is indirect with a 10° offset: 20° on the robot is -30° on the servo
    assert bus.motor(1).present_position_deg == pytest.approx(-30.0, abs=0.3)
    assert re.search(r"^base (19\.[7-9]|20\.[0-3])° \(held\), top 0\.0°, 3 0\.0°$", where(commands))
    commands.execute("move", ["3", "-12"])
    assert re.search(r", 3 -1[12]\.\d° \(held\)$", where(commands))
    assert commands.execute("release", ["all"]) == "hand: released all"
    assert "(held)" not in commands.execute("where", [])


def test_hand_commands_play_a_move_file(bus: VirtualBus, tmp_path: Path) -> None:
    path = tmp_path / "wave.move"
    write_move(Move(10, ["top"], np.linspace(0.0, 30.0, 6)[:, None]), path)
    commands = HandCommands(Hand(bus), {"top": Joint(2, "direct", 0.0)})
    assert commands.execute("play", [str(path), "--speed", "2"]) == (
        f"hand: playing {path} (1 motors, 0.25 s)"
    )
    assert commands.hand.wait(10.0)
    assert bus.motor(2).present_position_deg == pytest.approx(30.0, abs=0.3)


@pytest.mark.parametrize(
    ("name", "args", "message"),
    [
        ("move", ["1"], "usage: move ID|NAME DEGREES"),
        ("move", ["1", "x"], "move takes degrees, not 'x'"),
        ("move", ["1", "5", "--over"], "usage: move"),
        ("move", ["1", "5", "--over", "soon"], "--over takes seconds, not 'soon'"),
        ("move", ["1", "5", "--over", "1e9"], "a gesture lasts 0-3600 s"),
        ("move", ["elbow", "5"], "no motor 'elbow' (names: base)"),
        ("move", ["7", "5"], "no motor 7 (motors: 1, 2, 3)"),
        ("move", ["1", "inf"], "degrees must be a finite number"),
        ("release", [], "usage: release ID|NAME|all"),
        ("where", ["now"], "usage: where"),
        ("play", [], "usage: play FILE"),
        ("play", ["/nonexistent/x.move"], "/nonexistent/x.move"),
    ],
)
def test_bad_hand_commands_are_one_line_errors(
    bus: VirtualBus, name: str, args: list[str], message: str
) -> None:
    commands = HandCommands(Hand(bus), {"base": Joint(1)})
    with pytest.raises(ControlError, match=re.escape(message)) as caught:
        commands.execute(name, args)
    assert "\n" not in str(caught.value)


def test_play_without_a_profile_says_what_to_do(bus: VirtualBus) -> None:
    with pytest.raises(ControlError, match="play needs --profile"):
        HandCommands(Hand(bus)).execute("play", ["x.move"])
    with pytest.raises(ControlError, match="give an ID"):
        HandCommands(Hand(bus)).execute("move", ["m1", "3"])
