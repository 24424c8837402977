"""Simulation: one MuJoCo world for a robot, its physics thread, and the handle robot.simulation."""

from __future__ import annotations

import logging
import math
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco  # noqa: TID253 (this room is imported lazily, by the factory)
import numpy as np

from poppy_core.checks import positive
from poppy_core.emulator.motor import VirtualMotor
from poppy_core.errors import ConfigError
from poppy_core.schedule import Worker
from poppy_core.sim.drive import Drive, Joint
from poppy_core.sim.exchange import MotorPort
from poppy_core.sim.model_files import MESH_DIR, read_model
from poppy_core.sim.objects import ObjectSpec, add_objects, marker_picture, picture_pixels
from poppy_core.sim.observing import Observing
from poppy_core.sim.placing import Placing, carry_state
from poppy_core.sim.plant import MotorJoint

logger = logging.getLogger(__name__)

SYNC_PERIOD_S = 0.005  # how often the physics thread wakes: reads commands, steps the world
# How often (simulated time) the sensed state is written back into the control tables. The bus
# samples present values at 50 Hz at most, so 100 Hz keeps them at most 10 ms old and halves
# the cost of the exchange (encoding four registers per motor) against writing every 5 ms.
STATE_PERIOD_S = 0.01


@dataclass
class _Binding:
    motor: VirtualMotor
    link: MotorJoint
    port: MotorPort
    index: int  # in the Drive's arrays


@dataclass
class _Objects:
    specs: list[ObjectSpec] = field(default_factory=list)


