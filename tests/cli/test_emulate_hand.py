"""`poppy emulate --control`'s hand commands: parsed lines, and the process driven on stdin."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from poppy_cli.commands.emulate_hand import HandCommands, HandJoint
from poppy_core.emulator import Hand, VirtualBus, build_bus_from_spec
from poppy_core.emulator.control import ControlError
from poppy_core.motion import Move, read_move, write_move
from tests.helpers.cli import POPPY, command_env, no_user_settings
from tests.helpers.processes import start
from tests.helpers.waiting import eventually, scaled

ARRIVED = re.compile(r"^m1 (39\.[7-9]|40\.[0-3])° \(held\), m2 -(29\.[7-9]|30\.[0-3])° \(held\)")


@pytest.fixture
def bus() -> Iterator[VirtualBus]:
    virtual = build_bus_from_spec("XL-320:1-3", protocol=2)
    yield virtual
    virtual.hand.close()


def where(commands: HandCommands) -> str:
    return commands.execute("where", [])


def test_hand_commands(bus: VirtualBus) -> None:
    commands = HandCommands(
        Hand(bus), {"base": HandJoint(1, "indirect", 10.0), "top": HandJoint(2)}
    )
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
    commands = HandCommands(Hand(bus), {"top": HandJoint(2, "direct", 0.0)})
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
    commands = HandCommands(Hand(bus), {"base": HandJoint(1)})
    with pytest.raises(ControlError, match=re.escape(message)) as caught:
        commands.execute(name, args)
    assert "\n" not in str(caught.value)


def test_play_without_a_profile_says_what_to_do(bus: VirtualBus) -> None:
    with pytest.raises(ControlError, match="play needs --profile"):
        HandCommands(Hand(bus)).execute("play", ["x.move"])
    with pytest.raises(ControlError, match="give an ID"):
        HandCommands(Hand(bus)).execute("move", ["m1", "3"])


def test_poppy_record_records_what_the_emulators_hand_does(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`poppy emulate --profile ergo-jr --control` on a pty, driven through its stdin, while
    `poppy record` on that pty records the motion the hand makes."""
    library = no_user_settings(tmp_path, monkeypatch, moves=True)
    env = dict(os.environ, **command_env())
    emulator = subprocess.Popen(
        [*POPPY, "emulate", "--profile", "ergo-jr", "--control"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    assert emulator.stdin is not None and emulator.stdout is not None
    said_by_emulator: list[str] = []
    reader = threading.Thread(
        target=lambda: said_by_emulator.extend(emulator.stderr or ()), daemon=True
    )
    recorder = None
    try:
        url = emulator.stdout.readline().strip()
        reader.start()
        assert url.startswith("/dev/"), url
        args = ["record", "byhand", "--profile", "ergo-jr", "--port", url, "--motors", "m1,m2"]
        recorder = start([*POPPY, *args], env, stdin=subprocess.DEVNULL)
        assert recorder.stderr is not None
        said = [recorder.stderr.readline()]  # a warning first: the factory return delays
        while not said[-1].startswith("recording") and said[-1] and len(said) < 5:
            said.append(recorder.stderr.readline())
        assert said[-1].startswith("recording"), "".join(said)
        emulator.stdin.write("move m1 40 --over 2\nmove m2 -30 --over 2\nmove m9 1\n")
        emulator.stdin.flush()

        def arrived() -> bool:  # asks `where` until the emulator says the hand got there
            emulator.stdin.write("where\n")
            emulator.stdin.flush()
            return any(ARRIVED.search(line) for line in list(said_by_emulator))

        assert eventually(arrived, timeout_s=30.0, interval_s=0.2), "".join(said_by_emulator)
        time.sleep(1.0)  # the recorder reads the held pose at least once more (50 Hz)
        recorder.send_signal(signal.SIGINT)
        _, stderr = recorder.communicate(timeout=scaled(30))
        assert recorder.returncode == 0, stderr
    finally:
        if recorder is not None and recorder.poll() is None:
            recorder.kill()
        emulator.stdin.write("release all\n")
        emulator.stdin.flush()
        emulator.send_signal(signal.SIGINT)
        emulator.wait(timeout=scaled(20))
        reader.join(10.0)
    err = "".join(said_by_emulator)
    assert emulator.returncode == 0, err
    assert "hand: m1 to 40° over 2 s" in err
    assert "error: no motor 'm9' (names: m1, m2, m3, m4, m5, m6)" in err
    move = read_move(library / "byhand.move")
    assert move.motors == ("m1", "m2")
    last = move.frame(-1)
    assert last["m1"] == pytest.approx(40.0, abs=1.0)
    assert last["m2"] == pytest.approx(-30.0, abs=1.0)
    m1 = move.trajectory("m1")
    assert ((m1 > 5.0) & (m1 < 35.0)).any()  # frames along the way, not a jump
