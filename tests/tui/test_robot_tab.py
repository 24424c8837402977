"""Pilot tests of the Robot tab's Primitives and Moves views, on a virtual Ergo Jr."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from textual.widgets import DataTable, Input, ProgressBar, Select  # noqa: TID253  (a TUI test)

from poppy_cli.tui.app import PoppyApp, make_app
from poppy_cli.tui.widgets.robot_panel import RobotPanel
from poppy_core.motion import MOVES_DIR_ENV, Primitive, attach_primitive, load_move
from poppy_core.robot import Robot
from tests.helpers.tui import no_ports, run_async, wait_for

SIZE = (80, 24)


@pytest.fixture
def moves_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty move library for the test."""
    monkeypatch.setenv(MOVES_DIR_ENV, str(tmp_path))
    return tmp_path


def sim_app() -> PoppyApp:
    return make_app(port_lister=no_ports, live_period_s=0)


async def open_sim(pilot: Any, app: PoppyApp) -> tuple[RobotPanel, Robot]:
    """Show the Robot tab and open the virtual Ergo Jr in it."""
    await pilot.press("f3")
    panel = app.main.query_one(RobotPanel)
    panel.open("ergo-jr", True)
    await wait_for(pilot, lambda: panel.robot is not None, what="robot opened")
    assert panel.robot is not None
    return panel, panel.robot


def notes(app: PoppyApp) -> list[str]:
    return [n.message for n in app._notifications]


def hand(robot: Robot, motor_id: int) -> Any:
    """The emulated motor ``motor_id`` (to move it by hand)."""
    (server,) = robot.emulators.values()
    return server.bus.motor(motor_id)


class Broken(Primitive):
    """A primitive whose run fails straight away."""

    def run(self) -> None:
        raise ValueError("broken on purpose")


@run_async
async def test_primitive_start_pause_stop(moves_dir: Path) -> None:
    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        panel, robot = await open_sim(pilot, app)
        await pilot.press("2")
        table = panel.query_one("#primitive-table", DataTable)
        assert table.has_focus
        assert "dance" in panel.primitives.primitives and "sinus" in panel.primitives.primitives
        dance = panel.primitives.primitives["dance"]
        dance.set_property("intro_s", 0.2)
        table.move_cursor(row=table.get_row_index("dance"))
        m1 = robot.motor("m1")
        start_goal = m1.goal_position
        await pilot.press("s")
        await wait_for(pilot, lambda: dance.state == "running" and dance.is_alive(), what="run")
        await wait_for(
            pilot, lambda: abs(m1.goal_position - start_goal) > 5, what="m1's goal moves"
        )
        assert not m1.compliant
        await wait_for(pilot, lambda: table.get_cell("dance", "state") == "running")
        await pilot.press("p")
        assert table.get_cell("dance", "state") == "paused" and dance.should_pause()
        await pilot.press("p")
        assert not dance.should_pause()
        await wait_for(pilot, lambda: dance.state == "running", what="resumed")
        await pilot.press("x")
        await wait_for(
            pilot, lambda: dance.state == "stopped" and not dance.is_alive(), what="stopped"
        )
        await wait_for(pilot, lambda: table.get_cell("dance", "state") == "stopped")


@run_async
async def test_failed_primitive_is_notified_once(moves_dir: Path) -> None:
    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        panel, robot = await open_sim(pilot, app)
        attach_primitive(robot, "broken", Broken(robot))
        panel.primitives.set_robot(robot)
        await pilot.press("2")
        table = panel.query_one("#primitive-table", DataTable)
        table.move_cursor(row=table.get_row_index("broken"))
        await pilot.press("s")
        await wait_for(pilot, lambda: table.get_cell("broken", "state") == "failed")
        assert "ValueError: broken on purpose" in table.get_cell("broken", "error")
        await pilot.pause(0.5)  # a few more refreshes: still one notification
        failures = [n for n in notes(app) if "primitive broken failed" in n]
        assert failures == ["primitive broken failed: ValueError: broken on purpose"]


