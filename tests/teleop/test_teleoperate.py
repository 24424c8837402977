"""``teleoperate``: a simulated follower copies a simulated leader moved by a test hand."""

from __future__ import annotations

import itertools
import math
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from poppy_core import from_profile
from poppy_core.errors import ArgumentError, ConfigError
from poppy_core.motion import read_move
from poppy_core.motion.teleop.joint_map import JointMap
from poppy_core.motion.teleop.session import Teleoperation, teleoperate
from poppy_core.robot import Robot
from tests.helpers.waiting import scaled
from tests.teleop.hands import READ_S, Hand, wait_for


class Waving:
    """A hand waving some joints of a robot in a thread until stopped."""

    def __init__(self, robot: Robot, motors: list[str], amplitude: float = 30.0) -> None:
        self.hand = Hand(robot)
        self.motors = motors
        self.amplitude = amplitude
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)

    def angle(self, k: int, t: float) -> float:
        return 15.0 + self.amplitude * math.sin(2.0 * t + k)

    def _run(self) -> None:
        start = time.monotonic()
        while not self.stop.wait(0.005):
            t = time.monotonic() - start
            self.hand.put({m: self.angle(k, t) for k, m in enumerate(self.motors)})

    def __enter__(self) -> Waving:
        self.thread.start()
        return self

    def __exit__(self, *_: object) -> None:
        self.stop.set()
        self.thread.join(2.0)


def test_the_follower_follows_the_leader_moved_by_hand(leader: Robot, follower: Robot) -> None:
    arm = ["m1", "m2", "m3"]
    gaps: list[float] = []
    with Waving(leader, arm), teleoperate(leader, follower, rate_hz=100) as teleop:
        assert wait_for(lambda: teleop.status().state == "following", timeout_s=5.0)
        for _ in range(20):  # the follower's goals keep close to the leader
            time.sleep(0.05)
            gaps.append(
                max(
                    abs(follower.motor(m).goal_position - leader.motor(m).present_position)
                    for m in arm
                )
            )
        assert all(leader.motor(m).compliant for m in arm)
        assert not any(follower.motor(m).compliant for m in arm)
    # a hand moving up to 60°/s, goals written within a few ticks: a few degrees apart at most
    assert sorted(gaps)[len(gaps) // 2] < 5.0
    report = teleop.report()
    assert report.ticks > 20 and report.holds == 0
    assert teleop.status().state == "stopped"
    assert not any(follower.motor(m).compliant for m in arm)  # stopped: stiff where it is


def test_the_start_ramp_does_not_jump(leader: Robot, follower: Robot) -> None:
    hand = Hand(leader)
    hand.put({"m1": 70.0, "m2": -50.0})
    time.sleep(READ_S)
    goals: list[float] = []
    changes: list[str] = []
    teleop = teleoperate(
        leader,
        follower,
        "m1=m1, m2=m2",
        rate_hz=100,
        on_change=lambda state, _: changes.append(state),
    )
    with teleop:
        deadline = time.monotonic() + scaled(3.0)
        while time.monotonic() < deadline and teleop.status().state != "following":
            goals.append(follower.m1.goal_position)
            time.sleep(0.01)
        assert wait_for(lambda: follower.m1.present_position == pytest.approx(70.0, abs=1.0))
    # 70° over a ~1.2 s minimum-jerk ramp: from 0° up to 70° through the values between, never
    # back (how big a step between two samples is a matter of when the threads ran: a loaded
    # machine makes the sampler or the ramp late)
    assert goals[0] == pytest.approx(0.0, abs=2.0)
    assert all(b >= a - 0.5 for a, b in itertools.pairwise(goals)), goals
    assert any(10.0 < goal < 60.0 for goal in goals), goals
    assert changes[:3] == ["held", "ramping", "following"]


def test_a_lost_leader_holds_the_follower_then_it_resumes_with_a_ramp(
    leader: Robot, follower: Robot
) -> None:
    hand = Hand(leader)
    with Waving(leader, ["m1", "m2"]) as waving, teleoperate(leader, follower) as teleop:
        assert wait_for(lambda: teleop.status().state == "following")
        hand.unplug("m2")  # the leader's servo stops answering
        assert wait_for(lambda: teleop.status().state == "leader lost", timeout_s=3.0)
        assert "m2" in teleop.status().reason
        time.sleep(0.1)
        held = follower.m1.goal_position
        time.sleep(0.3)
        assert follower.m1.goal_position == held  # holds while the hand keeps moving
        waving.amplitude = 0.0  # the hand waits far from where the follower held
        hand.plug("m2")  # back: answers the background retry within a second
        assert wait_for(lambda: teleop.status().state in ("ramping", "following"), 5.0)
        assert wait_for(lambda: teleop.status().state == "following", timeout_s=5.0)
    assert teleop.report().holds == 1


def test_record_saves_the_followers_trajectory(
    leader: Robot, follower: Robot, tmp_path: Path
) -> None:
    path = f"{tmp_path}/teleop.move"
    with Waving(leader, ["m1"]):
        report = teleoperate(
            leader,
            follower,
            "m1=m1",
            rate_hz=50,
            duration_s=1.5,
            record=path,
            record_metadata={"robot": "ergo-jr"},
        ).run()
    move = read_move(path)
    assert move.motors == ("m1",) and move.framerate == 50
    # the run's samples on the 50 Hz grid, within the run (how close to its 1.5 s: `python -m
    # bench timing`; a loaded machine makes the last tick late, or skips it)
    assert report.duration_s >= 1.5 and 0 < move.duration_s <= report.duration_s + 1 / 50
    assert report.recorded_frames == len(move) and move.metadata["robot"] == "ergo-jr"
    assert max(move.positions[:, 0]) - min(move.positions[:, 0]) > 5.0  # it moved


@pytest.fixture
def torso() -> Iterator[Robot]:
    with from_profile("torso", sim=True, sensors=False) as robot:
        yield robot


def test_one_robot_copies_its_left_arm_to_its_right_arm(torso: Robot) -> None:
    mirror = "r_shoulder_y=l_shoulder_y, r_shoulder_x=-l_shoulder_x, r_arm_z=-l_arm_z"
    with (
        Waving(torso, ["l_shoulder_y", "l_shoulder_x", "l_arm_z"], 20.0),
        teleoperate(torso, torso, mirror, rate_hz=50) as teleop,
    ):
        assert wait_for(lambda: teleop.status().state == "following", timeout_s=5.0)
        time.sleep(0.3)
        left = torso.l_shoulder_x.present_position
        assert torso.r_shoulder_x.goal_position == pytest.approx(-left, abs=6.0)
        assert torso.l_shoulder_x.compliant and not torso.r_shoulder_x.compliant


def test_bad_teleoperations_are_refused(leader: Robot, follower: Robot) -> None:
    with pytest.raises(ConfigError, match="cannot lead and follow"):
        Teleoperation(leader, leader, JointMap.parse("m1=m2, m2=m1"))
    with pytest.raises(ConfigError, match="the leader has no motor m9"):
        Teleoperation(leader, follower, JointMap.parse("m1=m9"))
    with pytest.raises(ArgumentError, match="rate"):
        Teleoperation(leader, follower, rate_hz=0)
    with pytest.raises(ConfigError, match="not a joint link"):
        teleoperate(leader, follower, "m1 = = m2")
