"""The node's messages made from the robot: joint states, transforms, diagnostics, images, IMUs."""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any

from poppy_core.server.ros2 import types
from poppy_core.server.ros2.joints import UrdfJoints, joint_transform, matrix_quaternion
from poppy_core.zenoh_wire import finite_or_nan

if TYPE_CHECKING:
    from poppy_core.kinematics import JointDescription
    from poppy_core.robot import Robot
    from poppy_core.sensors import Imu

OK, WARN, ERROR = 0, 1, 2
"""diagnostic_msgs/DiagnosticStatus levels."""


def stamp(now: float | None = None) -> Any:
    """A builtin_interfaces/Time of ``now`` (``time.time()`` when None)."""
    seconds = time.time() if now is None else now
    whole = math.floor(seconds)
    return types.message(
        "builtin_interfaces/msg/Time", sec=int(whole), nanosec=int((seconds - whole) * 1e9)
    )


def header(frame: str = "", now: float | None = None) -> Any:
    """A std_msgs/Header."""
    return types.message("std_msgs/msg/Header", stamp=stamp(now), frame_id=frame)


def joint_state(robot: Robot, joints: UrdfJoints, now: float | None = None) -> Any:
    """Every motor: its joint's position (rad), speed (rad/s) and effort (N·m, from the load
    as a fraction of the servo's stall torque); NaN where a value is not read."""
    import numpy as np

    names, positions, velocities, efforts = [], [], [], []
    for motor in robot.motors:
        frame = joints.frames[motor.name]
        names.append(motor.name)
        positions.append(frame.to_joint(finite_or_nan(motor.present_position)))
        velocities.append(math.radians(frame.scale * finite_or_nan(motor.present_speed)))
        stall = getattr(motor.model, "stall_torque_nm", None)
        load = finite_or_nan(motor.present_load)
        efforts.append(frame.scale * load / 100.0 * stall if stall else math.nan)
    return types.message(
        types.JOINT_STATE,
        header=header("", now),
        name=names,
        position=np.array(positions, dtype=np.float64),
        velocity=np.array(velocities, dtype=np.float64),
        effort=np.array(efforts, dtype=np.float64),
    )


def transform(joint: JointDescription, radians: float, now: float | None = None) -> Any:
    """A geometry_msgs/TransformStamped from the joint's parent link to its child link."""
    matrix = joint_transform(joint, radians)
    x, y, z, w = matrix_quaternion(matrix[:3, :3])
    return types.message(
        "geometry_msgs/msg/TransformStamped",
        header=header(joint.parent, now),
        child_frame_id=joint.child,
        transform=types.message(
            "geometry_msgs/msg/Transform",
            translation=types.message(
                "geometry_msgs/msg/Vector3",
                x=float(matrix[0, 3]),
                y=float(matrix[1, 3]),
                z=float(matrix[2, 3]),
            ),
            rotation=types.message("geometry_msgs/msg/Quaternion", x=x, y=y, z=z, w=w),
        ),
    )


def tf_message(robot: Robot, joints: UrdfJoints, now: float | None = None) -> Any:
    """The moving joints' transforms at the motors' present angles (forward kinematics, one
    joint at a time, as robot_state_publisher does); a joint without a motor stays at 0."""
    motors = {m.name: m for m in robot.motors}
    out = []
    for joint in joints.moving():
        motor = motors.get(joint.name)
        angle = 0.0
        if motor is not None:
            degrees = finite_or_nan(motor.present_position)
            angle = joints.to_joint(joint.name, degrees) if math.isfinite(degrees) else 0.0
        out.append(transform(joint, angle, now))
    return types.message(types.TF_MESSAGE, transforms=out)


def tf_static(joints: UrdfJoints, now: float | None = None) -> Any:
    """The fixed joints' transforms."""
    return types.message(
        types.TF_MESSAGE, transforms=[transform(j, 0.0, now) for j in joints.fixed()]
    )


def _key_values(values: dict[str, Any]) -> list[Any]:
    return [
        types.message("diagnostic_msgs/msg/KeyValue", key=str(k), value=str(v))
        for k, v in values.items()
    ]


