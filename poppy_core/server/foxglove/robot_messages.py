"""The robot as Foxglove messages: joint states, frame transforms, images, detections, health.

Positions are the URDF joints' angles in radians (``UrdfJoints``, as on ROS 2), transforms are
the URDF's tree at those angles (forward kinematics joint by joint, as robot_state_publisher
does), so the 3D panel's URDF layer moves the robot from ``/tf``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from foxglove.messages import (
    CircleAnnotation,
    CompressedImage,
    FrameTransform,
    FrameTransforms,
    ImageAnnotations,
    JointState,
    JointStates,
    Log,
    LogLevel,
    Point2,
    PointsAnnotation,
    PointsAnnotationType,
    Quaternion,
    TextAnnotation,
    Timestamp,
    Vector3,
)
from foxglove.messages import Color as FoxgloveColor

from poppy_core.server.ros2.joints import UrdfJoints, joint_transform, matrix_quaternion
from poppy_core.zenoh_wire import finite_or_nan

if TYPE_CHECKING:
    from poppy_core.kinematics import JointDescription
    from poppy_core.robot import Robot

MARKER_COLOUR = FoxgloveColor(r=0.1, g=0.8, b=0.2, a=1.0)
FACE_COLOUR = FoxgloveColor(r=1.0, g=0.6, b=0.0, a=1.0)
BLOB_COLOUR = FoxgloveColor(r=0.2, g=0.5, b=1.0, a=1.0)
WHITE = FoxgloveColor(r=1.0, g=1.0, b=1.0, a=1.0)


def stamp(now: float) -> Timestamp:
    """A Foxglove timestamp of ``now`` (seconds since the epoch)."""
    return Timestamp.from_epoch_secs(now)


def joint_states(robot: Robot, joints: UrdfJoints, now: float) -> JointStates:
    """Every motor: its joint's position (rad), speed (rad/s) and effort (N·m, from the load
    as a fraction of the servo's stall torque); a value not read is left out."""
    out = []
    for motor in robot.motors:
        frame = joints.frames[motor.name]
        degrees = finite_or_nan(motor.present_position)
        speed = finite_or_nan(motor.present_speed)
        stall = getattr(motor.model, "stall_torque_nm", None)
        load = finite_or_nan(motor.present_load)
        effort = frame.scale * load / 100.0 * stall if stall else math.nan
        out.append(
            JointState(
                name=motor.name,
                position=_finite(frame.to_joint(degrees)),
                velocity=_finite(math.radians(frame.scale * speed)),
                effort=_finite(effort),
            )
        )
    return JointStates(timestamp=stamp(now), joints=out)


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


def transform(joint: JointDescription, radians: float, now: float) -> FrameTransform:
    """The transform from the joint's parent link to its child link at ``radians``."""
    matrix = joint_transform(joint, radians)
    x, y, z, w = matrix_quaternion(matrix[:3, :3])
    return FrameTransform(
        timestamp=stamp(now),
        parent_frame_id=joint.parent,
        child_frame_id=joint.child,
        translation=Vector3(x=float(matrix[0, 3]), y=float(matrix[1, 3]), z=float(matrix[2, 3])),
        rotation=Quaternion(x=x, y=y, z=z, w=w),
    )


def positions_joint_states(
    joints: UrdfJoints, degrees: Mapping[str, float], now: float
) -> JointStates:
    """Recorded positions (motor name -> degrees, user frame) as joint angles (rad) alone: a
    dataset's state or action (``poppy dataset view --mcap``); a value not finite is left out."""
    return JointStates(
        timestamp=stamp(now),
        joints=[
            JointState(name=name, position=_finite(joints.to_joint(name, value)))
            for name, value in degrees.items()
        ],
    )


def frame_transforms(robot: Robot, joints: UrdfJoints, now: float) -> FrameTransforms:
    """Every joint's transform at the motors' present angles (``positions_transforms``)."""
    degrees = {m.name: finite_or_nan(m.present_position) for m in robot.motors}
    return positions_transforms(joints, degrees, now)


