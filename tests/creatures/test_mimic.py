"""``mimic``: a simulated Torso's or Humanoid's arms follow a skeleton (Kinect's form), checked
through the chains' forward kinematics."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any, ClassVar

import numpy as np
import pytest

from poppy_core import from_config, from_profile
from poppy_core.creatures import Mimic
from poppy_core.creatures.arm_directions import person_arms
from poppy_core.errors import ArgumentError
from poppy_core.robot import Robot, RobotConfig, load_profile
from poppy_core.sensors import DummyCamera, PoseSkeleton, Sensor, Skeleton
from poppy_core.sensors.kinect import JOINTS, Point2D, Point3D, Quaternion, SkeletonJoint
from tests.helpers.arms import angle_deg, robot_arms, robot_frame
from tests.helpers.sensor_rest import rest
from tests.helpers.waiting import eventually

Vec = tuple[float, float, float]
FORWARD, LEFT, UP = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
DOWN, RIGHT = (0.0, 0.0, -1.0), (0.0, -1.0, 0.0)


def kinect(v: Vec) -> np.ndarray:
    """A person's (forward, left, up) direction in the Kinect's frame, the person facing it
    (x to the sensor's left: the person's right; y up; z away from the sensor)."""
    forward, left, up = v
    return np.array([-left, up, -forward])


def skeleton(arms: Mapping[str, tuple[Vec, Vec]], user: int = 1) -> Skeleton:
    """A person 2 m in front of a Kinect with each arm's (upper arm, forearm) directions."""
    at: dict[str, np.ndarray] = {
        "hip_center": np.array([0.0, 0.0, 2.0]),
        "shoulder_center": np.array([0.0, 0.5, 2.0]),
    }
    at["spine"] = (at["hip_center"] + at["shoulder_center"]) / 2
    at["head"] = at["shoulder_center"] + [0.0, 0.2, 0.0]
    for side in ("left", "right"):
        lateral = kinect(LEFT if side == "left" else RIGHT)
        upper, fore = arms[side]
        at[f"shoulder_{side}"] = at["shoulder_center"] + 0.2 * lateral
        at[f"elbow_{side}"] = at[f"shoulder_{side}"] + 0.3 * kinect(upper)
        at[f"wrist_{side}"] = at[f"elbow_{side}"] + 0.25 * kinect(fore)
        at[f"hand_{side}"] = at[f"wrist_{side}"] + 0.05 * kinect(fore)
        at[f"hip_{side}"] = at["hip_center"] + 0.1 * lateral
        at[f"knee_{side}"] = at[f"hip_{side}"] + [0.0, -0.45, 0.0]
        at[f"ankle_{side}"] = at[f"knee_{side}"] + [0.0, -0.45, 0.0]
        at[f"foot_{side}"] = at[f"ankle_{side}"] + [0.0, -0.05, -0.1]
    joints = [
        SkeletonJoint(Point3D(*at[n]), Quaternion(0.0, 0.0, 0.0, 1.0), Point2D(0.0, 0.0))
        for n in JOINTS
    ]
    return Skeleton(0.0, user, *joints)


class FakeSkeletons(Sensor):
    """A skeleton sensor whose skeletons the test sets."""

    registers: ClassVar[tuple[str, ...]] = ("tracked_skeleton",)

    def __init__(self) -> None:
        super().__init__("kinect", 30.0)
        self.skeletons: dict[Any, Skeleton] = {}

    def update(self) -> None:
        return None

    @property
    def tracked_skeleton(self) -> dict[Any, Skeleton]:
        return dict(self.skeletons)


@pytest.fixture(scope="module")
def torso() -> Iterator[Robot]:
    with from_profile("torso", sim=True, start_defaults=False) as robot:
        yield robot


SIDEWAYS_BENT = {  # left arm out to the side, forearm forward; right arm forward, forearm up
    "left": (LEFT, FORWARD),
    "right": (FORWARD, UP),
}


def follows(robot: Robot, wanted: Mapping[str, tuple[Vec, Vec]], within_deg: float) -> bool:
    arms = robot_arms(robot)
    return all(
        angle_deg(arms[side][0], upper) < within_deg and angle_deg(arms[side][1], fore) < within_deg
        for side, (upper, fore) in wanted.items()
    )


def test_the_arms_copy_the_persons_without_mirror(torso: Robot) -> None:
    source = FakeSkeletons()
    source.skeletons = {1: skeleton(SIDEWAYS_BENT)}
    mimic = Mimic(torso, source, mirror=False, smoothing=0.0)
    torso.attach_primitive(mimic, "mimic_copy")
    mimic.start()
    try:
        assert eventually(lambda: follows(torso, SIDEWAYS_BENT, 8.0), timeout_s=20.0)
    finally:
        mimic.stop()
    for name, goal in mimic.goals.items():
        low, high = torso.motor(name).angle_limit
        assert low <= goal <= high