@run_async
async def test_record_then_play_a_move(moves_dir: Path) -> None:
    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        panel, robot = await open_sim(pilot, app)
        await pilot.press("3")
        moves = panel.moves
        m1 = robot.motor("m1")
        moves.query_one("#move-name", Input).value = "wave"
        moves.query_one("#record-group", Select).value = "base"
        robot.motor("m6").compliant = False
        await pilot.press("r")
        recorder = moves.recorder
        assert recorder is not None
        assert all(m.compliant for m in robot.group("base"))
        assert not robot.motor("m6").compliant  # not in the group: untouched
        await wait_for(pilot, lambda: recorder.frames_recorded > 10, what="frames")
        start = m1.present_position
        hand(robot, 1).move_by_hand(40.0)
        await wait_for(
            pilot, lambda: abs(m1.present_position - start) > 30, what="m1 moved by hand"
        )
        held = m1.present_position
        await pilot.pause(0.3)
        await pilot.press("r")  # stop: saved to the library
        path = moves_dir / "wave.move"
        await wait_for(pilot, lambda: path.is_file(), what="move file")
        await wait_for(pilot, lambda: any(str(path) in n for n in notes(app)), what="notice")
        move = load_move("wave")
        assert list(move.motors) == ["m1", "m2", "m3"]
        assert len(move) > 10
        trajectory = move.trajectory("m1")
        assert trajectory[0] == pytest.approx(start, abs=1.0)
        assert trajectory[-1] == pytest.approx(held, abs=1.0)
        table = moves.query_one("#moves-table", DataTable)
        assert moves.selected == path and table.get_cell(str(path), "move") == "wave"

        hand(robot, 1).move_by_hand(-30.0)  # still compliant: it stays there
        await wait_for(pilot, lambda: abs(m1.present_position - held) > 30, what="moved away")
        # A quarter of the speed: playing lasts longer than a key press takes in the pilot.
        moves.query_one("#play-speed", Input).value = "0.25"
        await pilot.press("p")
        await wait_for(pilot, lambda: moves.player is not None, what=f"player {notes(app)}")
        player = moves.player
        assert player is not None
        await wait_for(pilot, lambda: not m1.compliant, what="stiffened")
        await wait_for(pilot, lambda: moves.player is None, timeout_s=15, what="played")
        assert not player.stopped and player.error is None and player.played_s > 0
        assert m1.goal_position == pytest.approx(held, abs=1.0)
        await wait_for(
            pilot, lambda: abs(m1.present_position - held) < 2, what="m1 follows the move"
        )
        # the app hears of the end through a message: let it handle it
        await wait_for(pilot, lambda: "wave: played" in notes(app), what="the note")
        bar = moves.query_one("#play-progress", ProgressBar)
        await wait_for(pilot, lambda: bar.progress == pytest.approx(1.0), what="a full bar")


@run_async
async def test_playback_stops_and_bad_input_is_refused(moves_dir: Path) -> None:
    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        panel, robot = await open_sim(pilot, app)
        await pilot.press("3")
        moves = panel.moves
        moves.query_one("#move-name", Input).value = "slow"
        await pilot.press("r")
        recorder = moves.recorder
        assert recorder is not None
        assert all(m.compliant for m in robot.motors)  # group "all"
        await wait_for(pilot, lambda: recorder.frames_recorded > 25, what="frames")
        await pilot.press("x")  # x saves a recording too
        await wait_for(pilot, lambda: (moves_dir / "slow.move").is_file(), what="saved")
        await wait_for(pilot, lambda: moves.selected is not None, what="listed")

        moves.query_one("#move-name", Input).value = "slow"
        await pilot.press("r")
        assert moves.recorder is None
        assert any("exists" in n for n in notes(app))

        speed = moves.query_one("#play-speed", Input)
        speed.value = "0"
        await pilot.press("p")
        assert moves.player is None
        assert any("speed must be a positive number" in n for n in notes(app))

        speed.value = "0.05"  # 20 times slower: still playing when stopped
        await pilot.press("p")
        await wait_for(pilot, lambda: moves.player is not None, what="player")
        player = moves.player
        assert player is not None and player.playing
        await pilot.press("x")
        await wait_for(pilot, lambda: moves.player is None, what="stopped")
        assert player.stopped and not player.playing
        assert "slow: stopped" in notes(app)


@run_async
async def test_the_motors_view_shows_who_drives_each_motor(moves_dir: Path) -> None:
    """A primitive running owns the motors it drives (``motion/leases.py``): the Motors view's
    "driven by" column names it, and empties once it stopped."""
    from poppy_core.motion import Sinus

    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        panel, robot = await open_sim(pilot, app)
        table = panel.query_one("#robot-table", DataTable)
        sinus = Sinus(robot, 50.0, [robot.m3], amp=10.0, freq=0.5)
        sinus.start()
        try:
            await wait_for(
                pilot,
                lambda: table.get_cell("m3", "driven by") == "primitive sinus",
                what="m3 driven by sinus",
            )
            assert table.get_cell("m1", "driven by") == ""
        finally:
            sinus.stop()
        await wait_for(pilot, lambda: table.get_cell("m3", "driven by") == "", what="freed")