def positions_transforms(
    joints: UrdfJoints, degrees: Mapping[str, float], now: float
) -> FrameTransforms:
    """Every joint's transform: the fixed ones, and the moving ones at the motors' angles
    (``degrees``: motor name -> degrees; a joint without a motor, or not read yet, at 0). The
    fixed ones ride along each time: a file opened in the middle, or a client that came late,
    has the whole tree."""
    out = [transform(j, 0.0, now) for j in joints.fixed()]
    for joint in joints.moving():
        value = degrees.get(joint.name, math.nan)
        angle = joints.to_joint(joint.name, value) if math.isfinite(value) else 0.0
        out.append(transform(joint, angle, now))
    return FrameTransforms(transforms=out)


def compressed_image(jpeg: bytes, frame: str, now: float) -> CompressedImage:
    """A JPEG image of the camera ``frame``."""
    return CompressedImage(timestamp=stamp(now), frame_id=frame, data=jpeg, format="jpeg")


def image_annotations(found: list[Any], now: float) -> ImageAnnotations:
    """Markers (their outline and id), faces (their box) and blobs (their circle) as
    annotations over the image; anything else a detector finds is left out."""
    at = stamp(now)
    points, circles, texts = [], [], []
    for thing in found:
        corners = getattr(thing, "corners", None)
        rect = getattr(thing, "rect", None)
        radius = getattr(thing, "radius", None)
        if corners is not None:
            outline = [Point2(x=float(x), y=float(y)) for x, y in corners]
            colour, label = MARKER_COLOUR, f"{getattr(thing, 'family', 'marker')} {thing.id}"
        elif rect is not None:
            x, y, w, h = (float(v) for v in rect)
            outline = [
                Point2(x=x, y=y),
                Point2(x=x + w, y=y),
                Point2(x=x + w, y=y + h),
                Point2(x=x, y=y + h),
            ]
            colour, label = FACE_COLOUR, "face"
        elif radius is not None and getattr(thing, "center", None) is not None:
            x, y = (float(v) for v in thing.center)
            circles.append(
                CircleAnnotation(
                    timestamp=at,
                    position=Point2(x=x, y=y),
                    diameter=2.0 * float(radius),
                    thickness=2.0,
                    outline_color=BLOB_COLOUR,
                )
            )
            texts.append(_label(at, Point2(x=x, y=y - float(radius)), "blob", BLOB_COLOUR))
            continue
        else:
            continue
        points.append(
            PointsAnnotation(
                timestamp=at,
                type=PointsAnnotationType.LineLoop,
                points=outline,
                outline_color=colour,
                thickness=2.0,
            )
        )
        texts.append(_label(at, outline[0], label, colour))
    return ImageAnnotations(timestamp=at, points=points, circles=circles, texts=texts)


def _label(at: Timestamp, where: Point2, text: str, colour: FoxgloveColor) -> TextAnnotation:
    return TextAnnotation(
        timestamp=at,
        position=where,
        text=text,
        font_size=14.0,
        text_color=WHITE,
        background_color=colour,
    )


@dataclass(frozen=True)
class HealthLine:
    """One part's health as a log line: its level and what it says."""

    part: str
    level: LogLevel
    text: str


def health_lines(
    buses: dict[str, dict[str, Any]], sensors: dict[str, dict[str, Any]]
) -> list[HealthLine]:
    """Each bus (ERROR when disconnected, WARNING with offline motors) and sensor (WARNING
    when not ok) as one line."""
    lines = []
    for bus, health in buses.items():
        offline = list(health.get("offline", []))
        label = str(health.get("label") or bus)
        if not health.get("connected", True):
            lines.append(HealthLine(f"bus {label}", LogLevel.Error, f"bus {label}: disconnected"))
        elif offline:
            lines.append(
                HealthLine(
                    f"bus {label}",
                    LogLevel.Warning,
                    f"bus {label}: offline motors: {', '.join(offline)}",
                )
            )
        else:
            lines.append(HealthLine(f"bus {label}", LogLevel.Info, f"bus {label}: ok"))
    for sensor, health in sensors.items():
        if health.get("ok", True):
            lines.append(HealthLine(f"sensor {sensor}", LogLevel.Info, f"sensor {sensor}: ok"))
        else:
            why = health.get("last_error") or "not ok"
            lines.append(
                HealthLine(f"sensor {sensor}", LogLevel.Warning, f"sensor {sensor}: {why}")
            )
    return lines


def log(line: HealthLine, name: str, now: float) -> Log:
    """A health line as a Foxglove log message of the robot ``name``."""
    return Log(timestamp=stamp(now), level=line.level, message=line.text, name=name)