class Simulation(Observing, Placing):
    """A MuJoCo world whose joints are driven by virtual motors (``robot.simulation``).

    Args:
        xml: the MJCF text of the robot (``profiles/<robot>/model.xml``).
        speed: how many simulated seconds pass per real second in the physics thread.
        assets: the files the model names (its meshes), by the name it gives them
            (``model_files.read_model``; ``Simulation.from_file`` reads them).
    """

    def __init__(
        self, xml: str, speed: float = 1.0, *, assets: dict[str, bytes] | None = None
    ) -> None:
        self._xml = xml
        self._assets = dict(assets or {})
        self.meshes_dir: Path | None = None
        """Where a scene's missing mesh files are looked for (the profile's meshes)."""
        self.speed = speed
        self._lock = threading.RLock()
        # Two compilations of one world: ``model`` steps the physics without the visual meshes
        # (they would cost every step their poses), ``view_model`` draws them; their bodies,
        # joints and cameras are the same, so a render copies the pose across (``view``).
        try:
            self.view_model = mujoco.MjModel.from_xml_string(xml, self._assets)
            self.model = add_objects(xml, [], self._assets, drawn=False)
        except ValueError as exc:
            raise ConfigError(f"the simulation model does not compile: {exc}") from exc
        self.data = mujoco.MjData(self.model)
        self._view_data = mujoco.MjData(self.view_model)
        mujoco.mj_forward(self.model, self.data)
        self._bindings: list[_Binding] = []
        self._drive = Drive()
        self._groups: list[tuple[Any, list[_Binding]]] = []  # bindings by their motors' lock
        self._carry_s = 0.0  # simulated time asked for but not yet stepped (< one timestep)
        self._state_age_s = math.inf  # simulated time since the state was last written
        self._objects = _Objects()
        self._renderers: dict[tuple[int, int], Any] = {}
        self._worker = Worker.periodic("mujoco physics", 1.0 / SYNC_PERIOD_S, self._step_physics)
        self._last_step: float | None = None

    @classmethod
    def from_file(cls, path: Path, speed: float = 1.0) -> Simulation:
        """The world of the MJCF file at ``path``, with the mesh files it names.

        Raises:
            ConfigError: the model or one of its meshes cannot be read.
        """
        xml, assets = read_model(path)
        simulation = cls(xml, speed, assets=assets)
        simulation.meshes_dir = path.parent / MESH_DIR
        return simulation

    # ------------------------------------------------------------------ motors

    def _resolve(self, joint: str) -> tuple[int, int, int]:
        """(qpos address, dof address, actuator id) of ``joint`` in the current model."""
        return self._resolve_in(self.model, joint)

    @staticmethod
    def _resolve_in(model: Any, joint: str) -> tuple[int, int, int]:
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        actuator = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, joint)
        if index < 0 or actuator < 0:
            raise ConfigError(f"the simulation model has no joint/actuator {joint!r}", field=joint)
        return int(model.jnt_qposadr[index]), int(model.jnt_dofadr[index]), actuator

    def bind(self, motor: VirtualMotor, link: MotorJoint) -> None:
        """Let ``motor`` drive joint ``link.joint``; its table starts at the joint's pose.

        The motor's lock must be the one it keeps (a ``VirtualBus`` sets it before attaching
        its plant): the exchange takes each lock once for all the motors sharing it.
        """
        with self._lock:
            joint = self.servo_joint(link.joint)
            target_rad = float(self.data.qpos[joint.qpos])
            binding = _Binding(motor, link, MotorPort(motor), self._drive.add(joint, target_rad))
            self._bindings.append(binding)
            for lock, members in self._groups:
                if lock is motor.lock:
                    members.append(binding)
                    break
            else:
                self._groups.append((motor.lock, [binding]))
            position = math.degrees(target_rad)
        with motor.lock:
            motor.set_state(position, 0.0, 0.0, False)
            motor.table.set_si("goal_position", position)

    def servo_joint(self, joint: str) -> Joint:
        """Where joint ``joint`` and its actuator are in the model, with the servo constants the
        model holds now (stall torque, gains; a fresh world's are the profile's servo's): what a
        ``Drive`` needs to move it.

        Raises:
            ConfigError: the model has no such joint or actuator.
        """
        with self._lock:
            qpos, dof, actuator = self._resolve(joint)
            model = self.model
            return Joint(
                qpos=qpos,
                dof=dof,
                actuator=actuator,
                stall_nm=float(model.actuator_forcerange[actuator][1]),
                kp=float(model.actuator_gainprm[actuator][0]),
                kv=float(-model.actuator_biasprm[actuator][2]),
            )

    def set_joint_deg(self, joint: str, angle_deg: float) -> None:
        """Put joint ``joint`` at ``angle_deg`` (the motor's own angle), at rest."""
        with self._lock:
            index = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, joint)
            if index < 0:
                raise ConfigError(f"no joint {joint!r} in the simulation", field=joint)
            self.data.qpos[self.model.jnt_qposadr[index]] = math.radians(angle_deg)
            self.data.qvel[self.model.jnt_dofadr[index]] = 0.0
            for binding in self._bindings:
                if binding.link.joint == joint:
                    self._drive.set_target(binding.index, math.radians(angle_deg))
            mujoco.mj_forward(self.model, self.data)

    def joint_deg(self, joint: str) -> float:
        """Angle of joint ``joint`` in degrees (the motor's own angle, as its table holds it)."""
        with self._lock:
            index = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, joint)
            if index < 0:
                raise ConfigError(f"no joint {joint!r} in the simulation", field=joint)
            return math.degrees(float(self.data.qpos[self.model.jnt_qposadr[index]]))

    # ------------------------------------------------------------------ stepping

    def advance(self, dt_s: float) -> None:
        """Advance the physics by ``dt_s`` seconds, exchanging with the motors' tables: commands
        read before, sensed state written after when ``STATE_PERIOD_S`` of simulated time has
        passed since the last write (never holding a motor lock and the world lock at once).

        Whole timesteps are stepped; the remainder is carried to the next call, so the
        simulated time tracks the sum of the ``dt_s`` asked for.
        """
        indexes, commands = [], []
        for lock, members in self._groups:
            with lock:
                for binding in members:
                    command = binding.port.read_command()
                    if command is not None:
                        indexes.append(binding.index)
                        commands.append(command)
        with self._lock:
            drive = self._drive
            drive.command(indexes, commands, self.data)
            drive.apply(self.model)
            timestep = float(self.model.opt.timestep)
            self._carry_s += dt_s
            steps = max(0, math.floor(self._carry_s / timestep + 1e-6))
            self._carry_s -= steps * timestep
            drive.step(self.model, self.data, steps)
            self._state_age_s += dt_s
            if self._state_age_s < STATE_PERIOD_S - 1e-9:
                return
            self._state_age_s = 0.0
            states = drive.sense(self.data)
        for lock, members in self._groups:
            with lock:
                for binding in members:
                    binding.port.write_state(states[binding.index])

    # ------------------------------------------------------------------ thread

    def start(self) -> None:
        """Run the physics in real time (times ``speed``) in a background thread."""
        if not self._worker.running:
            self._last_step = None
        self._worker.start()

    def _step_physics(self, now: float) -> None:
        """One wake of the physics thread: the world stepped by the time since the last one
        (times ``speed``); a step that raises is logged once and retried with backoff while
        the emulator goes on answering."""
        last, self._last_step = self._last_step, now
        if last is not None:
            self.advance(min(now - last, 0.1) * self.speed)  # never catch up more than 100 ms

    def stop(self) -> None:
        """Stop the physics thread (idempotent)."""
        self._worker.stop(2.0)

    @property
    def running(self) -> bool:
        """True while the physics thread runs."""
        return self._worker.running

    def close(self) -> None:
        """Stop the thread and free the renderers."""
        self.stop()
        with self._lock:
            self._close_renderers()

    # ------------------------------------------------------------------ handle

    def reset(self) -> None:
        """Back to the initial pose: world state reset, objects back where added, goals = pose."""
        with self._lock:
            mujoco.mj_resetData(self.model, self.data)
            mujoco.mj_forward(self.model, self.data)
            poses = []
            for binding in self._bindings:
                target_rad = float(self.data.qpos[self._drive.qpos[binding.index]])
                self._drive.set_target(binding.index, target_rad)
                poses.append((binding, math.degrees(target_rad)))
        for binding, position in poses:
            with binding.motor.lock:
                binding.motor.table.set_si("goal_position", position)
                binding.motor.set_state(position, 0.0, 0.0, False)

    def add_object(
        self,
        kind: str,
        name: str,
        position: tuple[float, float, float],
        size: float | tuple[float, ...] = 0.02,
        mass: float = 0.05,
    ) -> None:
        """Add a free ``"cube"``, ``"sphere"``, ``"cylinder"`` or ``"cone"`` (size: half side,
        radius, or radius and half height; m).

        The model is rebuilt; the robot's state and the other objects' poses are kept.

        Raises:
            ConfigError: unknown kind, or the name is already used.
        """
        self._add(ObjectSpec.make(kind, name, position, size, mass))

    def add_marker(
        self,
        name: str,
        marker_id: int,
        position: tuple[float, float, float],
        size: float = 0.05,
        *,
        family: str = "aruco",
        dictionary: str = "DICT_4X4_50",
        facing: tuple[float, float, float] | None = None,
    ) -> None:
        """Add a card showing a marker, held in place (it does not fall).

        Args:
            name: the card's body name.
            marker_id: the marker's id.
            position: the card's centre (m, world).
            size: side of the marker's black square (m), as the detector's ``marker_size``;
                the card adds a white margin of one cell around it.
            family: ``"aruco"`` or ``"hamming"`` (pypot's cards).
            dictionary: the ArUco dictionary.
            facing: direction the marker faces; None: toward the robot's camera (``camera``).

        Raises:
            ConfigError: the name is used, or no direction to face.
            SensorError: unknown family, dictionary or id.
        """
        image, side = marker_picture(marker_id, size, family, dictionary)
        self.add_picture(name, image, position, side, facing=facing)

    def add_picture(
        self,
        name: str,
        image: np.ndarray,
        position: tuple[float, float, float],
        size: float = 0.1,
        *,
        facing: tuple[float, float, float] | None = None,
    ) -> None:
        """Add a square card showing ``image`` (RGB, ``(h, w, 3)`` uint8; a face, a photo), held
        in place (it does not fall).

        Args:
            name: the card's body name.
            image: the picture; it is stretched to the square card.
            position: the card's centre (m, world).
            size: side of the card (m).
            facing: direction the picture faces; None: toward the robot's camera (``camera``).

        Raises:
            ConfigError: the name is used, no direction to face, a bad image.
            ArgumentError: a size that is not a positive length.
        """
        pixels = picture_pixels(image)
        side = positive(size, "size")
        if facing is None:
            facing = self._toward_camera(position)
        self._add(ObjectSpec.card(name, pixels, position, side, facing))

    def _toward_camera(self, position: tuple[float, float, float]) -> tuple[float, float, float]:
        with self._lock:
            camera = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, "camera")
            if camera < 0:
                raise ConfigError("no camera to face: give facing=(x, y, z)", field="facing")
            x, y, z = (float(v) for v in self.data.cam_xpos[camera] - np.asarray(position))
        return (x, y, z)

    @property
    def lock(self) -> threading.RLock:
        """The world's lock: hold it to read ``model``/``data`` consistently."""
        return self._lock

    def _add(self, spec: ObjectSpec) -> None:
        name = spec.name
        with self._lock:
            if mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name) >= 0:
                raise ConfigError(f"an object called {name!r} exists", field=name)
            self._install(specs=[*self._objects.specs, spec])

    def _install(
        self,
        xml: str | None = None,
        assets: dict[str, bytes] | None = None,
        specs: list[ObjectSpec] | None = None,
    ) -> None:
        """Compile the world again and run it from now on: ``xml`` and ``assets`` (a new scene,
        default the current one) with the objects ``specs`` (default those added so far). The
        robot's state is carried over and its motors bound again.

        Raises:
            ConfigError: the world does not compile, or lacks a bound motor's joint.
        """
        with self._lock:
            xml = self._xml if xml is None else xml
            assets = self._assets if assets is None else dict(assets)
            specs = self._objects.specs if specs is None else specs
            try:
                view = add_objects(xml, specs, assets)
                model = add_objects(xml, specs, assets, drawn=False)
            except ValueError as exc:
                raise ConfigError(f"the simulation model does not compile: {exc}") from exc
            for binding in self._bindings:
                self._resolve_in(model, binding.link.joint)
            self._xml, self._assets, self._objects.specs = xml, assets, specs
            self.data = carry_state(self.model, self.data, model)
            self.model, self.view_model = model, view
            self._view_data = mujoco.MjData(view)
            for binding in self._bindings:
                self._drive.relocate(binding.index, *self._resolve(binding.link.joint))
            self._drive.invalidate()
            self._close_renderers()