def diagnostics(
    name: str, buses: dict[str, dict[str, Any]], sensors: dict[str, str], now: float | None = None
) -> Any:
    """One status per bus (ERROR when disconnected, WARN with offline motors) and per sensor."""
    statuses = []
    for bus, health in buses.items():
        offline = list(health.get("offline", []))
        if not health.get("connected", True):
            level, text = ERROR, "disconnected"
        elif offline:
            level, text = WARN, f"offline: {', '.join(offline)}"
        else:
            level, text = OK, "ok"
        values = {k: v for k, v in health.items() if not isinstance(v, dict | list)}
        values["offline"] = ", ".join(offline)
        statuses.append(
            types.message(
                "diagnostic_msgs/msg/DiagnosticStatus",
                level=bytes([level])[0],
                name=f"{name}: bus {bus}",
                message=text,
                hardware_id=str(bus),
                values=_key_values(values),
            )
        )
    for sensor, state in sensors.items():
        statuses.append(
            types.message(
                "diagnostic_msgs/msg/DiagnosticStatus",
                level=OK if state == "ok" else WARN,
                name=f"{name}: sensor {sensor}",
                message=state,
                hardware_id=sensor,
                values=[],
            )
        )
    return types.message(types.DIAGNOSTIC_ARRAY, header=header("", now), status=statuses)


def compressed_image(jpeg: bytes, frame: str, now: float | None = None) -> Any:
    """A sensor_msgs/CompressedImage of JPEG bytes."""
    import numpy as np

    return types.message(
        types.COMPRESSED_IMAGE,
        header=header(frame, now),
        format="jpeg",
        data=np.frombuffer(jpeg, dtype=np.uint8),
    )


def imu(sensor: Imu, frame: str, now: float | None = None) -> Any:
    """A sensor_msgs/Imu of an IMU's last values (orientation, rad/s, m/s²); what the device
    does not measure has -1 as its covariance's first element, as the message asks."""
    import numpy as np

    w, x, y, z = sensor.quaternion
    rates, accel = sensor.angular_velocity, sensor.acceleration
    unknown = np.zeros(9)
    unknown[0] = -1.0

    def vector(values: dict[str, float] | None, scale: float) -> Any:
        v = values or {"x": 0.0, "y": 0.0, "z": 0.0}
        return types.message(
            "geometry_msgs/msg/Vector3", x=v["x"] * scale, y=v["y"] * scale, z=v["z"] * scale
        )

    return types.message(
        types.IMU,
        header=header(frame, now),
        orientation=types.message("geometry_msgs/msg/Quaternion", x=x, y=y, z=z, w=w),
        orientation_covariance=np.zeros(9),
        angular_velocity=vector(rates, math.radians(1)),
        angular_velocity_covariance=np.zeros(9) if rates is not None else unknown.copy(),
        linear_acceleration=vector(accel, 1.0),
        linear_acceleration_covariance=np.zeros(9) if accel is not None else unknown.copy(),
    )


def string(text: str) -> Any:
    """A std_msgs/String."""
    return types.message(types.STRING, data=text)


def skeletons_tf(skeletons: dict[Any, Any], frame: str, now: float | None = None) -> Any:
    """A tf2_msgs/TFMessage of tracked skeletons (a Kinect's, a camera pose's): per user and
    joint a transform from ``frame`` (the sensor's) to ``<frame>/user_<id>/<joint>``, the
    joint's position (m) and orientation."""
    import numpy as np

    out = []
    for user, skeleton in skeletons.items():
        for name in skeleton.joints:
            joint = getattr(skeleton, name)
            q = np.asarray(joint.orientation, dtype=float)
            norm = float(np.linalg.norm(q))
            x, y, z, w = (float(v) for v in (q / norm if norm > 0 else (0.0, 0.0, 0.0, 1.0)))
            px, py, pz = (float(v) for v in joint.position)
            out.append(
                types.message(
                    "geometry_msgs/msg/TransformStamped",
                    header=header(frame, now),
                    child_frame_id=f"{frame}/user_{user}/{name}",
                    transform=types.message(
                        "geometry_msgs/msg/Transform",
                        translation=types.message("geometry_msgs/msg/Vector3", x=px, y=py, z=pz),
                        rotation=types.message("geometry_msgs/msg/Quaternion", x=x, y=y, z=z, w=w),
                    ),
                )
            )
    return types.message(types.TF_MESSAGE, transforms=out)
