"""ServoWorld: a profile's MuJoCo model stepped in process, its joints moved by poppy's servo model.

The model is the one ``poppy sim`` runs (``robot.virtual.start_simulation``: the profile's
``model.xml``), its limits the profile's. There is no emulator, bus or physics thread: the
joint goals go straight to the simulation's ``Drive`` (the servo loop the virtual motors use:
the goal ramped at the servo's no-load speed, the position actuator's gains and torque limit
from its datasheet), which steps ``mj_step``. Angles are in the user frame, as a robot's
motors show them (orientation and offset applied), so that an action means the same here as
``motor.goal_position`` on the robot.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco  # noqa: TID253 (this room is imported lazily: gymnasium makes an env on demand)
import numpy as np

from poppy_core.errors import ConfigError
from poppy_core.kinematics import Chain
from poppy_core.models import model_by_name
from poppy_core.motion.chains import chains_from_config
from poppy_core.robot.profiles import load_profile
from poppy_core.robot.virtual import start_simulation
from poppy_core.sim.drive import Drive
from poppy_core.sim.exchange import Command
from poppy_core.sim.gl import check_offscreen_gl
from poppy_core.sim.objects import ObjectSpec

# the simulated camera's rendering (sim/camera.py): what costs a software renderer most, off
PLAIN_RENDERING = (
    mujoco.mjtRndFlag.mjRND_SHADOW,
    mujoco.mjtRndFlag.mjRND_REFLECTION,
    mujoco.mjtRndFlag.mjRND_SKYBOX,
)


class ServoWorld:
    """The simulation of profile ``robot`` (``ergo-jr``, ``torso``, ``humanoid``), with
    ``objects`` added to its model (MjSpec, as ``Simulation.add_object``), stepped by hand.

    Args:
        robot: the profile's name.
        control_period_s: simulated time of one :meth:`act` (a whole number of timesteps).
        objects: free objects added to the model before the servos are bound.

    Raises:
        ConfigError: unknown profile, no simulation model, an object that does not fit.
    """

    def __init__(
        self, robot: str, control_period_s: float, objects: Sequence[ObjectSpec] = ()
    ) -> None:
        config = load_profile(robot)
        self.config = config
        self.simulation = start_simulation(config)
        for spec in objects:
            self.simulation.add_object(spec.kind, spec.name, spec.position, spec.size, spec.mass_kg)
        self.model: Any = self.simulation.model
        self.data: Any = self.simulation.data
        self.names: tuple[str, ...] = tuple(config.motors)
        entries = [config.motors[name] for name in self.names]
        self.sign = np.array([1.0 if m.orientation == "direct" else -1.0 for m in entries])
        self.offset = np.array([float(m.offset) for m in entries])
        limits = np.array([m.user_angle_limit for m in entries], dtype=float)
        self.low, self.high = limits[:, 0], limits[:, 1]
        self._speed = [model_by_name(m.type).no_load_speed_dps for m in entries]
        self.drive = Drive()
        joints = [self.simulation.servo_joint(name) for name in self.names]
        for joint in joints:
            self.drive.add(joint, float(self.data.qpos[joint.qpos]))
        self._qpos = np.array([j.qpos for j in joints])
        self._dof = np.array([j.dof for j in joints])
        self._all = list(range(len(joints)))
        timestep = float(self.model.opt.timestep)
        self.frame_skip = max(1, round(control_period_s / timestep))
        self.control_period_s = self.frame_skip * timestep
        self.goal = self.positions()
        self.chains: dict[str, Chain] = chains_from_config(config)
        self._renderers: dict[tuple[int, int], Any] = {}

    # ------------------------------------------------------------------ frames

    def to_motor(self, user_deg: np.ndarray) -> np.ndarray:
        """User-frame angles (one per motor, degrees) in the motors' own frame."""
        return np.asarray(self.sign * (user_deg + self.offset))

    def positions(self) -> np.ndarray:
        """Each motor's present angle (degrees, user frame)."""
        motor = np.degrees(self.data.qpos[self._qpos])
        return np.asarray(self.sign * motor - self.offset)

    def velocities(self) -> np.ndarray:
        """Each motor's joint speed (degrees/s, user frame)."""
        return np.asarray(self.sign * np.degrees(self.data.qvel[self._dof]))

    def home(self) -> np.ndarray:
        """The pose the model starts in (``poppy sim``'s), user frame."""
        motor = np.degrees(self.model.qpos0[self._qpos])
        return np.asarray(self.sign * motor - self.offset)

    # ------------------------------------------------------------------ stepping

    def reset(self, pose_deg: np.ndarray) -> None:
        """The world as built, the motors at rest at ``pose_deg`` (user frame), stiff, their
        goals there."""
        pose = np.clip(np.asarray(pose_deg, dtype=float), self.low, self.high)
        mujoco.mj_resetData(self.model, self.data)
        radians = np.radians(self.to_motor(pose))
        self.data.qpos[self._qpos] = radians
        for index, angle in enumerate(radians):
            self.drive.set_target(index, float(angle))
        self._command(pose)
        mujoco.mj_forward(self.model, self.data)

    def act(self, goal_deg: np.ndarray) -> None:
        """Send every motor its goal (user frame, clipped to its limits) and step one control
        period."""
        self._command(np.clip(np.asarray(goal_deg, dtype=float), self.low, self.high))
        self.drive.apply(self.model)
        self.drive.step(self.model, self.data, self.frame_skip)

    def _command(self, goal: np.ndarray) -> None:
        self.goal = goal
        motor = self.to_motor(goal)
        commands = [
            Command(True, angle, speed, 100.0)
            for angle, speed in zip(motor.tolist(), self._speed, strict=True)
        ]
        self.drive.command(self._all, commands, self.data)

    # ------------------------------------------------------------------ bodies

    def _free_joint(self, name: str) -> tuple[int, int]:
        """(qpos, dof) addresses of the free joint of object ``name`` (``add_objects`` names it)."""
        joint = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, f"{name}_free")
        return int(self.model.jnt_qposadr[joint]), int(self.model.jnt_dofadr[joint])

    def object_position(self, name: str) -> np.ndarray:
        """The free object ``name``'s position now (m, world): its joint's, not the pose
        ``mj_step`` computed before its last integration."""
        address, _ = self._free_joint(name)
        return np.array(self.data.qpos[address : address + 3])

    def place(self, name: str, position: Sequence[float] | np.ndarray) -> None:
        """Put the free object ``name`` at ``position`` (m, world), upright and at rest."""
        address, dof = self._free_joint(name)
        self.data.qpos[address : address + 7] = [*position, 1.0, 0.0, 0.0, 0.0]
        self.data.qvel[dof : dof + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def base_frame(self, chain: Chain) -> tuple[np.ndarray, np.ndarray]:
        """The world pose of ``chain``'s base body: (position, 3x3 rotation)."""
        body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, chain.base)
        return np.array(self.data.xpos[body]), np.array(self.data.xmat[body]).reshape(3, 3)

    def cameras(self) -> list[str]:
        """The model's cameras (``camera`` is the robot's own; ``front``, ``side``, ``top``)."""
        model = self.model
        names = (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_CAMERA, i) for i in range(model.ncam))
        return [name for name in names if name]

    def render(self, camera: str, width: int, height: int) -> np.ndarray:
        """An RGB image (height × width × 3) of the world now from ``camera``, drawn as the
        simulated camera draws (``sim.camera``: no shadows, reflections or skybox, which cost
        a software renderer 30× the frame).

        Raises:
            ConfigError: no OpenGL backend here, or no such camera.
        """
        key = (width, height)
        renderer = self._renderers.get(key)
        if renderer is None:
            check_offscreen_gl()
            try:
                renderer = mujoco.Renderer(self.simulation.view_model, height, width)
            except (mujoco.FatalError, RuntimeError, ValueError) as exc:
                raise ConfigError(f"cannot render {width}x{height}: {exc}") from exc
            for flag in PLAIN_RENDERING:
                renderer.scene.flags[flag] = False
            self._renderers[key] = renderer
        try:
            renderer.update_scene(self.simulation.view(), camera=camera)
        except ValueError as exc:
            raise ConfigError(f"no camera {camera!r} in the model: {exc}", field="camera") from exc
        return np.asarray(renderer.render())

    def close(self) -> None:
        """Free the renderers."""
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()
        self.simulation.close()


def chain_angles(world: ServoWorld, chain: Chain, pose_deg: np.ndarray) -> np.ndarray:
    """The angles of ``chain``'s joints (its order) out of a whole pose (the world's order)."""
    index = [world.names.index(name) for name in chain.names]
    return np.asarray(pose_deg)[index]