def test_mirrored_the_robot_raises_the_arm_on_the_persons_side(torso: Robot) -> None:
    source = FakeSkeletons()
    person = {"right": (UP, UP), "left": (DOWN, FORWARD)}  # the right arm up, the left down
    source.skeletons = {3: skeleton(person)}
    mimic = Mimic(torso, source, smoothing=0.0)  # mirror is the default
    assert mimic.mirror
    torso.attach_primitive(mimic, "mimic_mirror")
    mimic.start()
    try:
        # the robot's left arm copies the person's right (the one on the same side seen from
        # the robot), its right arm the person's left
        expected = {"left": (UP, UP), "right": (DOWN, FORWARD)}
        assert eventually(lambda: follows(torso, expected, 8.0), timeout_s=20.0)
    finally:
        mimic.stop()


def test_directions_out_of_reach_end_within_the_limits(torso: Robot) -> None:
    source = FakeSkeletons()
    behind = (-0.7, 0.0, -0.7)  # both arms far behind the back: past the shoulders' limits
    source.skeletons = {1: skeleton({"left": (behind, behind), "right": (behind, behind)})}
    mimic = Mimic(torso, source, mirror=False, smoothing=0.0)
    torso.attach_primitive(mimic, "mimic_limits")
    mimic.start()
    try:
        assert eventually(lambda: len(mimic.goals) == 8, timeout_s=20.0)
    finally:
        mimic.stop()
    for name, goal in mimic.goals.items():
        low, high = torso.motor(name).angle_limit
        assert low - 1e-6 <= goal <= high + 1e-6


def test_nobody_tracked_leaves_the_arms_where_they_are(torso: Robot) -> None:
    source = FakeSkeletons()
    mimic = Mimic(torso, source)
    torso.attach_primitive(mimic, "mimic_nobody")
    mimic.start()
    try:
        assert eventually(lambda: mimic.update_rate_hz > 0, timeout_s=20.0)
        assert mimic.goals == {}
    finally:
        mimic.stop()


def test_the_robots_left_is_from_its_right_shoulder_to_its_left_one(torso: Robot) -> None:
    frames = {
        side: getattr(torso, f"{side[0]}_arm_chain").model.frames() for side in ("left", "right")
    }
    across = frames["left"]["l_shoulder_x"][:3, 3] - frames["right"]["r_shoulder_x"][:3, 3]
    frame = robot_frame(torso.l_arm_chain)
    assert angle_deg(frame @ across, LEFT) < 5.0
    assert angle_deg(frame @ [0.0, 0.0, 1.0], UP) < 5.0  # the URDF's z is up


def test_person_arms_reads_the_directions_back() -> None:
    arms = person_arms(skeleton(SIDEWAYS_BENT))
    for side, (upper, fore) in SIDEWAYS_BENT.items():
        assert angle_deg(arms[side][0], upper) < 1e-6
        assert angle_deg(arms[side][1], fore) < 1e-6


def test_bad_settings_are_one_line(torso: Robot) -> None:
    with pytest.raises(ArgumentError, match=r"smoothing must be from 0 to 0\.95"):
        Mimic(torso, FakeSkeletons(), smoothing=1.5)
    with pytest.raises(ArgumentError, match="mimic needs a skeleton sensor"):
        Mimic(torso)


def _config(kinect_port: int) -> RobotConfig:
    data = load_profile("humanoid").to_pypot_dict()
    data["sensors"] = {"kinect": {"type": "KinectSensor", "addr": "127.0.0.1", "port": kinect_port}}
    return RobotConfig.from_dict(data, source="robot.json")


def test_a_humanoid_with_a_kinect_gets_mimic_started_through_rest() -> None:
    pytest.importorskip("zmq")
    with from_config(_config(9), sim=True, start_defaults=False) as robot:
        assert isinstance(robot.mimic, Mimic) and robot.mimic.source is robot.kinect
        robot.kinect.tracked_skeleton = skeleton(SIDEWAYS_BENT, user=2)  # as the server's
        robot.mimic.mirror = False
        robot.mimic.smoothing = 0.0
        with rest(robot) as client:
            assert client.get("/primitive/mimic/start.json").status_code < 300
            try:
                assert eventually(lambda: follows(robot, SIDEWAYS_BENT, 8.0), timeout_s=20.0)
                running = client.get("/primitives/running/list.json").json()["running_primitives"]
                assert "mimic" in running
            finally:
                assert client.get("/primitive/mimic/stop.json").status_code < 300
        assert eventually(lambda: robot.mimic.state == "stopped", timeout_s=10.0)


def test_a_source_that_is_not_well_is_said_once(
    torso: Robot, tmp_path: Any, caplog: pytest.LogCaptureFixture
) -> None:
    camera = DummyCamera("camera", (64, 48), 10.0)
    source = PoseSkeleton("pose", camera, python=str(tmp_path / "no" / "python"))
    mimic = Mimic(torso, source)
    torso.attach_primitive(mimic, "mimic_unwell")
    with camera, source:
        mimic.start()
        try:
            assert eventually(
                lambda: any(r.name.endswith("mimic") for r in caplog.records), timeout_s=20.0
            )
        finally:
            mimic.stop()
    said = [r.getMessage() for r in caplog.records if r.name.endswith("mimic")]
    assert len(said) == 1 and "no interpreter" in said[0] and mimic.goals == {}
