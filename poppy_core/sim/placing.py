"""Moving things in a MuJoCo world by hand: objects' poses, the clock, a user's scene file.

``Simulation`` takes these from ``Placing``; they are what pypot's V-REP calls did
(``set_object_position``, ``get_simulation_current_time``, a scene with props: see
``poppy_core.robot.vrep_names``).
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Any, Protocol

import mujoco  # noqa: TID253 (this room is imported lazily, by the factory)
import numpy as np

from poppy_core.errors import ConfigError
from poppy_core.sim.model_files import read_model


def carry_state(old_model: Any, old_data: Any, model: Any) -> Any:
    """New data for ``model`` holding ``old_data``'s joint states, controls, actuator gains and
    clock, for the joints and actuators both models name (the others start as ``model`` says)."""
    data = mujoco.MjData(model)
    joint, actuator = mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_ACTUATOR
    for j in range(old_model.njnt):
        new = mujoco.mj_name2id(model, joint, mujoco.mj_id2name(old_model, joint, j) or "")
        if new < 0 or model.jnt_type[new] != old_model.jnt_type[j]:
            continue
        size_q = 7 if old_model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE else 1
        size_v = 6 if size_q == 7 else 1
        qa, na = old_model.jnt_qposadr[j], model.jnt_qposadr[new]
        va, nv = old_model.jnt_dofadr[j], model.jnt_dofadr[new]
        data.qpos[na : na + size_q] = old_data.qpos[qa : qa + size_q]
        data.qvel[nv : nv + size_v] = old_data.qvel[va : va + size_v]
    data.time = old_data.time
    for a in range(old_model.nu):
        new = mujoco.mj_name2id(model, actuator, mujoco.mj_id2name(old_model, actuator, a) or "")
        if new < 0:
            continue
        model.actuator_gainprm[new] = old_model.actuator_gainprm[a]
        model.actuator_biasprm[new] = old_model.actuator_biasprm[a]
        model.actuator_forcerange[new] = old_model.actuator_forcerange[a]
        data.ctrl[new] = old_data.ctrl[a]
    mujoco.mj_forward(model, data)
    return data


class PlacingHost(Protocol):
    """What ``Placing`` needs of the world it is mixed into (``Simulation`` gives it)."""

    @property
    def model(self) -> Any:
        """The stepped ``MjModel`` (without the visual meshes)."""
        ...

    @property
    def view_model(self) -> Any:
        """The drawn ``MjModel`` (same bodies, with the visual meshes)."""
        ...

    @property
    def data(self) -> Any:
        """The world's ``MjData``."""
        ...

    @property
    def meshes_dir(self) -> Path | None:
        """Where a scene's missing mesh files are looked for."""
        ...

    @property
    def lock(self) -> threading.RLock:
        """Held to read or change ``model``/``data``."""
        ...

    def _body(self, name: str) -> int:
        """Body ``name``'s index (``ConfigError`` if there is none)."""
        ...

    def _install(self, xml: str | None = None, assets: dict[str, bytes] | None = None) -> None:
        """Compile the world again from ``xml`` and ``assets``, carrying the robot's state."""
        ...


class Placing:
    """Poses set by hand, the simulated time, and loading a scene (a mixin of a ``PlacingHost``,
    the ``Simulation``)."""

    @property
    def time(self: PlacingHost) -> float:
        """The simulated time (s) since the world was built."""
        with self.lock:
            return float(self.data.time)

    def set_object_position(
        self: PlacingHost, name: str, position: tuple[float, float, float]
    ) -> None:
        """Put body ``name`` (an object, a scene's prop, the Humanoid's root) at ``position``
        (m, world frame), at rest; its orientation is kept.

        Raises:
            ConfigError: no such body, a robot link, or a position that is not 3 numbers.
        """
        point = _vector(position, 3, "position")
        with self.lock:
            body, joint = _placeable(self, name)
            if joint is None:
                self.model.body_pos[body] = point
                self.view_model.body_pos[body] = point
            else:
                address = int(self.model.jnt_qposadr[joint])
                self.data.qpos[address : address + 3] = point
                dof = int(self.model.jnt_dofadr[joint])
                self.data.qvel[dof : dof + 6] = 0.0
            mujoco.mj_forward(self.model, self.data)

    def set_object_orientation(
        self: PlacingHost, name: str, quat: tuple[float, float, float, float]
    ) -> None:
        """Turn body ``name`` (as ``set_object_position`` places) to the quaternion ``quat``
        (w, x, y, z; normalised here), at rest; its position is kept.

        Raises:
            ConfigError: no such body, a robot link, or not a quaternion.
        """
        turn = _vector(quat, 4, "orientation")
        length = float(np.linalg.norm(turn))
        if length < 1e-9:
            raise ConfigError("an orientation quaternion cannot be zero", field="orientation")
        turn = turn / length
        with self.lock:
            body, joint = _placeable(self, name)
            if joint is None:
                self.model.body_quat[body] = turn
                self.view_model.body_quat[body] = turn
            else:
                address = int(self.model.jnt_qposadr[joint])
                self.data.qpos[address + 3 : address + 7] = turn
                dof = int(self.model.jnt_dofadr[joint])
                self.data.qvel[dof : dof + 6] = 0.0
            mujoco.mj_forward(self.model, self.data)

    def load_scene(self: PlacingHost, path: str | Path, meshes: Path | None = None) -> None:
        """Replace the world by the MJCF scene at ``path``: the robot and its props.

        The scene names the robot's joints and actuators like the profile's model (start
        from a copy of ``profiles/<robot>/model.xml`` and add bodies); its mesh files are read
        beside it, else in ``meshes`` (default: the profile's). The robot keeps its pose and goals;
        objects added before are added again.

        Raises:
            ConfigError: the file cannot be read or compiled, or lacks the robot's joints.
        """
        scene = Path(path)
        xml, assets = read_model(scene, meshes if meshes is not None else self.meshes_dir)
        self._install(xml, assets)


def _free_joint(host: PlacingHost, body: int) -> int | None:
    """The free joint that moves ``body`` on its own, if any."""
    model = host.model
    for j in range(int(model.body_jntnum[body])):
        joint = int(model.body_jntadr[body]) + j
        if model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_FREE:
            return joint
    return None


def _placeable(host: PlacingHost, name: str) -> tuple[int, int | None]:
    """(body, its free joint or None for a body fixed in the world).

    Raises:
        ConfigError: ``name`` is a link moved by the robot's joints.
    """
    body = host._body(name)
    joint = _free_joint(host, body)
    model = host.model
    if joint is None and (model.body_parentid[body] != 0 or model.body_jntnum[body]):
        raise ConfigError(
            f"{name!r} moves with the robot's joints: set its motors' goal positions, or "
            "place an object or the robot's free root",
            field=name,
        )
    return body, joint


def _vector(values: object, size: int, field: str) -> np.ndarray:
    try:
        vector = np.asarray(values, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        vector = np.zeros(0)
    if vector.shape != (size,) or not np.isfinite(vector).all():
        raise ConfigError(f"{field} must be {size} finite numbers, not {values!r}", field=field)
    return vector
