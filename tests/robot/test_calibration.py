"""Calibration: zeros and ranges read by a scripted session, the profile written safely, drift."""

from __future__ import annotations

import os
import time
from collections.abc import Iterator, Sequence
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core import from_config, from_profile
from poppy_core.errors import CalibrationCancelled, ConfigError
from poppy_core.models import model_by_name
from poppy_core.robot import (
    Calibration,
    CalibrationSession,
    JointCalibration,
    Motor,
    RangeWatch,
    ReferencePosture,
    Robot,
    check_calibration,
    load_profile,
    save_user_profile,
)
from poppy_core.robot.calibration import check_motors, servo_range
from tests.teleop.hands import READ_S, Hand


class ScriptedAnswers:
    """Answers a session as a person would: puts the robot in the posture (motor-frame zeros
    given), moves each joint through the range given, answers questions from a list."""

    def __init__(
        self,
        robot: Robot,
        zeros: dict[str, float] | None = None,
        ranges: dict[str, tuple[float, float]] | None = None,
        answers: Sequence[bool] = (),
        cancel_at: str | None = None,
    ) -> None:
        self.hand = Hand(robot)
        self.zeros = zeros or {}
        self.ranges = ranges or {}
        self.answers = list(answers)
        self.cancel_at = cancel_at
        self.questions: list[str] = []
        self.postures = 0
        self.moves: list[list[str]] = []

    def posture(self, posture: ReferencePosture, motors: Sequence[str]) -> bool:
        self.postures += 1
        for name in motors:
            self.hand.put_motor_frame(name, self.zeros.get(name, 0.0))
        return self.cancel_at != "posture"

    def move(self, motors: Sequence[str], watch: RangeWatch) -> bool:
        self.moves.append(list(motors))
        for name in motors:
            low, high = self.ranges.get(name, (-40.0, 40.0))
            for value in (low, high, self.zeros.get(name, 0.0)):
                self.hand.put_motor_frame(name, value)
                time.sleep(READ_S)
        return self.cancel_at != "move"

    def confirm(self, question: str) -> bool:
        self.questions.append(question)
        return self.answers.pop(0)


@pytest.fixture
def robot() -> Iterator[Robot]:
    with from_profile("ergo-jr", sim=True, sensors=False) as built:
        yield built


def test_zeros_and_ranges_become_offsets_and_limits(robot: Robot) -> None:
    answers = ScriptedAnswers(
        robot, zeros={"m1": 3.0, "m2": -4.0}, ranges={"m1": (-140.0, 130.0), "m2": (-120.0, 100.0)}
    )
    calibration = CalibrationSession(robot, answers, ["m1", "m2"], settle_s=READ_S).run()
    assert answers.moves == [["m1"], ["m2"]]  # one joint at a time
    config = calibration.apply(robot.config, "my-ergo")  # type: ignore[arg-type]
    m1, m2 = config.motors["m1"], config.motors["m2"]
    # XL-320 reads in steps of 0.29°: the zeros are the nearest steps
    assert m1.offset == pytest.approx(3.0, abs=0.3)  # direct: offset = zero
    assert m2.offset == pytest.approx(4.0, abs=0.3)  # indirect: offset = -zero
    assert m1.angle_limit == pytest.approx((-143.0, 127.0), abs=0.6)
    assert m2.angle_limit == pytest.approx((-104.0, 116.0), abs=0.6)
    # the joints read 0° in the posture with the new frames
    for name, zero in (("m1", 3.0), ("m2", -4.0)):
        motor = Motor.from_config(name, config.motors[name], model_by_name("XL-320"))
        assert motor.to_user(zero) == pytest.approx(0.0, abs=0.3)
    assert config.profile is not None and config.profile.name == "my-ergo"
    assert config.profile.kind == "ergo-jr"
    section = config.model_extra["calibration"]  # type: ignore[index]
    assert section["from"] == "ergo-jr" and set(section["motors"]) == {"m1", "m2"}
    assert config.motors["m3"] == robot.config.motors["m3"]  # type: ignore[union-attr]


def test_a_posture_with_angles_and_all_joints_at_once(robot: Robot) -> None:
    posture = ReferencePosture("elbow bent", positions={"m3": 30.0})
    answers = ScriptedAnswers(robot, zeros={"m3": -30.0})  # m3 is indirect
    session = CalibrationSession(
        robot, answers, ["m1", "m3"], posture=posture, one_at_a_time=False, settle_s=READ_S
    )
    calibration = session.run()
    assert answers.moves == [["m1", "m3"]]
    assert calibration.joints["m3"].offset("indirect") == pytest.approx(0.0, abs=0.3)
    assert calibration.joints["m3"].posture == 30.0


def test_a_joint_barely_moved_is_asked_about(robot: Robot) -> None:
    answers = ScriptedAnswers(robot, ranges={"m1": (-2.0, 2.0)}, answers=[True])
    calibration = CalibrationSession(robot, answers, ["m1"], settle_s=READ_S).run()
    assert "m1" in answers.questions[0] and "keep the previous range" in answers.questions[0]
    assert calibration.joints["m1"].range is None  # kept
    config = calibration.apply(robot.config)  # type: ignore[arg-type]
    assert config.motors["m1"].angle_limit == (-150.0, 150.0)
    # "no": the joint is moved again
    again = ScriptedAnswers(robot, ranges={"m1": (-2.0, 2.0)}, answers=[False, True])
    CalibrationSession(robot, again, ["m1"], settle_s=READ_S).run()
    assert again.moves == [["m1"], ["m1"]] and len(again.questions) == 2


