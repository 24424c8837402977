"""Which creature a config describes, and what each creature attaches to its robot.

``attach_creature(robot, kind)`` applies a creature's setup (documented in the Poppy
documentation's "specific features" of each creature library) and attaches its primitives.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from poppy_core.creatures import body, ergo_demos, ergo_jr, interaction, postures, safety
from poppy_core.creatures.face_tracking import FaceTracking
from poppy_core.creatures.head_follow import HeadFollow
from poppy_core.creatures.mimic import ARMS, Mimic
from poppy_core.creatures.tracking import MarkerFollow, TrackingFeedback
from poppy_core.errors import ConfigError, RegisterError
from poppy_core.motion import Primitive, primitive_manager
from poppy_core.motion.chains import attach_chains

if TYPE_CHECKING:
    from poppy_core.robot import Robot, RobotConfig

logger = logging.getLogger(__name__)

Factory = Callable[["Robot", "CreatureSpec"], Primitive]

# Motor names of the pypot configurations (poppy_ergo_jr.json, poppy_torso.json,
# poppy_humanoid.json), to recognise a config that has no profile header.
TORSO_MOTORS: frozenset[str] = frozenset(
    {
        "abs_z",
        "bust_y",
        "bust_x",
        "head_z",
        "head_y",
        "l_shoulder_y",
        "l_shoulder_x",
        "l_arm_z",
        "l_elbow_y",
        "r_shoulder_y",
        "r_shoulder_x",
        "r_arm_z",
        "r_elbow_y",
    }
)
HUMANOID_MOTORS: frozenset[str] = TORSO_MOTORS | {
    "abs_y",
    "abs_x",
    "l_hip_x",
    "l_hip_z",
    "l_hip_y",
    "l_knee_y",
    "l_ankle_y",
    "r_hip_x",
    "r_hip_z",
    "r_hip_y",
    "r_knee_y",
    "r_ankle_y",
}
ERGO_JR_MOTORS: frozenset[str] = frozenset(ergo_jr.ERGO_JR_MOTORS)


@dataclass(frozen=True)
class CreatureSpec:
    """What makes a creature: its default goto control, safe groups, filter and primitives.

    Attributes:
        kind: ``"ergo-jr"``, ``"torso"`` or ``"humanoid"``.
        goto_control: the control its primitives' gotos use (pypot's ``goto_behavior``).
        safe_groups: groups whose motors get ``compliant_behavior = "safe"``.
        manager_filter: how the primitive manager combines requests.
        primitives: name -> factory, in attach order.
        started: primitives started once attached.
    """

    kind: str
    goto_control: str
    safe_groups: tuple[str, ...]
    manager_filter: str
    primitives: Mapping[str, Factory]
    started: tuple[str, ...] = ()
    motors: frozenset[str] = field(default_factory=frozenset)


@dataclass
class Creature:
    """Attached to a robot as ``robot.creature``: its kind and behaviours.

    Attributes:
        kind: the creature kind.
        goto_control: the creature's default goto control.
        primitives: name -> the attached primitive.
    """

    kind: str
    goto_control: str
    primitives: dict[str, Primitive]


def _ergo_jr_primitives() -> dict[str, Factory]:
    ms = postures.ERGO_JR_POSTURE_S
    return {
        "safe_power_up": lambda r, s: ergo_jr.SafePowerUp(r, control=s.goto_control),
        "dance": lambda r, s: ergo_jr.Dance(r, control=s.goto_control),
        "base_posture": lambda r, s: postures.CreaturePosture(
            r, postures.ERGO_JR_BASE, ms, s.goto_control
        ),
        # postures.py: RestPosture lights the LEDs blue, CuriousPosture pink, TetrisPosture yellow.
        "rest_posture": lambda r, s: postures.CreaturePosture(
            r, postures.ERGO_JR_REST, ms, s.goto_control, led="blue"
        ),
        "curious_posture": lambda r, s: postures.CreaturePosture(
            r, postures.ERGO_JR_CURIOUS, ms, s.goto_control, led="pink"
        ),
        "tetris_posture": lambda r, s: postures.CreaturePosture(
            r, postures.ERGO_JR_TETRIS, ms, s.goto_control, led="yellow"
        ),
        "jump": lambda r, s: ergo_jr.Jump(r),
        # poppy_ergo_jr.py attaches its four demos under these names (Puzzel spelt so).
        "tinsel_demo": lambda r, s: ergo_demos.TinselDemo(r),
        "stubborn_demo": lambda r, s: ergo_demos.StubbornDemo(r),
        "chicken_demo": lambda r, s: ergo_demos.ChickenDemo(r),
        "puzzel_demo": lambda r, s: ergo_demos.PuzzleDemo(r),
    }


def _upper_body_primitives() -> dict[str, Factory]:
    return {
        "limit_torque": lambda r, s: safety.LimitTorque(r),
        "temperature_monitoring": lambda r, s: safety.TemperatureMonitor(r),
        "dance_beat_motion": lambda r, s: body.DanceBeatMotion(r),
        "upper_body_idle_motion": lambda r, s: body.UpperBodyIdleMotion(r),
        "head_idle_motion": lambda r, s: body.HeadIdleMotion(r),
        "arms_turn_compliant": lambda r, s: interaction.ArmsTurnCompliant(r),
        "arms_copy_motion": lambda r, s: interaction.ArmsCopyMotion(r),
    }


def _humanoid_primitives() -> dict[str, Factory]:
    ms = postures.HUMANOID_POSTURE_S
    stand = {name: 0.0 for name in HUMANOID_MOTORS}
    return {
        "stand_position": lambda r, s: postures.CreaturePosture(r, stand, ms, s.goto_control),
        "sit_position": lambda r, s: postures.CreaturePosture(
            r, postures.humanoid_sit(), ms, s.goto_control
        ),
        **_upper_body_primitives(),
    }


CREATURES: dict[str, CreatureSpec] = {
    # Ergo Jr: pypot's default goto behaviour ('dummy', poppy_ergo_jr does not change it), the
    # manager sums requests (poppy_ergo_jr.py: filter = numpy.sum); no safe compliance is
    # documented for it.
    "ergo-jr": CreatureSpec(
        kind="ergo-jr",
        goto_control="dummy",
        safe_groups=(),
        manager_filter="sum",
        primitives=_ergo_jr_primitives(),
        motors=ERGO_JR_MOTORS,
    ),
    # Poppy documentation (Torso specific features): default goto behaviour 'minjerk'. Safe
    # compliance of the torso group and the summing filter as on the Humanoid it is cut from.
    "torso": CreatureSpec(
        kind="torso",
        goto_control="minjerk",
        safe_groups=("torso",),
        manager_filter="sum",
        primitives={
            **_upper_body_primitives(),
            "init_position": lambda r, s: postures.InitPosition(r, s.goto_control),
        },
        started=("temperature_monitoring",),
        motors=TORSO_MOTORS,
    ),
    # Poppy documentation (Humanoid specific features): goto 'minjerk' on every motor, 'safe'
    # compliance on the torso group "to avoid self-collision", the manager's filter a sum;
    # temperature_monitoring "is looping and started by default".
    "humanoid": CreatureSpec(
        kind="humanoid",
        goto_control="minjerk",
        safe_groups=("torso",),
        manager_filter="sum",
        primitives=_humanoid_primitives(),
        started=("temperature_monitoring",),
        motors=HUMANOID_MOTORS,
    ),
}
"""Kind -> its spec."""


def normalize_kind(kind: str) -> str | None:
    """The known creature kind ``kind`` spells (``"PoppyErgoJr"``, ``"ergo_jr"``...), or None."""
    key = kind.strip().lower().replace("_", "").replace("-", "").replace(" ", "")
    key = key.removeprefix("poppy")
    for known in CREATURES:
        if known.replace("-", "") == key:
            return known
    return None


def detect_kind(config: RobotConfig) -> str | None:
    """The creature a config describes: its profile header's kind (or name), else its motors.

    Without a header (a pypot JSON config), the motor names must be exactly those of a
    creature's pypot configuration.
    """
    header = config.profile
    if header is not None:
        for value in (header.kind, header.name):
            kind = normalize_kind(value) if value else None
            if kind is not None:
                return kind
        if header.kind:
            return None  # a kind of its own: not one of ours
    names = frozenset(config.motors)
    for kind, spec in CREATURES.items():
        if names == spec.motors:
            return kind
    return None


def attach_creature(robot: Robot, kind: str, *, start_defaults: bool = True) -> Creature:
    """Set a robot up as creature ``kind`` and attach its primitives (``robot.<name>``).

    Sets the primitive manager's filter, the safe compliance of the creature's groups and, on
    Ergo Jr, the documented torque limit and gains; then attaches each primitive and starts
    those started by default (``temperature_monitoring``). Attaching again returns the
    primitives already there. The creature's kinematic chains (``robot.chain``,
    ``robot.l_arm_chain``...) come from the config's ``kinematics`` section, or the creature's
    profile; a simulated Ergo Jr (MuJoCo) also gets ``head_follow``, an Ergo Jr with a marker
    detector ``tracking_feedback`` and ``marker_follow``, one with a face detector
    ``face_tracking``; a Torso or Humanoid with a skeleton sensor (Kinect, camera pose)
    ``mimic``.

    Args:
        robot: the robot.
        kind: ``"ergo-jr"``, ``"torso"`` or ``"humanoid"`` (other spellings accepted).
        start_defaults: start the primitives the creature starts by default.

    Returns:
        The creature (also ``robot.creature``).

    Raises:
        ConfigError: unknown kind, or a primitive name taken by a motor or group.
    """
    known = normalize_kind(kind)
    if known is None:
        raise ConfigError(
            f"unknown creature {kind!r} (creatures: {', '.join(CREATURES)})",
            field="kind",
            value=kind,
        )
    existing = robot.extensions.get("creature")
    if isinstance(existing, Creature) and existing.kind == known:
        return existing
    spec = CREATURES[known]
    _setup(robot, spec)
    attached: dict[str, Primitive] = {}
    for name, factory in spec.primitives.items():
        primitive = factory(robot, spec)
        robot.attach_primitive(primitive, name)
        attached[name] = primitive
    chains = attach_chains(robot, known, control=spec.goto_control)
    if known == "ergo-jr" and "chain" in chains and robot.simulation is not None:
        attached["head_follow"] = HeadFollow(robot, "chain")
        robot.attach_primitive(attached["head_follow"], "head_follow")
    if known == "ergo-jr" and any(s.name == "marker_detector" for s in robot.sensors):
        attached["tracking_feedback"] = TrackingFeedback(robot)
        robot.attach_primitive(attached["tracking_feedback"], "tracking_feedback")
        if "chain" in chains:
            attached["marker_follow"] = MarkerFollow(robot, "chain")
            robot.attach_primitive(attached["marker_follow"], "marker_follow")
    faces = [s for s in robot.sensors if "faces" in s.registers]  # a FaceDetector
    if known == "ergo-jr" and faces and "chain" in chains:
        attached["face_tracking"] = FaceTracking(robot, "chain", faces[0])
        robot.attach_primitive(attached["face_tracking"], "face_tracking")
    skeletons = [s for s in robot.sensors if "tracked_skeleton" in s.registers]
    if known in ("torso", "humanoid") and skeletons and set(ARMS.values()) <= set(chains):
        attached["mimic"] = Mimic(robot, skeletons[0])
        robot.attach_primitive(attached["mimic"], "mimic")
    creature = Creature(known, spec.goto_control, attached)
    robot.attach("creature", creature)
    if start_defaults and not robot.closed:
        for name in spec.started:
            attached[name].start()
    logger.info("%s: attached %s", known, ", ".join(attached))
    return creature


def _setup(robot: Robot, spec: CreatureSpec) -> None:
    primitive_manager(robot).filter = spec.manager_filter
    for group in spec.safe_groups:
        if group in robot.motorgroups:
            for motor in robot.group(group):
                motor.compliant_behavior = "safe"
    if spec.kind == "ergo-jr":
        for motor in robot.motors:
            try:
                if motor.model.has_torque_limit:
                    motor.torque_limit = ergo_jr.ERGO_JR_TORQUE_LIMIT_PCT
                if motor.model.has_register("p_gain"):
                    motor.pid = ergo_jr.ERGO_JR_PID
            except RegisterError as exc:
                logger.warning("%s: Ergo Jr setting not applied: %s", motor.name, exc)
