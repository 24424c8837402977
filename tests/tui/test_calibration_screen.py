"""The Robot tab's calibration: guided in a modal screen, reviewed, written to the user profile."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml
from textual.widgets import Button  # noqa: TID253  (a TUI test)

from poppy_cli.tui.widgets.calibration import CalibrationScreen
from tests.tui.conftest import run_async, wait_for
from tests.tui.test_robot_tab import SIZE, hand, open_sim, sim_app


def watching(screen: CalibrationScreen, motor: str) -> bool:
    """Whether the range step shown is ``motor``'s (the previous one may still be shown)."""
    watch = screen._watch
    return watch is not None and any(r.motor == motor for r in watch.readings())


def reading(screen: CalibrationScreen, motor: str) -> Any:
    """The range step's live reading of ``motor`` (current, low, high, span)."""
    watch = screen._watch
    assert watch is not None, "no range step shown"
    return next(r for r in watch.readings() if r.motor == motor)


@pytest.fixture(autouse=True)
def user_dirs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "xdg"))
    return tmp_path / "xdg"


def step_title(screen: CalibrationScreen) -> str:
    return str(screen.query_one("#calibration-title").render())


@run_async
async def test_a_calibration_from_the_robot_tab_is_saved(user_dirs: Path) -> None:
    app = sim_app()
    async with app.run_test(size=(100, 40)) as pilot:
        panel, robot = await open_sim(pilot, app)
        panel.query_one("#robot-calibrate", Button).press()
        await wait_for(pilot, lambda: isinstance(app.screen, CalibrationScreen), what="screen")
        screen = app.screen
        assert isinstance(screen, CalibrationScreen)
        await wait_for(pilot, lambda: bool(screen.query("#calibration-continue")), what="buttons")
        go = screen.query_one("#calibration-continue", Button)
        await wait_for(
            pilot,
            lambda: "posture" in step_title(screen).lower() and not go.disabled,
            what="posture step",
        )
        for motor_id in range(1, 7):
            hand(robot, motor_id).move_by_hand(5.0)  # the posture reads 5° off the old zero
        go.press()
        for step in range(6):  # one joint at a time: each swept through 60°
            await wait_for(
                pilot,
                lambda m=f"m{step + 1}": (
                    step_title(screen) == "Ranges" and not go.disabled and watching(screen, m)
                ),
                what=f"range step {step + 1}",
            )
            virtual = hand(robot, step + 1)
            motor = f"m{step + 1}"
            at_posture = reading(screen, motor).current
            # each position held until the sampler saw it (a busy machine runs it late)
            for angle, span in ((-25.0, 29.0), (35.0, 59.0), (5.0, 59.0)):
                virtual.move_by_hand(angle)
                now = reading(screen, motor)
                await wait_for(
                    pilot,
                    lambda m=motor, a=angle, s=span, p=at_posture: (
                        reading(screen, m).span >= s
                        and (a != 5.0 or abs(reading(screen, m).current - p) < 1.0)
                    ),
                    what=f"{motor} sampled at {angle}° (now {now})",
                )
            go.press()
        await wait_for(pilot, lambda: step_title(screen) in ("Review", "Question"), what="review")
        assert step_title(screen) == "Review", str(screen.query_one("#calibration-text").render())
        assert go.label.plain == "Save"
        go.press()
        await wait_for(pilot, lambda: not isinstance(app.screen, CalibrationScreen), what="saved")
    saved = user_dirs / "poppy" / "profiles" / "ergo-jr" / "profile.yaml"
    assert saved.is_file(), list(user_dirs.rglob("*"))
    motors = yaml.safe_load(saved.read_text())["motors"]
    assert all(abs(abs(motors[f"m{i}"]["offset"]) - 5.0) < 1.0 for i in range(1, 7)), motors


@run_async
async def test_cancelling_writes_nothing(user_dirs: Path) -> None:
    app = sim_app()
    async with app.run_test(size=SIZE) as pilot:
        panel, _ = await open_sim(pilot, app)
        panel.query_one("#robot-calibrate", Button).press()
        await wait_for(pilot, lambda: isinstance(app.screen, CalibrationScreen), what="screen")
        screen = app.screen
        assert isinstance(screen, CalibrationScreen)
        await wait_for(pilot, lambda: bool(screen.query("#calibration-continue")), what="buttons")
        go = screen.query_one("#calibration-continue", Button)
        await wait_for(pilot, lambda: not go.disabled, what="posture step")
        await pilot.press("escape")
        await wait_for(pilot, lambda: not isinstance(app.screen, CalibrationScreen), what="closed")
    assert not list(user_dirs.rglob("profile.yaml"))