def test_a_zero_far_from_the_current_one_is_asked_about(robot: Robot) -> None:
    answers = ScriptedAnswers(
        robot, zeros={"m1": 60.0}, ranges={"m1": (-90.0, 90.0)}, answers=[False, True]
    )
    calibration = CalibrationSession(robot, answers, ["m1"], settle_s=READ_S).run()
    assert answers.postures == 2 and "reference posture" in answers.questions[0]
    assert calibration.joints["m1"].zero == pytest.approx(60.0, abs=0.3)


@pytest.mark.parametrize("where", ["posture", "move"])
def test_cancelling_raises_and_writes_nothing(robot: Robot, where: str, tmp_path: Path) -> None:
    answers = ScriptedAnswers(robot, cancel_at=where)
    with pytest.raises(CalibrationCancelled, match="nothing was written"):
        CalibrationSession(robot, answers, ["m1"], settle_s=READ_S).run()
    assert list(tmp_path.iterdir()) == []


servo = st.sampled_from(["XL-320", "AX-12A", "MX-28", "MX-64"])
angles = st.floats(-400.0, 400.0, allow_nan=False)


@given(
    servo,
    st.sampled_from(["direct", "indirect"]),
    st.floats(-60, 60),
    angles,
    angles,
    st.floats(-45, 45),
)
def test_ranges_never_widen_beyond_the_servo(
    model: str, orientation: str, zero: float, a: float, b: float, posture: float
) -> None:
    joint = JointCalibration("j", zero, posture, (a, b))
    low_servo, high_servo = servo_range(model)
    limit = joint.angle_limit(orientation, (low_servo, high_servo))
    if limit is None:
        return
    sign = 1.0 if orientation == "direct" else -1.0
    offset = joint.offset(orientation)
    motor_ends = sorted(sign * (value + offset) for value in limit)
    assert motor_ends[0] >= low_servo - 0.01 and motor_ends[1] <= high_servo + 0.01
    assert limit[0] < limit[1]


def _calibration(offset_deg: float) -> Calibration:
    return Calibration({"m1": JointCalibration("m1", offset_deg, 0.0, (-100.0, 100.0))})


def test_the_profile_is_written_atomically_and_the_previous_one_kept(tmp_path: Path) -> None:
    base = load_profile("ergo-jr")
    first = save_user_profile(_calibration(2.0).apply(base), "ergo-jr", tmp_path)
    assert first.backup is None and first.path == tmp_path / "ergo-jr" / "profile.yaml"
    assert load_profile("ergo-jr", tmp_path).motors["m1"].offset == 2.0
    old_text = first.path.read_text()
    second = save_user_profile(
        _calibration(5.0).apply(base), "ergo-jr", tmp_path, comment="calibrated again"
    )
    assert second.backup == tmp_path / "ergo-jr" / "profile.yaml.bak"
    assert second.backup.read_text() == old_text
    assert second.path.read_text().startswith("# calibrated again\n")
    assert load_profile("ergo-jr", tmp_path).motors["m1"].offset == 5.0
    assert sorted(p.name for p in (tmp_path / "ergo-jr").iterdir()) == [
        "profile.yaml",
        "profile.yaml.bak",
    ]  # no temporary file left


def test_a_write_cut_short_leaves_the_previous_profile(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    base = load_profile("ergo-jr")
    saved = save_user_profile(_calibration(2.0).apply(base), "ergo-jr", tmp_path)
    before = saved.path.read_text()
    real_replace = os.replace

    def failing_replace(src: str, dst: str) -> None:
        if str(dst).endswith("profile.yaml"):
            raise OSError(28, "No space left on device")
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", failing_replace)
    with pytest.raises(ConfigError, match=r"cannot write .*profile\.yaml: no space left"):
        save_user_profile(_calibration(9.0).apply(base), "ergo-jr", tmp_path)
    assert saved.path.read_text() == before
    assert not [p for p in saved.path.parent.iterdir() if p.name.endswith(".tmp")]


def test_bad_names_and_motors_are_refused(tmp_path: Path) -> None:
    config = load_profile("ergo-jr")
    for name in ("../evil", "a/b", "", ".hidden"):
        with pytest.raises(ConfigError, match="cannot be a profile name"):
            save_user_profile(config, name, tmp_path)
    with pytest.raises(ConfigError, match="no motor or group 'm9'"):
        check_motors(config, ["m9"])
    assert check_motors(config, ["base", "m2", "m6"]) == ["m1", "m2", "m3", "m6"]


def test_check_reports_drift(tmp_path: Path) -> None:
    calibrated = _calibration(0.0).apply(load_profile("ergo-jr"), "checked")
    with from_config(calibrated, sim=True, sensors=False) as robot:
        hand = Hand(robot)

        class Posture(ScriptedAnswers):
            def posture(self, posture: ReferencePosture, motors: Sequence[str]) -> bool:
                hand.put({name: 0.0 for name in motors} | {"m2": 5.0})
                return True

        drifts = {d.motor: d for d in check_calibration(robot, Posture(robot), settle_s=READ_S)}
    assert drifts["m2"].drift == pytest.approx(5.0, abs=0.3) and not drifts["m2"].ok
    assert all(d.ok for name, d in drifts.items() if name != "m2")
