"""Sensors as Foxglove messages: a Kinect's skeletons as a 3D scene, an IMU's orientation as a
transform and its values as JSON.

Skeletons are drawn in the frame named after the Kinect sensor, with the positions the skeleton
server sends (metres, the Kinect's skeleton space): a sphere at each joint and a line along each
bone. The bones are the Kinect SDK's (v1) pairs of its 20 joints: the torso chain from the hip
centre to the head, each arm from the shoulder centre to the hand, each leg from the hip centre
to the foot.
"""

from __future__ import annotations

from itertools import pairwise
from typing import Any

from foxglove.messages import Color as FoxgloveColor
from foxglove.messages import (
    FrameTransform,
    LinePrimitive,
    LinePrimitiveLineType,
    Point3,
    Pose,
    Quaternion,
    SceneEntity,
    SceneEntityDeletion,
    SceneEntityDeletionType,
    SceneUpdate,
    SpherePrimitive,
    Vector3,
)

from poppy_core.sensors.kinect import LEFT_ARM, LEFT_LEG, RIGHT_ARM, RIGHT_LEG, TORSO
from poppy_core.server.foxglove.robot_messages import stamp


def _chain(*names: str) -> list[tuple[str, str]]:
    return list(pairwise(names))


BONES: tuple[tuple[str, str], ...] = tuple(
    _chain(*TORSO)
    + _chain("shoulder_center", *LEFT_ARM)
    + _chain("shoulder_center", *RIGHT_ARM)
    + _chain("hip_center", *LEFT_LEG)
    + _chain("hip_center", *RIGHT_LEG)
)
"""The skeleton's 19 bones (pairs of joint names), as the Kinect SDK draws them."""
JOINT_DIAMETER_M = 0.06
BONE_THICKNESS_M = 0.02
JOINT_COLOUR = FoxgloveColor(r=1.0, g=0.8, b=0.1, a=1.0)
BONE_COLOUR = FoxgloveColor(r=0.2, g=0.8, b=0.4, a=1.0)
IMU_REFERENCE_FRAME = "world"
"""The frame an IMU's orientation is given in (level, fixed: the ``/NAME/imu`` transform's
parent); its child frame is the IMU's name."""

IMU_VALUES_SCHEMA: dict[str, Any] = {
    "type": "object",
    "title": "poppy.ImuValues",
    "description": "An IMU's values (docs/foxglove.md): angles in degrees, rates in degrees "
    "per second, accelerations in m/s² (gravity included); null: not measured",
    "properties": {
        "timestamp": {
            "type": "object",
            "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}},
        },
        "orientation": {
            "type": "object",
            "properties": {k: {"type": "number"} for k in ("yaw", "pitch", "roll")},
        },
        "quaternion": {
            "type": "object",
            "properties": {k: {"type": "number"} for k in ("w", "x", "y", "z")},
        },
        "angular_velocity": {
            "type": ["object", "null"],
            "properties": {k: {"type": "number"} for k in ("x", "y", "z")},
        },
        "acceleration": {
            "type": ["object", "null"],
            "properties": {k: {"type": "number"} for k in ("x", "y", "z")},
        },
    },
}
"""The JSON schema of ``/NAME/imu/values``."""


def _point(xyz: Any) -> Point3:
    return Point3(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))


def skeleton_entity(skeleton: Any, frame: str, now: float) -> SceneEntity:
    """One user's skeleton: a sphere per joint, a line per bone, in ``frame``."""
    positions = {name: getattr(skeleton, name).position for name in skeleton.joints}
    size = Vector3(x=JOINT_DIAMETER_M, y=JOINT_DIAMETER_M, z=JOINT_DIAMETER_M)
    spheres = [
        SpherePrimitive(
            pose=Pose(position=Vector3(x=float(x), y=float(y), z=float(z))),
            size=size,
            color=JOINT_COLOUR,
        )
        for x, y, z in positions.values()
    ]
    bone = LinePrimitive(
        type=LinePrimitiveLineType.LineList,
        thickness=BONE_THICKNESS_M,
        points=[_point(positions[name]) for pair in BONES for name in pair],
        color=BONE_COLOUR,
    )
    return SceneEntity(
        timestamp=stamp(now),
        frame_id=frame,
        id=user_entity(skeleton.user_id),
        spheres=spheres,
        lines=[bone],
    )


def user_entity(user: Any) -> str:
    """The scene entity's id of a user's skeleton."""
    return f"user {user}"


def skeletons_scene(
    skeletons: dict[Any, Any], gone: list[Any], frame: str, now: float
) -> SceneUpdate:
    """Each tracked user's skeleton, and the users ``gone`` since the last update removed."""
    return SceneUpdate(
        deletions=[
            SceneEntityDeletion(
                timestamp=stamp(now), type=SceneEntityDeletionType.MatchingId, id=user_entity(u)
            )
            for u in gone
        ],
        entities=[skeleton_entity(s, frame, now) for s in skeletons.values()],
    )


def imu_transform(quaternion: list[float], frame: str, now: float) -> FrameTransform:
    """The IMU's orientation (``[w, x, y, z]``) as the transform from the reference frame to
    the IMU's ``frame``."""
    w, x, y, z = (float(v) for v in quaternion)
    return FrameTransform(
        timestamp=stamp(now),
        parent_frame_id=IMU_REFERENCE_FRAME,
        child_frame_id=frame,
        translation=Vector3(x=0.0, y=0.0, z=0.0),
        rotation=Quaternion(x=x, y=y, z=z, w=w),
    )


def imu_values(
    orientation: dict[str, float],
    quaternion: list[float],
    angular_velocity: dict[str, float] | None,
    acceleration: dict[str, float] | None,
    now: float,
) -> dict[str, Any]:
    """The IMU's registers as a ``poppy.ImuValues`` message (``IMU_VALUES_SCHEMA``)."""
    sec = int(now)
    return {
        "timestamp": {"sec": sec, "nsec": int((now - sec) * 1e9)},
        "orientation": dict(orientation),
        "quaternion": dict(zip("wxyz", quaternion, strict=True)),
        "angular_velocity": angular_velocity,
        "acceleration": acceleration,
    }
